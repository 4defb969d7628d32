"""The small cases, run for real (LIGGGHTS in process): results against the plugin alone."""
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import pyvista

from plugins.heat import Pair, collide
from plugins.heat.batch import pair_properties
from pyhost.scene import load_scene

pytestmark = pytest.mark.engines
CASES = Path(__file__).resolve().parents[2] / "cases"


def run_case(name, out, *extra):
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(CASES / name), "--out", str(out), *extra],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    rows = list(csv.DictReader(open(out / "collisions.csv")))
    return rows, json.loads((out / "summary.json").read_text())


def last_frame(out):
    reader = pyvista.get_reader(str(out / "vtk" / "particles.pvd"))
    reader.set_active_time_value(reader.time_values[-1])
    return reader.read()[0]


def test_two_particles_match_plugin(tmp_path):
    rows, summary = run_case("two-particles", tmp_path)
    assert summary["collisions"] == 1 and summary["energy_balance_error"] == pytest.approx(0, abs=1e-12)
    scene = load_scene(CASES / "two-particles" / "case.toml")
    steel = scene.materials["steel"]
    ref = collide(0.4, Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel)), "A")
    row = rows[0]
    assert float(row["v0"]) == pytest.approx(0.4, rel=1e-3)
    for key, value in (("Q", ref.Q), ("e", ref.e), ("t_coll", ref.t_coll)):
        assert float(row[key]) == pytest.approx(value, rel=0.01), key
    v = last_frame(tmp_path).point_data["velocity"]
    assert v[1, 0] - v[0, 0] == pytest.approx(ref.e * 0.4, rel=0.01)      # rebound with the model's e
    T = last_frame(tmp_path).point_data["temperature"]
    C = 4 / 3 * math.pi * 2e-3**3 * 7800 * 470
    assert (400 - T[0]) * C == pytest.approx(ref.Q, rel=0.01)
    # each frame's change since the particle came in (400 K and 300 K): what particles.png colours
    change = last_frame(tmp_path).point_data["temperature_change"]
    assert change == pytest.approx(T - [400.0, 300.0], abs=1e-9)
    assert change[0] < 0 < change[1] and change[0] == pytest.approx(-change[1], rel=1e-9)


def test_wall_impact_matches_plugin_and_balances(tmp_path):
    rows, summary = run_case("wall-impact", tmp_path)
    scene = load_scene(CASES / "wall-impact" / "case.toml")
    steel = scene.materials["steel"]
    wall_row = [r for r in rows if r["wall"] != "0"][0]
    v0 = float(wall_row["v0"])
    assert v0 == pytest.approx(1.0, rel=1e-3)
    ref = collide(v0, Pair.wall(dT=350.0 - 300.0, **pair_properties(steel, steel)), "B")
    assert float(wall_row["Q"]) == pytest.approx(ref.Q, rel=0.01)
    # the particle's heat content changed by exactly what came from the wall
    assert summary["heat_from_walls"] == pytest.approx(-ref.Q, rel=0.01)
    assert summary["energy_balance_error"] == pytest.approx(0, abs=1e-12)


def test_hot_cold_box_smoke_conserves_and_converges(tmp_path):
    rows, summary = run_case("hot-cold-box", tmp_path, "--test")
    assert summary["collisions"] > 1000 and summary["capped"] == 0
    assert abs(summary["energy_balance_error"]) < 1e-12
    hist = list(csv.DictReader(open(tmp_path / "history.csv")))
    hot = float(hist[-1]["T_group0"]) - float(hist[0]["T_group0"])
    cold = float(hist[-1]["T_group1"]) - float(hist[0]["T_group1"])
    assert hot < 0 < cold
    assert hot == pytest.approx(-cold, rel=1e-6)          # equal heat capacities
    assert (tmp_path / "temperatures.png").stat().st_size > 10000
    assert (tmp_path / "particles.png").stat().st_size > 10000


def test_a_run_that_does_not_end_on_a_frame_gets_one_at_its_end(tmp_path):
    """two-particles for 1.5 ms with frames every 0.4 ms: rows at 0, 0.4, 0.8 and 1.2 ms, and
    one at the end, holding the state summary.json reports (the same totals)."""
    text = (CASES / "two-particles" / "case.toml").read_text()
    assert "every = 2e-4" in text and "end = 2e-3 " in text
    (tmp_path / "case.toml").write_text(text.replace("every = 2e-4", "every = 4e-4").replace("end = 2e-3 ", "end = 1.5e-3 "))
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    hist = list(csv.DictReader(open(out / "history.csv")))
    summary = json.loads((out / "summary.json").read_text())
    assert [float(h["time"]) for h in hist] == pytest.approx([0.0, 4e-4, 8e-4, 1.2e-3, 1.5e-3], abs=1e-9)
    assert float(hist[-1]["time"]) == pytest.approx(summary["time"], abs=1e-12)
    assert int(hist[-1]["collisions"]) == summary["collisions"] == 1
    assert pyvista.get_reader(str(out / "vtk" / "particles.pvd")).time_values[-1] == pytest.approx(1.5e-3, abs=1e-9)


