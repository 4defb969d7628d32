"""SceneDem on the real LIGGGHTS: the fluid-force array starts at zero, however many engines
the process built before (the array is uninitialised memory until set)."""
from pathlib import Path

import numpy as np
import pytest

from pyhost.dem import FLUID_FIX, SceneDem
from pyhost.dem_input import place_particles
from pyhost.scene import load_scene

pytestmark = pytest.mark.engines
CASE = Path(__file__).resolve().parents[2] / "cases" / "packed-bed-ergun" / "case.toml"


def test_first_step_feels_gravity_only(tmp_path):
    """Free particles of the lattice (no contact yet): one step changes v by g dt exactly,
    for each of four engines built in turn in one process."""
    scene = load_scene(CASE)
    particles = place_particles(scene)
    g, dt = np.array(scene.domain.gravity), scene.time.dem_step
    for k in range(4):
        dem = SceneDem(scene, particles, tmp_path / f"dem{k}", fluid_force=True)
        try:
            assert np.all(dem.lmp.external_force(FLUID_FIX) == 0.0)
            v0 = dem.state()[1].copy()
            dem.run(1)
            dv = dem.state()[1] - v0
            assert np.allclose(dv, g * dt, rtol=0, atol=1e-12 * np.abs(g).max() * dt), k
        finally:
            dem.close()
