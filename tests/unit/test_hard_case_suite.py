"""The plugin's hard cases (tools/hard_cases.py, docs/hard-cases.md): every pair and speed
either gives finite outputs for models A, B and C, flagged where delta_max exceeds the
smaller radius, or is refused (exit 2) for leaving double precision."""
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
from hard_cases import PAIRS, PLUGIN_CASES, plugin_case  # noqa: E402


def smaller_radius(pair):
    args = PAIRS[pair]
    value = lambda name, default: float(args[args.index(name) + 1]) if name in args else default
    return min(value("--R1", 2e-3), math.inf if "--wall" in args else value("--R2", 2e-3))


BEYOND_DOUBLES = ("R = 1e100 m", "E* = 1e300 Pa", "dT = 1e308 K")


@pytest.mark.parametrize("pair,v0", PLUGIN_CASES)
def test_finite_or_refused(pair, v0):
    r = plugin_case(pair, v0)
    assert (r["code"] == 2) == (pair in BEYOND_DOUBLES or v0 == 1e300), r["error"]
    if r["code"] == 2:
        assert "double precision" in r["error"] and r["error"].startswith("error: ")
        return
    assert r["code"] == 0 and len(r["rows"]) == 3
    for row in r["rows"]:
        assert all(math.isfinite(x) for x in row.values() if isinstance(x, float)), row
        assert ("delta_max_exceeds_radius" in row["flags"]) == (row["delta_max"] > smaller_radius(pair))

