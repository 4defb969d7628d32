"""The coupling loop's bookkeeping, on a minimal numpy DEM (Hertz + damping, velocity Verlet).

The real-engine versions of these scenes are the cases; here the DEM is a stand-in so that
the host's own logic (detection, impact speed, heat, restitution, conservation) is tested
on its own.
"""
import csv

import numpy as np
import pytest

from plugins.heat import Pair, collide
from plugins.heat.comparison import COMPARISON
from pyhost.collisions import DemHertz
from pyhost.contact_heat import dem_pair, pair_properties
from pyhost.contacts import find_contacts
from pyhost.dem_input import place_particles
from pyhost.loop import Coupling
from pyhost.scene import load_scene


class NumpyDem:
    def __init__(self, scene, particles):
        self.scene, self.p = scene, particles
        self.x, self.v = particles.position.copy(), particles.velocity.copy()
        m = next(iter(scene.materials.values())).dem
        self.law = DemHertz(m.youngs_modulus / (2 * (1 - m.poisson_ratio**2)), m.restitution)
        self.calls = 0

    def forces(self):
        d = self.scene.domain
        c = find_contacts(self.x, self.v, self.p.radius, d.box, d.periodic, [w.plane for w in self.scene.walls])
        F = np.zeros_like(self.x)
        wall = c.j >= 2**30
        jj = np.where(wall, 0, c.j)
        R = np.where(wall, self.p.radius[c.i], self.p.radius[c.i] * self.p.radius[jj] / (self.p.radius[c.i] + self.p.radius[jj]))
        m = np.where(wall, self.p.mass[c.i], self.p.mass[c.i] * self.p.mass[jj] / (self.p.mass[c.i] + self.p.mass[jj]))
        f = np.maximum(self.law.force(c.delta, c.approach, R, m), 0.0)
        np.add.at(F, c.i, f[:, None] * c.normal)
        np.add.at(F, jj[~wall], -f[~wall, None] * c.normal[~wall])
        return F / self.p.mass[:, None] + np.asarray(self.scene.domain.gravity)

    def run(self, steps):
        dt = self.scene.time.dem_step
        for _ in range(steps):
            self.v += 0.5 * dt * self.forces()
            self.x += dt * self.v
            self.v += 0.5 * dt * self.forces()

    def state(self):
        self.calls += 1
        return self.x, self.v

    def add_velocity(self, index, dv):
        np.add.at(self.v, index, dv)


SCENE = """
[effects]
contact_heat = "{model}"
heat_path = "exact"
restitution_feedback = {feedback}
[materials.steel]
density = 7800.0
youngs_modulus = 210e9
poisson_ratio = 0.3
yield_stress = 300e6
heat_capacity = 470.0
conductivity = 45.0
dem = {{ youngs_modulus = 2e8, restitution = 0.9 }}
[[particles]]
material = "steel"
count = 2
radius = 2e-3
temperature = 300.0
positions = [[0.045, 0.005, 0.01], [0.0492, 0.005, 0.01]]
[domain]
box = [0.0, 0.1, 0.0, 0.01, 0.0, 0.02]
gravity = [0.0, 0.0, 0.0]
[time]
dem_step = 5e-7
end = 1e-3
sample_every = 2
[output]
vtk = false
every = 5e-4
"""


def run(tmp_path, model="A", feedback="false", hot=400.0, speed=0.4):
    (tmp_path / "case.toml").write_text(SCENE.format(model=model, feedback=feedback))
    scene = load_scene(tmp_path / "case.toml")
    p = place_particles(scene)
    p.velocity[0, 0], p.velocity[1, 0] = speed / 2, -speed / 2
    p.temperature[0] = hot
    dem = NumpyDem(scene, p)
    summary = Coupling(scene, dem, p, tmp_path / "out", progress_every=1e9).run()
    return scene, p, dem, summary


def test_head_on_heat_matches_plugin_and_is_conserved(tmp_path):
    scene, p, dem, summary = run(tmp_path)
    assert summary["collisions"] == 1
    assert abs(summary["energy_balance_error"]) < 1e-12
    rows = (tmp_path / "out" / "collisions.csv").read_text().splitlines()
    v0, Q = float(rows[1].split(",")[4]), float(rows[1].split(",")[5])
    assert v0 == pytest.approx(0.4, rel=1e-4)
    ref = collide(0.4, Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(*[scene.materials["steel"]] * 2)), "A")
    assert Q == pytest.approx(ref.Q, rel=1e-3)


