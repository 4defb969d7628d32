"""Side models on the real LIGGGHTS: contact_heat = [A, hertz, softened] moves heat with A
exactly as A alone, and writes the others' heat on the same collision."""
import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from plugins.heat import Pair
from plugins.heat.comparison import COMPARISON
from plugins.heat.batch import dem_pair, pair_properties
from pyhost.scene import load_scene

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
TWO = (ROOT / "cases" / "two-particles" / "case.toml").read_text().replace("[output]", "[output]\nvtk = false\n"
                                                                             "pictures = false")


def run(folder: Path, models: str):
    folder.mkdir()
    (folder / "case.toml").write_text(TWO.replace('contact_heat = "A"', f"contact_heat = {models}"))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    row, = csv.DictReader(open(folder / "out" / "collisions.csv"))
    return row, json.loads((folder / "out" / "summary.json").read_text())


def test_side_models_are_columns_and_move_nothing(tmp_path):
    alone, s_alone = run(tmp_path / "alone", '"A"')
    row, summary = run(tmp_path / "all", '["A", "hertz", "softened"]')
    assert (row["Q"], row["e"], row["v0"]) == (alone["Q"], alone["e"], alone["v0"])
    assert summary["heat_moved"] == s_alone["heat_moved"]
    steel = load_scene(tmp_path / "all" / "case.toml").materials["steel"]
    pair = Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel))
    v0 = float(row["v0"])
    sign = 1.0 if row["i"] == "1" else -1.0            # Q > 0 from i to j; particle 1 is the hot one
    assert sign * float(row["Q_hertz"]) == pytest.approx(float(COMPARISON["hertz"].heat(v0, pair)["Q"]), rel=1e-12)
    assert sign * float(row["Q_softened"]) == pytest.approx(
        float(COMPARISON["softened"].heat(v0, pair, dem_pair(steel, steel))["Q"]), rel=1e-12)
    assert summary["heat_by_model"] == pytest.approx(
        {m: abs(float(row[k])) for m, k in (("A", "Q"), ("hertz", "Q_hertz"), ("softened", "Q_softened"))},
        rel=1e-12)