def test_particle_outside_the_box_is_refused_before_liggghts(tmp_path):
    text = (CASES / "two-particles" / "case.toml").read_text()
    (tmp_path / "case.toml").write_text(text.replace("[[0.045, 0.005, 0.01]]", "[[0.5, 0.005, 0.01]]"))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 2
    assert "particles[0].positions[0]" in r.stderr and "outside the box" in r.stderr and "Traceback" not in r.stderr


class Interrupting:
    """A DEM that fails after a few chunks, as an engine that diverges would."""

    def __init__(self, dem, after):
        self.dem, self.calls, self.after = dem, 0, after

    def run(self, n):
        self.calls += 1
        if self.calls > self.after:
            raise RuntimeError("diverged")
        self.dem.run(n)

    def __getattr__(self, name):
        return getattr(self.dem, name)


def test_results_so_far_survive_a_failure(tmp_path):
    from pyhost.world import simulate

    scene = load_scene(CASES / "hot-cold-box" / "case.toml")
    with pytest.raises(RuntimeError, match="diverged"):
        # the DEM runs in chunks of 1000 steps (the contact events' harvests): the third one fails
        simulate(scene, tmp_path, progress_every=1e9, wrap=lambda dem: Interrupting(dem, 2))
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"].startswith("stopped at t = 0.002 s by RuntimeError: diverged")
    rows = list(csv.DictReader(open(tmp_path / "collisions.csv")))
    assert len(rows) == summary["collisions"] > 0
    assert abs(summary["energy_balance_error"]) < 1e-12


def test_hot_cold_bed_smoke(tmp_path):
    """The default case, fluid on, for 50 ms (the halves meet after ~20 ms): heat moves hot to
    cold, balance exact, fluid written."""
    rows, summary = run_case("hot-cold-bed", tmp_path, "--test")
    assert summary["collisions"] > 5000 and summary["capped"] == 0
    assert abs(summary["energy_balance_error"]) < 1e-12            # walls adiabatic
    hist = list(csv.DictReader(open(tmp_path / "history.csv")))
    assert float(hist[-1]["T_group0"]) < 400.0 and float(hist[-1]["T_group1"]) > 300.0
    reader = pyvista.get_reader(str(tmp_path / "vtk" / "fluid.pvd"))
    reader.set_active_time_value(reader.time_values[-1])
    fluid = reader.read()[0]
    alpha = fluid.point_data["alpha"]
    assert alpha.min() < 0.7 and alpha.max() == pytest.approx(1.0)   # a bed below, free air above


def test_hot_cold_gas_bed_smoke_run_keeps_particles_and_gas_energy(tmp_path):
    """cases/hot-cold-gas-bed -test (0.02 s): collisions and convection both move heat, and
    particles plus gas keep their energy with what crossed the fluid's boundaries to 1e-12."""
    _, summary = run_case("hot-cold-gas-bed", tmp_path, "--test")
    assert summary["collisions"] > 1000 and summary["heat_moved"] > 0
    assert summary["heat_convected_gross"] > 0
    assert abs(summary["energy_balance_error"]) < 1e-12
    assert abs(summary["total_energy_balance_error"]) < 1e-12


@pytest.mark.long
def test_fluid_beside_the_dem_gives_the_same_run(tmp_path):
    """cases/hot-cold-gas-bed -test (convection: the gas's temperature and boundary heat are
    read after each advance) with the fluid advancing while the DEM runs ([fluid] overlap =
    "always") and with the two taking turns ("never"): collisions.csv and history.csv the same
    to the byte, the summaries key by key."""
    import shutil

    files = {}
    for overlap in ("always", "never"):
        case = tmp_path / f"case-{overlap}"
        shutil.copytree(CASES / "hot-cold-gas-bed", case)
        toml = case / "case.toml"
        toml.write_text(toml.read_text().replace("[fluid]\n", f'[fluid]\noverlap = "{overlap}"\n', 1))
        r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--test", "--out", str(tmp_path / overlap)],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        out = tmp_path / overlap
        files[overlap] = [(out / f).read_bytes() for f in ("collisions.csv", "history.csv")]
        files[overlap].append(json.loads((out / "summary.json").read_text()))
    assert files["always"] == files["never"]