def test_restitution_feedback_gives_model_rebound(tmp_path):
    _, _, dem, summary = run(tmp_path, model="C", feedback="true")
    ref = collide(0.4, Pair(R1=2e-3, R2=2e-3, rho1=7800, rho2=7800, Estar=210e9 / (2 * 0.91), c1=470, c2=470,
                            k1=45, k2=45), "C")
    separation = dem.v[1, 0] - dem.v[0, 0]
    assert separation == pytest.approx(ref.e * 0.4, rel=1e-3)
    assert dem.v[0, 0] + dem.v[1, 0] == pytest.approx(0.0, abs=1e-12)     # momentum


def test_isothermal_scene_samples_nothing(tmp_path):
    _, _, dem, summary = run(tmp_path, model="none")
    assert summary["collisions"] == 0
    assert dem.calls == 0          # no VTK frames asked for, and no contact sampling


RESTING = SCENE.replace('positions = [[0.045, 0.005, 0.01], [0.0492, 0.005, 0.01]]',
                        'positions = [[0.045, 0.005, 0.0021], [0.06, 0.005, 0.0021]]') \
    .replace("gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0, -9.81]") \
    .replace("dem_step = 5e-7", "dem_step = 5e-6").replace("end = 1e-3", "end = 0.03") \
    .replace("restitution = 0.9", "restitution = 0.3") \
    .replace("[domain]", '[[walls]]\nplane = "zlo"\nmaterial = "steel"\ntemperature = 400.0\n[domain]')


@pytest.mark.parametrize("enduring", [False, True])
def test_resting_contact_conducts_only_when_enduring_is_on(tmp_path, enduring):
    text = RESTING.format(model="A", feedback="false").replace(
        "restitution_feedback = false", f"restitution_feedback = false\nenduring_conduction = {str(enduring).lower()}")
    (tmp_path / "case.toml").write_text(text)
    scene = load_scene(tmp_path / "case.toml")
    p = place_particles(scene)
    dem = NumpyDem(scene, p)
    summary = Coupling(scene, dem, p, tmp_path / "out", progress_every=1e9).run()
    assert abs(summary["energy_balance_error"]) < 1e-12
    rows = list(csv.DictReader(open(tmp_path / "out" / "collisions.csv")))
    collision_heat = -sum(float(r["Q"]) for r in rows if r["wall"] != "0")
    assert summary["wall_collisions"] >= 2                      # bounces, then rests
    if enduring:
        assert summary["enduring_heat"] > 0
        assert summary["heat_from_walls"] == pytest.approx(collision_heat + summary["enduring_heat"], rel=1e-9)
    else:
        assert summary["enduring_heat"] == 0
        assert summary["heat_from_walls"] == pytest.approx(collision_heat, rel=1e-12)


def test_side_models_are_columns_and_move_nothing(tmp_path):
    """contact_heat = [A, hertz, softened]: A moves the heat exactly as alone; the side
    columns are the plugin's heat of each model on the same collision at the same dT."""
    (tmp_path / "alone").mkdir()
    _, _, _, alone = run(tmp_path / "alone")
    text = SCENE.format(model="A", feedback="false").replace('contact_heat = "A"',
                                                             'contact_heat = ["A", "hertz", "softened"]')
    (tmp_path / "case.toml").write_text(text)
    scene = load_scene(tmp_path / "case.toml")
    p = place_particles(scene)
    p.velocity[0, 0], p.velocity[1, 0] = 0.2, -0.2
    p.temperature[0] = 400.0
    summary = Coupling(scene, NumpyDem(scene, p), p, tmp_path / "out", progress_every=1e9).run()
    row, = csv.DictReader(open(tmp_path / "out" / "collisions.csv"))
    row_alone, = csv.DictReader(open(tmp_path / "alone" / "out" / "collisions.csv"))
    assert row["Q"] == row_alone["Q"] and row["e"] == row_alone["e"]
    assert summary["heat_moved"] == alone["heat_moved"]
    steel = scene.materials["steel"]
    pair = Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel))
    v0 = float(row["v0"])
    assert float(row["Q_hertz"]) == pytest.approx(float(COMPARISON["hertz"].heat(v0, pair)["Q"]), rel=1e-12)
    assert float(row["Q_softened"]) == pytest.approx(
        float(COMPARISON["softened"].heat(v0, pair, dem_pair(steel, steel))["Q"]), rel=1e-12)
    assert summary["heat_by_model"] == pytest.approx(
        {"A": float(row["Q"]), "hertz": float(row["Q_hertz"]), "softened": float(row["Q_softened"])}, rel=1e-12)
