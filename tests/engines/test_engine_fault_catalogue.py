"""Engine faults of a real run through the command line: each ends with exit code 3 (a
failed simulation, docs/exit-codes.md) and one line saying what failed and why. Fluid
solver faults are simulated with small programs posing as collheatFoam (COLLHEAT_SOLVER).
Then a full disk where only an engine run reaches (a script's checkpoint, the pictures),
named with its file, and what a killed checkpoint left, removed at the restart."""
import json
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


@pytest.mark.parametrize("ranks", [1, pytest.param(2, marks=[pytest.mark.long, pytest.mark.skipif(
    shutil.which("mpirun") is None, reason="no mpirun: tools/setup.sh --engines")])])
def test_particle_leaving_through_an_open_face(tmp_path, ranks):
    """Also on two ranks, where each keeps its own particles' positions before each chunk and
    rank 0 gathers them only for the report."""
    r = run(tmp_path, one_particle(30.0), ranks=ranks)
    assert_failed(r, "ParticlesLost", "ids [1]", "v = [30.0, 0.0, 0.0]", "open at xhi")
    assert "stopped at t = " in (tmp_path / "out" / "summary.json").read_text()


@pytest.mark.long
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


POUR = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block 0 0.02 0 0.02 0 0.02 units box
create_box 1 box
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-5
fix walls all wall/gran model hertz tangential history primitive type 1 zplane 0.0
region fill block 0.002 0.018 0.002 0.018 0.002 0.018 units box
fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
fix pdd all particledistribution/discrete 15485867 1 pts 1.0
fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 0 insert_every once overlapcheck yes \
all_in yes particles_in_region 40 region fill
fix integr all nve/sphere
run 2000
"""
GLASS = dict(types=[1], temperature=300.0, density=2500.0, youngs_modulus=63e9, poisson_ratio=0.25,
             yield_stress=500e6, heat_capacity=840.0, conductivity=1.0)


def limited(tmp_path, args, size):
    """``python -m pyhost ARGS`` whose files may not exceed ``size`` bytes: a full disk."""
    import resource
    import signal

    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    return subprocess.run([sys.executable, "-m", "pyhost", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, preexec_fn=small_files, timeout=300)


def test_a_full_disk_at_a_scripts_checkpoint_is_named(tmp_path):
    """A script's checkpoint on a full disk: LIGGGHTS' write_restart ignores its failed writes,
    so the run went on with exit 0 and a checkpoint whose dem.restart was cut (8000 of 10,441
    bytes: read back, 'Did not assign all atoms correctly'). The restart is now read back in a
    forked copy: exit 2 naming dem.restart, the run's summary.json of the steps done, and no
    .checkpoint.new left."""
    case = tmp_path / "case"
    case.mkdir()
    (case / "in.run").write_text(POUR)
    (case / "case.toml").write_text(tomli_w.dumps(dict(dem=dict(script="in.run"), effects=dict(contact_heat="A"),
                                                       materials=dict(glass=GLASS),
                                                       output=dict(vtk=False, pictures=False, checkpoint=0.005))))
    r = limited(tmp_path, ["run", case, "--out", tmp_path / "out"], 8000)
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    assert f"error: {tmp_path / 'out' / '.checkpoint.new' / 'dem.restart'}: LIGGGHTS wrote a restart it cannot read " \
           "back, a full disk?" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"].startswith("stopped at t = 0.005 s")
    assert not (tmp_path / "out" / ".checkpoint.new").exists() and not (tmp_path / "out" / "checkpoint").exists()


def test_a_full_disk_at_the_pictures_is_named(tmp_path):
    """The run's data fit, its pictures do not: the picture process ended with a traceback
    (PIL's) and the run said 'pictures failed (exit 1)'; it names the picture's file."""
    case = tmp_path / "case"
    case.mkdir()
    (case / "case.toml").write_text(tomli_w.dumps(dict(BASE, output=dict(every=2e-5, vtk=True, pictures=True))))
    r = limited(tmp_path, ["run", case, "--out", tmp_path / "out"], 30000)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "Traceback" not in r.stderr and f"error: {tmp_path / 'out' / 'temperatures.png'}: File too large" \
        in r.stderr, r.stderr
    assert "warning: pictures failed (exit 1)" in r.stdout


def test_what_a_killed_checkpoint_left_is_cleaned_at_the_restart(tmp_path):
    """A kill during a checkpoint leaves OUT/.checkpoint.new and vtk/particles.pvd.tmp (a
    stop or a full disk removes its own now). The restart's reading of the checkpoint removes
    .checkpoint.new at once (it stayed until the restarted run's first checkpoint, for ever if
    that run was killed first; the .pvd.tmp goes at its first index, written at the start);
    the restarted run then goes on to its end."""
    case = tmp_path / "case"
    case.mkdir()
    (case / "in.run").write_text(POUR)
    (case / "case.toml").write_text(tomli_w.dumps(dict(dem=dict(script="in.run"), effects=dict(contact_heat="A"),
                                                       materials=dict(glass=GLASS),
                                                       output=dict(vtk=True, pictures=False, checkpoint=0.01))))
    out = tmp_path / "out"
    first = subprocess.run([sys.executable, "-m", "pyhost", "run", case, "--out", out], capture_output=True, text=True,
                           cwd=ROOT, timeout=300)
    assert first.returncode == 0, first.stderr[-2000:]
    (out / ".checkpoint.new").mkdir()
    (out / ".checkpoint.new" / "dem.restart").write_bytes(b"cut")
    (out / "vtk" / "particles.pvd.tmp").write_text("<?xml")
    from pyhost.checkpoint import load
    from pyhost.scene import load_scene
    load(out, load_scene(case / "case.toml"), 0.01)
    assert not (out / ".checkpoint.new").exists() and (out / "checkpoint" / "dem.restart").is_file()
    again = subprocess.run([sys.executable, "-m", "pyhost", "run", case, "--out", out, "--restart", "--extend", "0.01"],
                           capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert again.returncode == 0, again.stdout[-2000:] + again.stderr[-2000:]
    assert not (out / ".checkpoint.new").exists() and not (out / "vtk" / "particles.pvd.tmp").exists()
    assert json.loads((out / "summary.json").read_text())["time"] == pytest.approx(0.03)
