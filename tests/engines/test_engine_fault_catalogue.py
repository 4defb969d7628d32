"""Engine faults of a real run through the command line: each ends with exit code 3 (a
failed simulation, docs/exit-codes.md) and one line saying what failed and why. Fluid
solver faults are simulated with small programs posing as collheatFoam (COLLHEAT_SOLVER)."""
import os
import shutil
import stat
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import tomli_w

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
BASE = tomllib.loads((ROOT / "cases" / "two-particles" / "case.toml").read_text())
STEEL = BASE["materials"]["steel"]


def run(tmp_path, scene, env=None, ranks=1):
    case = tmp_path / "case"
    case.mkdir()
    (case / "case.toml").write_text(tomli_w.dumps(scene))
    cmd = [sys.executable, "-m", "pyhost", "run", str(case), "--out", str(tmp_path / "out")]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd
        env = dict(env or {}, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env={**os.environ, **(env or {})},
                          timeout=120)


def one_particle(speed, youngs=2e8, walls=(), dem_step=2e-7):
    scene = dict(BASE, materials={"steel": dict(STEEL, dem=dict(STEEL["dem"], youngs_modulus=youngs))},
                 time=dict(dem_step=dem_step, end=5e-3), output=dict(every=1e-3, pictures=False, vtk=False))
    scene["particles"] = [dict(material="steel", count=1, radius=2e-3, temperature=300.0,
                               positions=[[0.045, 0.005, 0.01]], velocity=[speed, 0.0, 0.0])]
    scene["walls"] = [dict(plane=w, material="steel") for w in walls]
    return scene


def assert_failed(r, *words):
    """Exit 3 and the error as the last line (under mpirun, the last before mpirun's own)."""
    assert r.returncode == 3, r.stderr[-2000:]
    line = r.stderr.split("\n-----", 1)[0].strip().splitlines()[-1]
    assert line.startswith("error: simulation failed") and "Traceback" not in r.stderr
    for w in words:
        assert w in r.stderr, (w, r.stderr[-2000:])


@pytest.mark.parametrize("ranks", [1, pytest.param(2, marks=pytest.mark.skipif(
    shutil.which("mpirun") is None, reason="no mpirun: tools/setup.sh --engines"))])
def test_particle_leaving_through_an_open_face(tmp_path, ranks):
    """Also on two ranks, where each keeps its own particles' positions before each chunk and
    rank 0 gathers them only for the report."""
    r = run(tmp_path, one_particle(30.0), ranks=ranks)
    assert_failed(r, "ParticlesLost", "ids [1]", "v = [30.0, 0.0, 0.0]", "open at xhi")
    assert "stopped at t = " in (tmp_path / "out" / "summary.json").read_text()


def test_particle_tunnelling_through_a_soft_wall(tmp_path):
    """5 MPa (LIGGGHTS' least modulus) and 30 m/s: the Hertz overlap would be 5 mm > R = 2 mm."""
    r = run(tmp_path, one_particle(30.0, youngs=5e6, walls=["xhi"], dem_step=1e-7))
    assert_failed(r, "ParticlesLost", "tunnelling through the soft wall xhi", "radius 0.002 m")


FLUID = dict(BASE, effects={"fluid": True}, fluid={"cells": [2, 1, 2]},
             time=dict(dem_step=2e-7, end=2e-3), output=dict(every=2e-4, pictures=False, vtk=False))
FAKES = {
    "never_connects": ("import time\ntime.sleep(600)\n", "start time-out"),
    "dies_at_start": ("import sys\nsys.exit(4)\n", "exit code 4"),
}


@pytest.mark.parametrize("kind", FAKES)
def test_fluid_solver_faults(tmp_path, kind):
    body, words = FAKES[kind]
    fake = tmp_path / "fake_solver"
    fake.write_text(f"#!{sys.executable}\n{body}")
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    r = run(tmp_path, FLUID, env={"COLLHEAT_SOLVER": str(fake), "COLLHEAT_FLUID_TIMEOUT": "2"})
    assert_failed(r, "FluidError", words)
    assert not (tmp_path / "out" / "fluid" / ".link").exists()


def test_fluid_solver_not_executable(tmp_path):
    fake = tmp_path / "fake_solver"
    fake.write_text("not a program")
    r = run(tmp_path, FLUID, env={"COLLHEAT_SOLVER": str(fake)})
    assert_failed(r, "cannot start the fluid solver", str(fake))
    assert not (tmp_path / "out" / "fluid" / ".link").exists()
