"""Users' own LIGGGHTS scripts through the host, unchanged: Debian's heatTransfer tutorial
(nobody here wrote it) and the user-style silo-heat case (STL walls, insertion, two types,
polydisperse radii, fix heat/gran, its own dumps)."""
import csv
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import glass_toml

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
TUTORIAL = Path("/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public/heatTransfer_1")
SOURCES = TUTORIAL.parent / "heatTransfer_2"
STREAM = TUTORIAL.parent / "insert_stream"

STEEL = """
[materials.steel]
types = [1]
density = 8000.0                  # the tutorial's particle template
youngs_modulus = 200e9
poisson_ratio = 0.3
yield_stress = 300e6
heat_capacity = 10.0              # J/(kg K): the tutorial's thermalCapacity (not steel's)
conductivity = 100.0              # W/(m K): the tutorial's thermalConductivity
dem = { youngs_modulus = 5e6, restitution = 0.7 }
"""


def run(case: Path, *extra):
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(case / "out"), *extra],
                       capture_output=True, text=True, cwd=ROOT, timeout=900)
    summary = case / "out" / "summary.json"
    return r, json.loads(summary.read_text()) if summary.exists() else None


@pytest.mark.long
@pytest.mark.skipif(not TUTORIAL.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_debian_heat_transfer_tutorial_runs_unchanged(tmp_path):
    """in.heatGran pours 890 steel spheres into a cylinder (primitive walls, insert/pack,
    heat/gran, dump custom/vtk), runs 'upto' 0.5 s, then sets Temp = 800 K in the half bed
    x > 0 and runs on. The host must run it as written: collisions found, the script's own
    'set' entering the balance, which closes."""
    case = tmp_path / "heatTransfer_1"
    shutil.copytree(TUTORIAL, case)
    for gz in case.rglob("*.gz"):
        subprocess.run(["gunzip", "-f", str(gz)], check=True)
    (case / "case.toml").write_text('[dem]\nscript = "in.heatGran"\n[effects]\ncontact_heat = "A"\n' + STEEL
                                    + "[time]\nsample_every = 5\ntest_end = 0.52\n[output]\nvtk = false\n"
                                      "pictures = false\n")
    r, summary = run(case, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "LIGGGHTS wall 'zwalls1' has no [[walls]] entry: adiabatic" in r.stdout
    assert summary["inserted"] == 890 and summary["departed"] == 0
    assert summary["particle_particle"] > 1000 and summary["particle_wall"] > 100
    assert abs(summary["energy_balance_error"]) < 1e-12
    # The script's own dumps (custom/vtk, every 800 steps) through the project's dump reader;
    # at step 20000, just before the 'set', the spheres at x > 0 are the ones set to 800 K.
    from pyhost.dumps import DumpReader
    frames = {f.step: f for f in DumpReader([case / "post" / "heatGran_*.vtk"], dt=2.5e-5)}
    steps = sorted(frames)
    assert steps[-1] == 20800 and all(b - a == 800 for a, b in zip(steps[1:], steps[2:]))
    assert len(frames[20800]) == 890 and frames[20800].time == pytest.approx(0.52)
    # without [output] every, the host's frames (history rows) come at the steps of the
    # script's own dump, once it is defined (after the script's 'run 1'), and said so
    with open(case / "out" / "history.csv") as f:
        history = [round(float(row["time"]) / 2.5e-5) for row in csv.DictReader(f)]
    assert history == [0] + steps, (history[:5], steps[:5])
    assert "frames and history rows every 800 steps (0.02 s; the script's most frequent dump)" in r.stdout
    frame = frames[20000]
    T, x = frame["f_Temp[0]"], frame.positions()[:, 0]
    m_c = 8000 * 4 / 3 * math.pi * 0.004**3 * 10.0           # J/K per sphere
    half = x > 0
    print(f"{half.sum()} spheres set to 800 K; energy set by the script {summary['energy_set_by_script']:.6g} J")
    assert 300 < half.sum() < 600
    assert summary["energy_set_by_script"] == pytest.approx(np.sum(m_c * (800.0 - T[half])), rel=1e-4)


def heat_sources_case(tmp_path: Path) -> Path:
    """Debian's heatTransfer_2, unchanged: heatTransfer_1's pour, then at step 20000 (0.5 s)
    heat/gran's per-atom heatSource set to +1.5 W in the region x > 0.03 m and -1.5 W in x < -0.03 m
    (``set region ... property/atom heatSource``), and a run on to step 50000."""
    case = tmp_path / "heatTransfer_2"
    shutil.copytree(SOURCES, case)
    (case / "case.toml").write_text('[dem]\nscript = "in.heatGran"\n[effects]\ncontact_heat = "A"\n'
                                    + STEEL.replace("100.0 ", "5.0 ").replace("0.7", "0.95") + "[time]\ntest_end = 0.55\n"
                                    "[output]\nvtk = false\npictures = false\n")
    return case


def source_heat_expected(log: Path, steps_after_set: int, dt: float = 2.5e-5) -> float:
    """The heat [J] the sources put in, from LIGGGHTS' own count of the atoms each 'set' gave
    a source ('N settings made'): (N_plus - N_minus) 1.5 W over the steps since."""
    made = [int(line.split()[0]) for line in log.read_text().splitlines() if "settings made for property/atom" in line]
    assert len(made) == 2, made
    return (made[0] - made[1]) * 1.5 * steps_after_set * dt


@pytest.mark.long
@pytest.mark.skipif(not SOURCES.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_debian_heat_source_tutorial_closes_its_balance_with_the_sources_heat(tmp_path):
    """The heat heat/gran's sources put in is a term of the energy balance
    (heat_from_sources), summed at every step by the contact event recorder: it equals the
    sources' power times the time they ran (to round-off), and the balance closes. Before
    that term, the run failed its balance (exit 3): -4.5 J unaccounted over the full run."""
    case = heat_sources_case(tmp_path)
    r, summary = run(case, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert summary["steps"] == 22000
    expected = source_heat_expected(case / "out" / "dem" / "log.liggghts", 22000 - 20000)
    print(f"heat_from_sources {summary['heat_from_sources']!r} J, expected {expected!r} J")
    assert expected != 0.0
    assert summary["heat_from_sources"] == pytest.approx(expected, rel=1e-9)
    assert abs(summary["energy_balance_error"]) < 1e-12


def hot_floor_case(tmp_path: Path, walls: str = "") -> Path:
    """heatTransfer_1 with its floor at 1000 K for its fix heat/gran ('zplane 0.0 temperature
    1000.'), the scene's [[walls]] as given, run to 0.52 s by --test."""
    case = tmp_path / "heatTransfer_1"
    shutil.copytree(TUTORIAL, case)
    script = case / "in.heatGran"
    text = script.read_text()
    floor = next(line for line in text.splitlines() if line.startswith("fix zwalls1"))
    script.write_text(text.replace(floor, floor.rstrip() + " temperature 1000."))
    (case / "case.toml").write_text('[dem]\nscript = "in.heatGran"\n[effects]\ncontact_heat = "A"\n' + STEEL + walls
                                    + "[time]\ntest_end = 0.52\n[output]\nvtk = false\npictures = false\n")
    return case


@pytest.mark.skipif(not TUTORIAL.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_heat_gran_wall_with_a_temperature_enters_the_balance(tmp_path):
    """heatTransfer_1 with its floor at 1000 K for heat/gran ('zplane 0.0 temperature 1000.',
    LIGGGHTS' own wall conduction): the heat its walls conduct in is a term of the balance
    (heat_from_script_walls, the net of heat/gran's flux summed at every step, its pair
    terms cancelling), positive, and the balance closes. Without it the run failed (exit 3)
    with the balance 4080 J off over 0.55 s."""
    r, summary = run(hot_floor_case(tmp_path), "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert ("LIGGGHTS wall 'zwalls1' has no [[walls]] entry: adiabatic for collision heat (the script's fix "
            "heat/gran conducts through its contacts at 1000. K" in r.stdout)
    print(f"heat_from_script_walls {summary['heat_from_script_walls']:.6g} J, "
          f"balance {summary['energy_balance_error']:.3g}")
    assert summary["heat_from_script_walls"] > 100.0          # J: the floor heats the 300 K bed
    assert summary["heat_from_walls"] == 0.0                  # (the host's own walls: none in the scene)
    assert abs(summary["energy_balance_error"]) < 1e-12


@pytest.mark.skipif(not TUTORIAL.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_a_hot_script_wall_in_the_scene_gets_collision_heat_and_heat_grans_share_back(tmp_path):
    """heatTransfer_1 with its floor at 1000 K for heat/gran, and the scene's [[walls]] giving
    the floor the same temperature for collision heat: its collisions move the models' heat,
    what heat/gran conducted through each during the model's t_coll is taken back from the
    particle (heat_gran_walls_undone, as for pairs), and the balance closes. Before, the two
    were both counted (exit 0). A [[walls]] temperature other than the script's is refused at
    the first run (exit 2), naming both."""
    walls = '[[walls]]\nfix = "zwalls1"\nmaterial = "steel"\ntemperature = {T}\n'
    r, summary = run(hot_floor_case(tmp_path, walls.format(T=1000.0)), "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    print(f"wall collisions {summary['particle_wall']}, heat_from_walls {summary['heat_from_walls']:.6g} J, "
          f"heat_gran_walls_undone {summary['heat_gran_walls_undone']:.6g} J, heat_from_script_walls "
          f"{summary['heat_from_script_walls']:.6g} J, balance {summary['energy_balance_error']:.3g}")
    assert summary["particle_wall"] > 0 and summary["heat_from_walls"] > 0.0
    assert 0.0 < summary["heat_gran_walls_undone"] < summary["heat_from_script_walls"]
    assert abs(summary["energy_balance_error"]) < 1e-12
    r, _ = run(hot_floor_case(tmp_path / "other", walls.format(T=900.0)), "--test")
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    line = next(k for k, text in enumerate((tmp_path / "other" / "heatTransfer_1" / "in.heatGran").read_text()
                                            .splitlines(), 1) if text.startswith("fix zwalls1"))
    assert f"walls[0].temperature: 900 K, where the script gives wall 'zwalls1' 1000 K (" in r.stderr
    assert f"in.heatGran:{line})" in r.stderr, r.stderr          # the wall fix's own line


@pytest.mark.long
@pytest.mark.skipif(not SOURCES.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_heat_gran_script_with_sources_restarts_bit_for_bit(tmp_path):
    """heatTransfer_2 (fix heat/gran conducting, its sources on) stopped by SIGTERM at 0.5625 s,
    after the sources were set, and restarted: collisions.csv, history.csv and summary.json
    (heat_from_sources included) equal to the last bit those of the run that wrote its periodic
    checkpoint at that step (0.575 s, the end of the chunk) and went on."""
    whole = restarts_bit_for_bit(heat_sources_case(tmp_path), ("test_end = 0.55", "test_end = 0.6"), 0.575,
                                 "checkpoint at t = 0.575 s (step 23000)", 22500)
    assert whole["heat_from_sources"] != 0.0


def restarts_bit_for_bit(case: Path, end: tuple, checkpoint: float, said: str, stop_at: int) -> dict:
    """``case`` run with --test to its end changed as ``end`` (old, new) and a periodic
    checkpoint at ``checkpoint`` [s] (which it ``said``), and again stopped by SIGTERM at step
    ``stop_at`` (checkpointing at the same step) then restarted: collisions.csv, history.csv and
    summary.json equal to the last bit. Returns the summary."""
    from conftest import STOPPER

    text = (case / "case.toml").read_text().replace(*end)
    (case / "case.toml").write_text(text.replace("[output]\n", f"[output]\ncheckpoint = {checkpoint}\n"))
    r, whole = run(case, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert said in r.stdout
    cut = case.parent / "cut"
    stopped = subprocess.run([sys.executable, "-c", STOPPER, str(stop_at), "SIGTERM", "run", str(case), "--test",
                              "--out", str(cut)], capture_output=True, text=True, cwd=ROOT, timeout=900)
    assert stopped.returncode == 128 + 15, stopped.stdout[-3000:] + stopped.stderr[-3000:]
    assert said in stopped.stdout
    again = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--test", "--out", str(cut),
                            "--restart"], capture_output=True, text=True, cwd=ROOT, timeout=900)
    assert again.returncode == 0, again.stdout[-3000:] + again.stderr[-3000:]
    for name in ("collisions.csv", "history.csv"):
        assert (cut / name).read_bytes() == (case / "out" / name).read_bytes(), name
    assert json.loads((cut / "summary.json").read_text()) == whole
    return whole


@pytest.mark.long
@pytest.mark.skipif(not TUTORIAL.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_hot_script_wall_take_back_restarts_bit_for_bit(tmp_path):
    """heatTransfer_1 with its 1000 K floor in the script and in [[walls]] (heat/gran's share of
    each wall collision taken back) stopped by SIGTERM after the half bed's Temp set and
    restarted: collisions.csv, history.csv and summary.json (heat_gran_walls_undone included)
    equal to the last bit those of the run that wrote its periodic checkpoint at that step."""
    case = hot_floor_case(tmp_path, '[[walls]]\nfix = "zwalls1"\nmaterial = "steel"\ntemperature = 1000.0\n')
    whole = restarts_bit_for_bit(case, ("test_end = 0.52", "test_end = 0.53"), 0.51,
                                 "checkpoint at t = 0.51 s (step 20400)", 20200)
    assert whole["heat_gran_walls_undone"] > 0.0


@pytest.mark.skipif(not STREAM.is_dir(), reason="liggghts-doc is installed by tools/setup_engines.sh")
def test_debian_restart_with_reset_timestep_before_its_first_run_runs_unchanged(tmp_path):
    """insert_stream's second script reads the restart the first writes, then 'reset_timestep 0',
    'reset_timestep 50000' and 'run 1'. After a read_restart LIGGGHTS refuses a new fix between
    reset_timestep and run ('must come immediately before run'), which is where the host added
    its fixes: the run ended at once (exit 2). The host now adds them before the resets, which
    still take effect: the run goes on from step 50000 (0.5 s at its 1e-5 s step)."""
    case = tmp_path / "insert_stream"
    shutil.copytree(STREAM, case)
    first = subprocess.run(["liggghts", "-in", "in.insert_stream", "-screen", "/dev/null"], cwd=case, capture_output=True,
                           text=True, timeout=300)
    assert first.returncode == 0 and (case / "post" / "liggghts.restart").exists(), first.stdout[-2000:]
    (case / "case.toml").write_text('[dem]\nscript = "in.insert_stream_reset_timestep"\n[effects]\ncontact_heat = "A"\n'
                                    + glass_toml() + "[time]\ntest_end = 0.03\n[output]\nvtk = false\npictures = false\n")
    r, summary = run(case, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "reset_timestep: LIGGGHTS takes no new fix between" in r.stdout
    assert summary["steps"] == 3000 and summary["time"] == pytest.approx(0.53)
    assert abs(summary["energy_balance_error"]) < 1e-12
    with open(case / "out" / "collisions.csv") as f:
        times = [float(row["time"]) for row in csv.DictReader(f)]
    assert times and min(times) > 0.5, times[:3]


@pytest.fixture(scope="module")
def silo(tmp_path_factory):
    case = tmp_path_factory.mktemp("silo") / "silo-heat"
    shutil.copytree(ROOT / "cases" / "silo-heat", case, ignore=shutil.ignore_patterns("output", "post", "log.*"))
    script = case / "in.liggghts"       # a fix print into a folder nobody made (settlingTestMPI's DEM/post)
    text = script.read_text()
    first_run = text.index("\nrun")
    script.write_text(text[:first_run] + '\nfix told all print 1000 "poured" file printed/by/fix.txt screen no'
                      + text[first_run:])
    r, summary = run(case, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert f"made the folder {case / 'printed' / 'by'}" in r.stdout and (case / "printed" / "by" / "fix.txt").is_file()
    return case, summary


def last_dump(folder: Path):
    files = sorted(folder.glob("particles_*.dump"), key=lambda f: int(f.stem.split("_")[1]))
    lines = files[-1].read_text().splitlines()
    columns = lines[8].split()[2:]
    return {c: np.array([float(row.split()[k]) for row in lines[9:]]) for k, c in enumerate(columns)}


def test_silo_script_dumps_carry_the_collision_heat(silo):
    """The user's own dump (f_Temp[0]) shows the hot aluminium cooled and the cold glass warmed;
    heat/gran alone could do that too, so the host's own record must agree: what the
    collisions moved out of the aluminium is in its temperatures."""
    case, summary = silo
    d = last_dump(case / "post")
    al, glass = d["type"] == 1, d["type"] == 2
    assert al.sum() == 400 and glass.sum() == 500 and summary["inserted"] == 900
    assert d["f_Temp[0]"][al].min() < 400.0 and d["f_Temp[0]"][glass].max() > 300.0
    assert len(set(np.round(d["radius"], 7))) == 4                       # polydisperse, two radii each
    assert summary["particle_particle"] > 1000 and summary["particle_wall"] > 100
    assert summary["collisions"] == summary["particle_particle"] + summary["particle_wall"]


def test_silo_balance_closes(silo):
    _, summary = silo
    assert abs(summary["energy_balance_error"]) < 1e-12
    assert summary["capped"] == 0


def test_silo_groups_move_apart_from_their_start(silo):
    case, _ = silo
    rows = list(csv.DictReader(open(case / "out" / "history.csv")))
    last = rows[-1]
    assert float(last["T_group0"]) < 400.0 and float(last["T_group1"]) > 300.0     # aluminium, glass


BAD = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block 0 0.01 0 0.01 0 0.01 units box
create_box 2 box
fix m1 all property/global youngsModulus peratomtype 5e6 5e6
fix_typo m2 all property/global poissonsRatio peratomtype 0.3 0.3
run 10
"""


def test_script_error_names_the_script_line(tmp_path):
    (tmp_path / "in.bad").write_text(BAD)
    (tmp_path / "case.toml").write_text('[dem]\nscript = "in.bad"\n[effects]\ncontact_heat = "A"\n' + STEEL)
    r, _ = run(tmp_path)
    assert r.returncode == 2
    assert "in.bad:10" in r.stderr and "ERROR" in r.stderr and "Traceback" not in r.stderr


def test_type_without_material_is_named(tmp_path):
    text = BAD.replace("fix_typo", "fix").replace("run 10", """
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.7 0.7 0.7 0.7
fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-6
create_atoms 1 single 0.003 0.005 0.005 units box
create_atoms 2 single 0.007 0.005 0.005 units box
set group all diameter 0.002 density 2500
fix integrate all nve/sphere
run 10""")
    (tmp_path / "in.two").write_text(text)
    (tmp_path / "case.toml").write_text('[dem]\nscript = "in.two"\n[effects]\ncontact_heat = "A"\n' + STEEL)
    r, _ = run(tmp_path)
    assert r.returncode == 2
    assert "atom type(s) [2] have no material" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.long
def test_silo_with_the_users_openfoam_case(tmp_path):
    """The same script with gas up through the user's hand-written OpenFOAM case (fluid/):
    the host copies the case, collheatFoam solves it, the particles feel it, the balance
    still closes, and the user's own case folder is left as it was."""
    case = tmp_path / "silo-heat"
    shutil.copytree(ROOT / "cases" / "silo-heat", case, ignore=shutil.ignore_patterns("output", "post", "log.*"))
    (case / "post").mkdir()
    text = (case / "case.toml").read_text()
    (case / "case.toml").write_text(text.replace("[effects]\n", "[effects]\nfluid = true\n").replace(
        "[time]\n", '[fluid]\ncase = "fluid"\ndrag = "difelice"\n\n[time]\ncouple_every = 20\n'))
    before = sorted(p.relative_to(case) for p in (case / "fluid").rglob("*"))
    r, summary = run(case, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert sorted(p.relative_to(case) for p in (case / "fluid").rglob("*")) == before
    assert abs(summary["energy_balance_error"]) < 1e-12 and summary["inserted"] == 900
    rows = list(csv.DictReader(open(case / "out" / "history.csv")))
    drop = float(rows[-1]["pressure_drop"])
    assert math.isfinite(drop) and drop > 0                 # the settled bed resists the gas
    assert (case / "out" / "vtk" / "fluid.pvd").exists()


def test_heat_capacity_differing_from_the_scripts_heat_gran_is_refused(tmp_path):
    """heat/gran integrates Temp with the script's thermalCapacity, the collisions with the
    scene's heat_capacity: if they differ the energies disagree, so the run stops at once."""
    case = tmp_path / "silo-heat"
    shutil.copytree(ROOT / "cases" / "silo-heat", case, ignore=shutil.ignore_patterns("output", "post", "log.*"))
    (case / "post").mkdir()
    text = (case / "case.toml").read_text()
    (case / "case.toml").write_text(text.replace("heat_capacity = 840.0", "heat_capacity = 800.0"))
    r, _ = run(case, "--test")
    assert r.returncode == 2
    assert "atom type 2" in r.stderr and "thermalCapacity 840" in r.stderr and "heat_capacity 800" in r.stderr
