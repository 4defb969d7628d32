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


@pytest.mark.parametrize("model", ["hertz", "softened", "zhou"])
def test_an_impact_beyond_the_range_of_a_comparison_model_is_flagged(tmp_path, model):
    """Two spheres head-on at 4000 m/s (2000 m/s each) with a comparison model moving the
    heat: hertz's indentation, (15 m* v0^2 / (16 E* R*^(1/2)))^(2/5) = 3.1 mm, exceeds the 2 mm
    radius, as does the DEM overlap softened and zhou conduct through (the 2e8 Pa DEM). The
    comparison models gave no indentation: hertz's run said nothing (outside_model_range 0,
    where models A, B and C are flagged at 2000 m/s), softened's and zhou's heat was NaN (the
    area of an overlap beyond 2R) and the run failed on its energy balance ('nan'). Now each
    is counted and warned, its heat finite and the run completed."""
    folder = tmp_path / "fast"
    folder.mkdir()
    scene = (TWO.replace('contact_heat = "A"', f'contact_heat = "{model}"')
             .replace("restitution_feedback = true", "restitution_feedback = false")
             .replace("velocity = [0.2, 0.0, 0.0]", "velocity = [2000.0, 0.0, 0.0]")
             .replace("velocity = [-0.2, 0.0, 0.0]", "velocity = [-2000.0, 0.0, 0.0]"))
    (folder / "case.toml").write_text(scene.replace("end = 2e-3 ", "end = 2e-5 ").replace("test_end = 1.5e-3", ""))
    steel = load_scene(folder / "case.toml").materials["steel"]
    pair = Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel))
    delta = (15 * pair.mstar * 4000.0**2 / (16 * pair.Estar * pair.Rstar**0.5)) ** 0.4
    assert delta == pytest.approx(3.1e-3, rel=0.02)
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    print(r.stdout[-3000:], r.stderr[-3000:])
    row, = csv.DictReader(open(folder / "out" / "collisions.csv"))
    assert float(row["v0"]) == pytest.approx(4000.0, rel=1e-3)
    summary = json.loads((folder / "out" / "summary.json").read_text())
    assert summary["outside_model_range"] == 1 and summary["status"] == "completed"
    assert 0.0 < abs(float(row["Q"])) < 1.0
    assert "a collision at v0 = 4000 m/s is outside the contact models' range" in r.stdout
