"""Coupled box scenes near the DEM's stability limit (tools/hard_cases.py, docs/hard-cases.md):
each runs to its end conserving sum(m c T) to 1e-12 with finite temperatures, or is refused
before the engine starts with the step to use."""
import csv
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
from hard_cases import BOX_CASES, box_case  # noqa: E402

pytestmark = pytest.mark.engines
REFUSED = {"spread 100 m/s, 9 steps per collision", "stiff 210 GPa, step of the soft DEM"}


@pytest.mark.parametrize("name", BOX_CASES)
def test_runs_conserving_heat_or_is_refused(name, tmp_path):
    r = box_case(name, tmp_path)
    if name in REFUSED:
        assert r["code"] == 2 and "time.dem_step" in r["error"] and "use dem_step <=" in r["error"]
        assert r["summary"] is None
        return
    s = r["summary"]
    assert r["code"] == 0 and s["status"] == "completed" and s["collisions"] > 0, r["error"]
    assert abs(s["energy_balance_error"]) <= 1e-12
    rows = list(csv.DictReader(open(tmp_path / "out" / "history.csv")))
    assert all(math.isfinite(float(row[k])) for row in rows for k in ("T_min", "T_max", "sum_mcT"))