def test_a_failure_of_the_last_advance_beside_the_dem_stops_the_run_with_its_summary(tmp_path):
    """The fluid's last advance of a run, left running beside the DEM, fails (injected: the
    solver's answer raises FluidError when the host takes it): the run stops as at any other
    failure, FluidError raised, with summary.json saying it stopped and why."""
    import tomllib

    import tomli_w

    from pyhost.engines.openfoam import FluidError
    from pyhost.world import simulate

    base = tomllib.loads((CASES / "two-particles" / "case.toml").read_text())
    scene = dict(base, effects={"fluid": True}, fluid={"cells": [2, 1, 2], "overlap": "always"},
                 time=dict(dem_step=2e-7, end=2e-4), output=dict(every=1e-4, pictures=False, vtk=False))
    (tmp_path / "case").mkdir()
    (tmp_path / "case" / "case.toml").write_text(tomli_w.dumps(scene))

    class FailingAnswer:
        """The solver, whose first answer taken by the loop's own wait is a failure."""
        def __init__(self, fluid):
            self.fluid, self.failed = fluid, False

        def __getattr__(self, name):
            return getattr(self.fluid, name)

        def wait(self):
            self.fluid.wait()
            if not self.failed:
                self.failed = True
                raise FluidError("injected: the solver failed in its last advance")

    with pytest.raises(FluidError, match="injected"):
        simulate(load_scene(tmp_path / "case" / "case.toml"), tmp_path / "out", progress_every=1e9,
                 wrap_fluid=FailingAnswer)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"].startswith("stopped at t = ") and "FluidError" in summary["status"]
    assert summary["time"] == pytest.approx(2e-4)


class Heating:
    """A DEM in which particle 0 gains 1 K after every chunk behind the host's back, as a heat
    source of a script that the host does not know would."""

    def __init__(self, dem):
        self.dem = dem

    def run(self, n):
        self.dem.run(n)
        self.dem.lmp.temperature()[0] += 1.0

    def __getattr__(self, name):
        return getattr(self.dem, name)


def test_a_broken_energy_balance_fails_the_run_after_writing_its_results(tmp_path):
    """No exit 0 with a wrong answer: a completed run whose energy balance is off by more than
    round-off raises InvariantBroken (exit 3) naming the balance, after summary.json (status
    failed, the residual), collisions.csv and history.csv are written whole. The same run
    without the heating passes with its balance at round-off."""
    from pyhost.effects.balance import TOLERANCE
    from pyhost.exitcodes import classify
    from pyhost.failures import InvariantBroken
    from pyhost.world import simulate

    scene = load_scene(CASES / "two-particles" / "case.toml")
    with pytest.raises(InvariantBroken, match="energy balance broken") as err:
        simulate(scene, tmp_path / "heated", progress_every=1e9, wrap=Heating)
    summary = json.loads((tmp_path / "heated" / "summary.json").read_text())
    assert summary["status"].startswith("failed at the end: energy balance broken")
    assert abs(summary["energy_balance_error"]) > 1e3 * TOLERANCE
    assert f"{summary['energy_balance_error']:.3g}" in str(err.value)
    assert classify(err.value)[0] == 3
    rows = list(csv.DictReader(open(tmp_path / "heated" / "collisions.csv")))
    assert len(rows) == summary["collisions"] == 1
    assert list(csv.DictReader(open(tmp_path / "heated" / "history.csv")))
    clean = simulate(scene, tmp_path / "clean", progress_every=1e9)
    assert clean["status"] == "completed" and abs(clean["energy_balance_error"]) < 1e-12


def test_a_broken_gas_energy_balance_fails_the_run(tmp_path, monkeypatch):
    """cases/hot-cold-gas-bed -test with the gas's starting energy (2.98 J above its reference)
    mis-noted by 20 % (a heat the gas gained or lost uncounted, 0.6 J, as its convection of
    0.47 J over the run is): the particles' balance holds, the balance of particles
    and gas does not, so the completed run raises InvariantBroken (exit 3) naming it, after
    summary.json is written with its status failed and the error. (Unbroken, the same run
    keeps it to 1e-12: test_hot_cold_gas_bed_smoke_run_keeps_particles_and_gas_energy.)"""
    import dataclasses

    from pyhost.effects import fluid
    from pyhost.exitcodes import classify
    from pyhost.failures import InvariantBroken
    from pyhost.world import simulate

    start = fluid.FluidExchange.start

    def misnoted(self):
        start(self)
        self.gas_energy0 *= 1.2

    monkeypatch.setattr(fluid.FluidExchange, "start", misnoted)
    scene = load_scene(CASES / "hot-cold-gas-bed" / "case.toml")
    scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, end=scene.time.test_end),
                                output=dataclasses.replace(scene.output, vtk=False, pictures=False))
    with pytest.raises(InvariantBroken, match="balance of particles and gas broken") as err:
        simulate(scene, tmp_path, progress_every=1e9)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"].startswith("failed at the end: energy balance of particles and gas broken")
    assert abs(summary["energy_balance_error"]) < 1e-12
    assert abs(summary["total_energy_balance_error"]) > 10 * fluid.TOTAL_TOLERANCE
    assert classify(err.value)[0] == 3
