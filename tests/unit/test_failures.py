"""The likely cause of a lost particle, from the scene and where and how fast it was last seen
(pyhost.failures): each cause where its physics says so, with its numbers."""
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from pyhost.engines.liggghts.box_input import dem_collision_time
from pyhost.failures import likely_cause
from pyhost.scene import load_scene

CASES = Path(__file__).resolve().parents[2] / "cases"


@pytest.fixture
def bed(tmp_path):
    """packed-bed-ergun: walls at z lo and hi, periodic in x and y, air blowing up."""
    return load_scene(CASES / "packed-bed-ergun" / "case.toml")


def test_open_face(tmp_path):
    scene = load_scene(CASES / "two-particles" / "case.toml")
    assert "open at ylo" in likely_cause(scene, 0, np.array([0.05, 0.001, 0.01]), np.array([0.1, -1.0, 0.0]), 0.0)


def test_time_step_too_long_at_that_speed(bed):
    """At 2 km/s the bed's DEM collision lasts fewer than 10 steps of 4 us."""
    t_c = dem_collision_time(bed, 2000.0)
    assert t_c < 10 * bed.time.dem_step
    cause = likely_cause(bed, 0, np.array([0.004, 0.004, 0.047]), np.array([0.0, 0.0, 2000.0]), 0.2)
    assert "time.dem_step = 4e-06 s" in cause and f"{t_c:.3g} s" in cause and f"{t_c / 20:.2g}" in cause


def test_soft_wall_tunnelling(bed):
    """5 MPa beads of 0.5 mm at 20 m/s: undamped Hertz overlap (15 m v^2 / (16 E* R^1/2))^(2/5),
    E* = E / (2 (1 - nu^2)) for two equal materials, is 0.92 mm > R."""
    slow_step = bed.__class__(**{**bed.__dict__, "time": bed.time.__class__(dem_step=1e-7, end=0.39)})
    cause = likely_cause(slow_step, 0, np.array([0.004, 0.004, 0.001]), np.array([0.0, 0.0, -20.0]), 0.2)
    m = 4 / 3 * np.pi * 0.5e-3**3 * 2700.0
    E = 5e6 / (2 * (1 - 0.33**2))
    overlap = (15 * m * 20.0**2 / (16 * E * np.sqrt(0.5e-3))) ** 0.4
    assert "tunnelling through the soft wall zlo" in cause and f"{overlap:.3g} m" in cause


def test_blow_out_by_the_gas(tmp_path):
    """The bed without its top wall: a bead rising through zhi at 0.5 m/s while the inlet
    blows 0.9 m/s is blown out (not merely "an open face")."""
    data = tomllib.loads((CASES / "packed-bed-ergun" / "case.toml").read_text())
    data["walls"] = [w for w in data["walls"] if w["plane"] != "zhi"]
    (tmp_path / "case.toml").write_text(tomli_w.dumps(data))
    scene = load_scene(tmp_path / "case.toml")
    cause = likely_cause(scene, 0, np.array([0.004, 0.004, 0.047]), np.array([0.0, 0.0, 0.5]), 0.39)
    assert cause.startswith("blown out by the gas through the open top") and "0.5 m/s" in cause and "0.9 m/s" in cause
