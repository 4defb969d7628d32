"""cases/packed-bed-ergun run for real (LIGGGHTS and collheatFoam): the settled bed's
pressure drop against Ergun at its own voidage, u_mf against Wen-Yu."""
import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pyhost.fluidization import measure
from pyhost.scene import load_scene
from conftest import once

pytestmark = [pytest.mark.engines, pytest.mark.long]   # a validation of the fluid: about 20 s
CASE = Path(__file__).resolve().parents[2] / "cases" / "packed-bed-ergun"


@pytest.fixture(scope="module")
def curve(tmp_path_factory):
    def make(folder):
        r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(CASE), "--out", str(folder / "out")],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]

    out = once(tmp_path_factory, "packed-bed-ergun", make) / "out"
    return out, measure(out)


def test_inlet_follows_the_table(curve):
    out, _ = curve
    scene = load_scene(CASE / "case.toml")
    rows = list(csv.DictReader(open(out / "history.csv")))
    t = np.array([float(r["time"]) for r in rows])
    u = np.array([float(r["u_inlet"]) for r in rows])
    times, speeds = np.array(scene.fluid.inlet_table).T
    assert np.allclose(u, np.interp(t, times, speeds), atol=1e-12)
    assert u.max() == pytest.approx(speeds.max())


@pytest.mark.parametrize("u", [0.2, 0.4])
def test_fixed_bed_pressure_drop_matches_ergun(curve, u):
    """Well below u_mf (0.35 and 0.7 of Wen-Yu's), within 5 % of Ergun at the bed's own
    voidage and height."""
    _, c = curve
    k = c.u.index(u)
    print(f"u {u} m/s: {c.dp[k]:.2f} Pa, Ergun {c.ergun[k]:.2f} Pa (voidage {c.voidage[k]:.4f})")
    assert 0.36 < c.voidage[k] < 0.46                               # a settled random packing
    assert c.dp[k] == pytest.approx(c.ergun[k], rel=0.05)


def test_minimum_fluidization_velocity_matches_wen_yu(curve):
    _, c = curve
    print(f"u_mf {c.u_mf:.4f} m/s, Wen-Yu {c.u_mf_wen_yu:.4f}, Ergun at the voidage {c.u_mf_ergun:.4f}")
    assert c.u_mf == pytest.approx(c.u_mf_wen_yu, rel=0.15)
    assert c.u_mf == pytest.approx(c.u_mf_ergun, rel=0.05)          # the fixed bed's own Ergun


def test_fluidized_bed_carries_its_weight(curve):
    _, c = curve
    assert c.fluidized_dp == pytest.approx(c.weight, rel=0.05)
    assert max(c.height) > 1.05 * min(c.height)                     # and it expanded
