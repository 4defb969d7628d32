"""``python -m pyhost compare``: the tables it writes obey the scaling laws of the models,
and the bed totals recover the run's own heat."""
import csv
import shutil
from pathlib import Path

import numpy as np
import pytest

from plugins.heat import MODEL_NAMES
from pyhost.cli import main
from plugins.heat.batch import evaluate
from pyhost.scene import load_scene

BED = Path(__file__).resolve().parents[2] / "cases" / "hot-cold-bed" / "case.toml"


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_compare_tables_and_bed_totals(tmp_path):
    run = tmp_path / "bed"
    (run / "output").mkdir(parents=True)
    shutil.copy(BED, run / "case.toml")
    scene = load_scene(run / "case.toml")
    mats = list(scene.materials.values())
    # four collisions between beads 1-2, 3-4, 5-6 and of bead 7 with wall 1 (adiabatic)
    v0, dT = np.array([0.01, 0.1, 0.5, 0.2]), np.array([100.0, -50.0, 3.0, 0.0])
    R, m0 = np.full(4, scene.particles[0].radius), np.zeros(4, int)
    R_j = np.array([R[0]] * 3 + [np.inf])
    G = {m: evaluate(m, "fast", mats, m0, m0, R, R_j, v0, np.ones(4))[0] for m in MODEL_NAMES}
    with open(run / "output" / "collisions.csv", "w") as f:
        f.write("time,i,j,wall,v0,Q,e,t_coll,model\n")
        for k, (i, j, w) in enumerate([(1, 2, 0), (3, 4, 0), (5, 6, 0), (7, 0, 1)]):
            f.write(f"0.001,{i},{j},{w},{float(v0[k])!r},{float(G['A'][k] * dT[k])!r},0.5,1e-6,A\n")
    assert main(["compare", "--out", str(tmp_path / "out"), "--bed", str(run / "output")]) == 0

    bed = {r["model"]: float(r["heat_J"]) for r in read(tmp_path / "out" / "comparison_bed.csv")}
    for m in MODEL_NAMES:
        assert bed[m] == pytest.approx(np.sum(np.abs(G[m][:3] * dT[:3])), rel=1e-12)
    rows = read(tmp_path / "out" / "comparison_modulus.csv")
    for name in ("aluminium", "steel", "glass"):
        lo, hi = (r for r in rows if r["material"] == name)
        # softened Q ~ E_DEM^(-3/5), with the area correction ~ E_DEM^(-4/15), zhou ~ E_DEM^(-2/5)
        # (overlap << R)
        assert float(lo["softened/A"]) / float(hi["softened/A"]) == pytest.approx(10**0.6, rel=0.02)
        assert float(lo["corrected/A"]) / float(hi["corrected/A"]) == pytest.approx(10 ** (4 / 15), rel=0.02)
        assert float(lo["zhou/A"]) / float(hi["zhou/A"]) == pytest.approx(10**0.4, rel=0.02)   # E^(-3/5 + 1/5)
    glass = rows[-1]                   # glass stays elastic at 0.5 m/s: A is Hertz
    assert float(glass["softened/A"]) == pytest.approx(float(glass["softened/hertz"]), rel=1e-9)
    speed = read(tmp_path / "out" / "comparison_speed.csv")
    assert set(speed[0]) == {"v0"} | {f"Q_{m}" for m in MODEL_NAMES}
    assert all((tmp_path / "out" / f"comparison_{k}.png").is_file() for k in ("speed", "modulus", "bed"))
