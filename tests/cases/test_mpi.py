"""The host under ``mpirun -np 2``: LIGGGHTS decomposes the domain over two ranks, the host on
rank 0 sees every collision once (also a pair that spans the ranks), and the results equal the
serial run's: exactly for one binary collision, to the chaos of a granular gas otherwise."""
import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import FLOOR_STL, POUR_SCRIPT, STOPPER, glass_toml, pour

pytestmark = [pytest.mark.engines,
              pytest.mark.skipif(shutil.which("mpirun") is None, reason="no mpirun: tools/setup.sh --engines")]
CASES = Path(__file__).resolve().parents[2] / "cases"
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(case, out, ranks, *extra):
    cmd = [sys.executable, "-m", "pyhost", "run", str(case), "--out", str(out), *extra]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return json.loads((out / "summary.json").read_text())


def grid(out):
    """LIGGGHTS' processor grid, from its own log."""
    for line in (out / "dem" / "log.liggghts").read_text().splitlines():
        if "MPI processor grid" in line:
            return line.split("MPI")[0].strip()
    return None


def pair_across_the_boundary(tmp_path):
    """two-particles with its spheres on either side of x = 0.05 m, where LIGGGHTS cuts the
    0.1 m long box between its two ranks."""
    case = tmp_path / "case"
    shutil.copytree(CASES / "two-particles", case, ignore=shutil.ignore_patterns("output", "log.*"))
    toml = case / "case.toml"
    text = toml.read_text()
    for old, new in (("[[0.045, 0.005, 0.01]]", "[[0.0478, 0.005, 0.01]]"),
                     ("[[0.0492, 0.005, 0.01]]", "[[0.0522, 0.005, 0.01]]")):
        assert old in text
        text = text.replace(old, new)
    toml.write_text(text)
    return case


def test_contact_events_of_a_pair_across_the_rank_boundary_equal_the_serial_run(tmp_path):
    """The same pair on contact events: the rank owning the smaller id records it, rank 0 joins
    the ranks' events. The collision row (impact speed at touch, heat, e, t_coll) and the
    history are the serial run's bit for bit. Restitution feedback: the recorder changes only
    its own rank's atoms, so the separation speed e v0 of a pair on two ranks is imposed by the
    host at the harvest after the end (restitution_late, 1 here) instead of at the end's step."""
    case = pair_across_the_boundary(tmp_path)
    serial = run(case, tmp_path / "np1", 1)
    parallel = run(case, tmp_path / "np2", 2)
    assert grid(tmp_path / "np2") == "2 by 1 by 1"
    assert serial["collisions"] == 1 and serial.pop("restitution_late") == 0
    assert parallel.pop("restitution_late") == 1
    assert parallel == serial
    for name in ("collisions.csv", "history.csv"):
        assert (tmp_path / "np2" / name).read_bytes() == (tmp_path / "np1" / name).read_bytes(), name


def test_frames_written_in_pieces_on_two_ranks_are_the_serial_frames(tmp_path):
    """The pair across the cut without restitution feedback (nothing then changes a velocity
    but LIGGGHTS, on either rank count): every frame of the two-rank run, written in pieces
    (each rank its own particle, rank 0 the .pvtu), read back equals the serial run's .vtu
    bit for bit once sorted by id (``assert_frames_equal``); history.csv too."""
    case = pair_across_the_boundary(tmp_path)
    toml = case / "case.toml"
    assert "restitution_feedback = true" in toml.read_text()
    toml.write_text(toml.read_text().replace("restitution_feedback = true", "restitution_feedback = false")
                    + "pictures = false\n")
    serial = run(case, tmp_path / "np1", 1)
    run(case, tmp_path / "np2", 2)
    assert serial["collisions"] == 1
    assert (tmp_path / "np2" / "history.csv").read_bytes() == (tmp_path / "np1" / "history.csv").read_bytes()
    assert_frames_equal(tmp_path / "np1" / "vtk", tmp_path / "np2" / "vtk", ranks=2)


def assert_frames_equal(serial, parallel, ranks):
    """The frames of a run on ``ranks`` ranks, each written in pieces (one .vtu per rank, a
    .pvtu naming them, the .pvd listing the .pvtu files), read back by pyvista: the serial
    run's frames (one .vtu each), point for point once sorted by id, every array bit for bit,
    at the same times."""
    import pyvista

    one, many = pyvista.get_reader(str(serial / "particles.pvd")), pyvista.get_reader(str(parallel / "particles.pvd"))
    assert many.time_values == one.time_values and len(one.time_values) > 2
    files = sorted(p.name for p in parallel.glob("particles_*"))
    frames = len(one.time_values)
    assert files == sorted([f"particles_{k:05d}.pvtu" for k in range(frames)]
                           + [f"particles_{k:05d}_p{r}.vtu" for k in range(frames) for r in range(ranks)])
    for k in range(frames):
        a, b = (pyvista.read(str(folder / name)) for folder, name in
                ((serial, f"particles_{k:05d}.vtu"), (parallel, f"particles_{k:05d}.pvtu")))
        assert sorted(a.point_data.keys()) == sorted(b.point_data.keys())
        ia, ib = np.argsort(a["id"]), np.argsort(b["id"])
        assert np.array_equal(a.points[ia], b.points[ib]), k
        for name in a.point_data.keys():
            assert b[name].dtype == a[name].dtype and np.array_equal(a[name][ia], b[name][ib]), (k, name)


@pytest.mark.long
def test_granular_gas_on_two_ranks(tmp_path):
    """hot-cold-box's smoke run (1000 spheres, periodic): the same collisions within the
    chaos of the gas (the order of the force sums differs, so rounding does), and the heat
    balance to rounding on two ranks."""
    serial = run(CASES / "hot-cold-box", tmp_path / "np1", 1, "--test")
    parallel = run(CASES / "hot-cold-box", tmp_path / "np2", 2, "--test")
    assert grid(tmp_path / "np2") is not None and grid(tmp_path / "np2") != "1 by 1 by 1"
    assert parallel["status"] == "completed"
    assert abs(parallel["energy_balance_error"]) < 1e-12
    assert parallel["collisions"] == pytest.approx(serial["collisions"], rel=0.02)
    assert parallel["heat_moved"] == pytest.approx(serial["heat_moved"], rel=0.02)
    rows = list(csv.DictReader(open(tmp_path / "np2" / "collisions.csv")))
    keys = {(min(int(r["i"]), int(r["j"])), max(int(r["i"]), int(r["j"])), r["time"]) for r in rows}
    assert len(keys) == len(rows) == parallel["collisions"]        # each collision once, not once per rank




@pytest.mark.long
def test_poured_silo_on_two_ranks(tmp_path):
    """silo-heat --test (900 spheres poured into an STL tube onto a shaken plate, fix
    heat/gran) on two ranks split across z, each rank recording its own contacts. Settling
    spheres keep their contacts while they cross the ranks' boundary: those contacts end on one
    rank and begin on the other at a neighbour build, and are joined into one
    (contacts_changed_rank, 5 measured). One left unjoined would begin a second time while
    resting, without closing in (contacts_without_impact). Measured: 3 such, each an atom
    inserted (steps 4001 and 8001) onto another: LIGGGHTS' insertion on two ranks places a few
    particles overlapping; asserted at most 5. The balance closes to 1e-12. (The pour itself
    depends on the cut: 7,237 collisions on two ranks against 7,794 serially, measured; on two
    ranks the samples of session 32 gave 7,234.)"""
    case = tmp_path / "silo"
    shutil.copytree(CASES / "silo-heat", case, ignore=shutil.ignore_patterns("output", "post"))
    (case / "case.toml").write_text((case / "case.toml").read_text() + "pictures = false\n")
    r = run(case, tmp_path / "out", 2, "--test")
    print({k: r.get(k) for k in ("collisions", "particle_wall", "heat_moved", "contacts_changed_rank")})
    assert grid(tmp_path / "out") == "1 by 1 by 2"
    assert r["status"] == "completed" and r["inserted"] == 900
    assert r["collisions"] > 5000 and r["particle_wall"] > 1000
    assert r.get("contacts_changed_rank", 0) > 0 and r.get("contacts_without_impact", 0) <= 5
    assert abs(r["energy_balance_error"]) < 1e-12


# conftest's pour without heat/gran, dumps or computes, 300 spheres
POUR = "\n".join(line for line in POUR_SCRIPT.splitlines()
                 if not line.startswith(("fix heat ", "fix m5 ", "fix m6 ", "compute ", "dump ", "thermo"))) \
    .replace("nparticles 60", "nparticles 300").replace("particlerate 6000", "particlerate 20000") \
    .replace("run 6000", "run 8000") + "\n"

COUNT_PARTIAL = """
import atexit, sys
import pyhost.effects.collisions as collisions
import pyhost.engines.dem as dem
from pyhost.cli import main
from mpi4py import MPI
collisions.ON_RANKS = False          # rank 0 moves all collision heat
if MPI.COMM_WORLD.Get_rank() == 0:
    calls, real = [0], dem.Dem.atoms_of
    def atoms_of(self, *args, **kwargs):
        calls[0] += 1
        return real(self, *args, **kwargs)
    dem.Dem.atoms_of = atoms_of
    atexit.register(lambda: print(f"atoms_of calls: {calls[0]}"))
sys.exit(main(sys.argv[1:]))
"""


def test_harvests_between_frames_gather_only_the_colliding_atoms(tmp_path):
    """A user's pour (300 spheres of two sizes onto an STL floor, hot type 1 and cold type 2,
    no fix heat/gran) on two ranks, a frame only at the end, rank 0 moving all collision heat
    (as with restitution feedback): its harvests every 1,000 steps gather the atoms of their
    events only (Dem.atoms_of), not every atom. Against the
    same run with a frame at every harvest (every atom gathered then): the same pour (the
    host changes no velocity here), so the same collisions, contacts without impact and
    particles, heat moved to 1e-12 and each balance to 1e-12."""
    out = {}
    for every in (1.0, 0.01):           # 0.01 s = 1,000 steps: a frame at each harvest
        case = tmp_path / f"every{every}"
        case.mkdir()
        (case / "floor.stl").write_text(FLOOR_STL)
        (case / "in.pour").write_text(POUR)
        (case / "case.toml").write_text(f"""[dem]
script = "in.pour"
[effects]
contact_heat = "A"
{glass_toml("hot", "[1]", "temperature = 400.0")}{glass_toml("cold", "[2]", "temperature = 300.0")}[output]
every = {every}
vtk = false
pictures = false
""")
        r = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", sys.executable, "-c", COUNT_PARTIAL, "run",
                            str(case), "--out", str(case / "out")], capture_output=True, text=True, env=ENV,
                           timeout=600)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        out[every] = json.loads((case / "out" / "summary.json").read_text())
        out[every]["atoms_of"] = int(r.stdout.rsplit("atoms_of calls: ", 1)[1].split()[0])
    partly, whole = out[1.0], out[0.01]
    print({k: (partly.get(k), whole.get(k)) for k in ("atoms_of", "collisions", "particle_wall",
                                                      "contacts_without_impact", "heat_moved")})
    assert grid(tmp_path / "every1.0" / "out") != "1 by 1 by 1"
    assert partly["atoms_of"] >= 5 and whole["atoms_of"] == 0
    assert partly["inserted"] == whole["inserted"] == 300
    for key in ("collisions", "particle_wall", "contacts_without_impact"):
        assert partly.get(key, 0) == whole.get(key, 0), key
    for r in (partly, whole):
        assert r["status"] == "completed" and abs(r["energy_balance_error"]) < 1e-12
    assert partly["heat_moved"] == pytest.approx(whole["heat_moved"], rel=1e-12)


ON_RANKS = """
import os, sys
import pyhost.effects.collisions as collisions
from pyhost.cli import main
collisions.ON_RANKS = os.environ["ON_RANKS"] == "1"
collisions.ON_RANKS_FROM = int(os.environ.get("ON_RANKS_FROM", collisions.ON_RANKS_FROM))
sys.exit(main(sys.argv[1:]))
"""


def test_collision_heat_moved_on_each_rank_agrees_with_rank_0_moving_it(tmp_path):
    """The pour on two ranks cut across x (``processors 2 1 1``: both ranks pour), a frame only
    at the end. Each rank moves the heat of its own collisions (pyhost.effects.rank_heat),
    against rank 0 moving all in their order. The pour is the same (the host changes no
    velocity), so the collisions are the same: times, ids, impact speeds, e and t_coll equal.
    A particle whose collisions of one batch were moved in two places met them out of order:
    each collision's heat within 1e-5 of the largest collision's (measured 1.8e-6, 2e-12 J),
    heat moved within 1e-6 (4.8e-8), mean temperatures within 1e-9 K (1.5e-11 K, of a 2.7e-4 K
    change). Most collisions are moved on their rank (measured 9,661 of 9,974)."""
    case = tmp_path / "case"
    case.mkdir()
    (case / "floor.stl").write_text(FLOOR_STL)
    (case / "in.pour").write_text(POUR.replace("atom_style granular\n", "atom_style granular\nprocessors 2 1 1\n"))
    (case / "case.toml").write_text(f"""[dem]
script = "in.pour"
[effects]
contact_heat = "A"
{glass_toml("hot", "[1]", "temperature = 400.0")}{glass_toml("cold", "[2]", "temperature = 300.0")}[output]
every = 1.0
vtk = false
pictures = false
""")
    ranks, alone, a, b = ranks_against_rank_0(case, tmp_path)
    print({k: (ranks.get(k), alone.get(k)) for k in ("collisions", "collisions_moved_on_ranks", "heat_moved",
                                                     "energy_balance_error")})
    assert grid(tmp_path / "1") == "2 by 1 by 1"
    assert ranks["collisions"] == alone["collisions"] > 5000
    assert ranks["collisions_moved_on_ranks"] > 0.8 * ranks["collisions"] and alone["collisions_moved_on_ranks"] == 0
    assert ranks["heat_moved"] == pytest.approx(alone["heat_moved"], rel=1e-6)
    for r in (ranks, alone):
        assert r["status"] == "completed" and abs(r["energy_balance_error"]) < 1e-12
    for column in ("time", "i", "j", "wall", "v0", "e", "t_coll"):
        assert np.array_equal(a[column], b[column]), column
    dQ = np.abs(a["Q"] - b["Q"]).max()
    print(f"largest heat difference {dQ:.3g} J, {dQ / np.abs(b['Q']).max():.3g} of the largest heat")
    assert dQ <= 1e-5 * np.abs(b["Q"]).max()
    a, b = (np.genfromtxt(tmp_path / on / "history.csv", delimiter=",", names=True) for on in ("1", "0"))
    for column in ("T_mean", "T_group0", "T_group1"):
        assert np.nanmax(np.abs(a[column] - b[column])) < 1e-9, column


def ranks_against_rank_0(case, tmp_path, *extra, fewest=256):
    """``case`` on two ranks, each moving its own collisions' heat (batches from ``fewest``
    collisions on) and rank 0 moving all: the two summaries and collisions.csv tables."""
    out = {}
    for on in ("1", "0"):
        r = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", sys.executable, "-c", ON_RANKS, "run",
                            str(case), *extra, "--out", str(tmp_path / on)], capture_output=True, text=True,
                           env=dict(ENV, ON_RANKS=on, ON_RANKS_FROM=str(fewest)), timeout=600)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        out[on] = json.loads((tmp_path / on / "summary.json").read_text())
    tables = [np.genfromtxt(tmp_path / on / "collisions.csv", delimiter=",", names=True, dtype=None, encoding=None)
              for on in ("1", "0")]
    return out["1"], out["0"], *tables


def box_variant(tmp_path, old, new, extra=""):
    case = tmp_path / "box"
    shutil.copytree(CASES / "hot-cold-box", case, ignore=shutil.ignore_patterns("output", "log.*"))
    text = (case / "case.toml").read_text()
    assert old in text
    (case / "case.toml").write_text(text.replace(old, new) + extra)
    return case


@pytest.mark.long
def test_box_with_a_hot_wall_moves_heat_on_each_rank_as_rank_0_does(tmp_path):
    """hot-cold-box --test closed in z by a wall at 500 K below and an adiabatic one above, on
    two ranks (frames every 10,000 steps: nine of its ten harvests come alone): each rank
    moving its own collisions' heat (particle-wall ones included) against rank 0 moving all.
    The same 8,719 collisions; the walls' heat within 1e-9 (measured 2e-15), each
    collision's heat within 1e-4 of the largest (7.2e-6), the balance to 1e-12."""
    case = box_variant(tmp_path, "periodic = [true, true, true]", "periodic = [true, true, false]", """
[[walls]]
plane = "zlo"
material = "steel"
temperature = 500.0

[[walls]]
plane = "zhi"
material = "steel"
""")
    ranks, alone, a, b = ranks_against_rank_0(case, tmp_path, "--test")
    assert ranks["collisions"] == alone["collisions"] and ranks["particle_wall"] == alone["particle_wall"] > 100
    assert ranks["collisions_moved_on_ranks"] > 0.8 * ranks["collisions"]
    assert ranks["heat_from_walls"] == pytest.approx(alone["heat_from_walls"], rel=1e-9) and ranks["heat_from_walls"] > 0
    for r in (ranks, alone):
        assert r["status"] == "completed" and abs(r["energy_balance_error"]) < 1e-12
    for column in ("time", "i", "j", "wall", "v0"):
        assert np.array_equal(a[column], b[column]), column
    assert np.abs(a["Q"] - b["Q"]).max() <= 1e-4 * np.abs(b["Q"]).max()


@pytest.mark.long
def test_restitution_feedback_with_heat_on_each_rank_as_rank_0_gives_it(tmp_path):
    """hot-cold-box --test with restitution feedback (harvests every 10 steps) on two ranks:
    each rank moving its own collisions' heat (its batches of about 6 collisions too, which a
    run leaves to rank 0: ON_RANKS_FROM), rank 0 giving every collision its separation speed
    (the model's e depends on the impact speed alone), against rank 0 doing both. The
    velocities are the same, so are the 6,449 collisions, their e and the late ones; each
    collision's heat within 1e-9 of the largest (measured: one of 6,449 differs, by 8e-12)."""
    case = box_variant(tmp_path, "restitution_feedback = false", "restitution_feedback = true")
    ranks, alone, a, b = ranks_against_rank_0(case, tmp_path, "--test", fewest=0)
    assert ranks["collisions"] == alone["collisions"] > 5000
    assert ranks["collisions_moved_on_ranks"] > 0.8 * ranks["collisions"]
    assert ranks.get("restitution_late", 0) == alone.get("restitution_late", 0) > 0
    assert ranks["clipped"] == alone["clipped"]
    for column in ("time", "i", "j", "wall", "v0", "e"):
        assert np.array_equal(a[column], b[column]), column
    assert np.abs(a["Q"] - b["Q"]).max() <= 1e-9 * np.abs(b["Q"]).max()
    for r in (ranks, alone):
        assert r["status"] == "completed" and abs(r["energy_balance_error"]) < 1e-12


@pytest.mark.long
def test_fluidized_bed_moves_heat_on_each_rank_at_its_exchanges(tmp_path):
    """hot-cold-bed --test (LIGGGHTS on two ranks, the fluid on one) on two ranks: its harvests
    come every 1,000 steps (alone: its fluid exchanges read no temperature) and at frames,
    where each rank moves its own collisions' heat before rank 0 gathers the atoms for the
    frame; against rank 0 moving all. The same 40,531 collisions (measured; 39,858 moved on their rank), each
    collision's heat within 1e-5 of the largest (1.0e-6), mean temperatures within 1e-9 K
    (6e-14 K), both balances closed."""
    ranks, alone, a, b = ranks_against_rank_0(CASES / "hot-cold-bed", tmp_path, "--test")
    assert ranks["collisions"] == alone["collisions"] > 10000
    assert ranks["collisions_moved_on_ranks"] > 0.8 * ranks["collisions"]
    for r in (ranks, alone):
        assert r["status"] == "completed" and abs(r["energy_balance_error"]) < 1e-12
    for column in ("time", "i", "j", "wall", "v0", "e"):
        assert np.array_equal(a[column], b[column]), column
    assert np.abs(a["Q"] - b["Q"]).max() <= 1e-5 * np.abs(b["Q"]).max()
    a, b = (np.genfromtxt(tmp_path / on / "history.csv", delimiter=",", names=True) for on in ("1", "0"))
    for column in ("T_mean", "T_group0", "T_group1"):
        assert np.nanmax(np.abs(a[column] - b[column])) < 1e-9, column


@pytest.mark.long
def test_heat_sources_on_two_ranks_sum_as_serially(tmp_path):
    """Debian's heatTransfer_2 (heat/gran's per-atom heat sources) on two ranks: each rank's
    recorder sums the heat its own atoms' sources put in, and rank 0 adds them up:
    heat_from_sources equals LIGGGHTS' own count of the atoms given a source times their power
    and time, to 1e-9 as serially, and the balance closes."""
    from test_user_scripts import SOURCES, heat_sources_case, source_heat_expected
    if not SOURCES.is_dir():
        pytest.skip("liggghts-doc is installed by tools/setup_engines.sh")
    case = heat_sources_case(tmp_path)
    summary = run(case, tmp_path / "two", 2, "--test")
    assert grid(tmp_path / "two") != "1 by 1 by 1"
    expected = source_heat_expected(tmp_path / "two" / "dem" / "log.liggghts", summary["steps"] - 20000)
    assert expected != 0.0
    assert summary["heat_from_sources"] == pytest.approx(expected, rel=1e-9)
    assert abs(summary["energy_balance_error"]) < 1e-12


def test_killed_two_rank_run_restarts_from_its_checkpoint_exactly(tmp_path):
    """hot-cold-box --test on two ranks with a checkpoint every 4 ms, rank 0 killed outright at
    step 6003 (mpirun ends the job) and continued with --restart on two ranks: collisions.csv,
    history.csv and the summary are those of the two-rank run never stopped, bit for bit."""
    case = tmp_path / "box"
    shutil.copytree(CASES / "hot-cold-box", case, ignore=shutil.ignore_patterns("output", "log.*"))
    (case / "case.toml").write_text((case / "case.toml").read_text() + "\ncheckpoint = 0.004\npictures = false\n")
    whole = run(case, tmp_path / "whole", 2, "--test")
    mpirun = ["mpirun", "--oversubscribe", "-np", "2", sys.executable]
    cut = subprocess.run(mpirun + ["-c", STOPPER, "6003", "SIGKILL", "run", str(case), "--test", "--out", str(tmp_path / "cut")],
                         capture_output=True, text=True, env=ENV, timeout=600)
    assert cut.returncode != 0 and not (tmp_path / "cut" / "summary.json").exists()
    assert (tmp_path / "cut" / "checkpoint" / "manifest.json").is_file()
    shutil.copytree(tmp_path / "cut", tmp_path / "cut1")
    restarted = run(case, tmp_path / "cut", 2, "--test", "--restart")
    assert restarted == whole
    for name in ("collisions.csv", "history.csv"):
        assert (tmp_path / "cut" / name).read_bytes() == (tmp_path / "whole" / name).read_bytes(), name
    # the same checkpoint continued on one rank: LIGGGHTS redistributes the atoms on reading, the
    # host's state is global; the serial run is another rounding of the same gas (its chaos level
    # against two ranks, test_granular_gas_on_two_ranks: 2 %)
    serial = run(case, tmp_path / "cut1", 1, "--test", "--restart")
    assert grid(tmp_path / "cut1") == "1 by 1 by 1"
    assert_continued(serial, whole)


@pytest.mark.long
def test_finished_two_rank_run_extended_is_the_longer_run(tmp_path):
    """hot-cold-box --test (10 ms) on two ranks with a checkpoint every 5 ms ends in one at its
    end; --restart --extend 0.005 on two ranks gives byte for byte (collisions.csv,
    history.csv; summary values) the two-rank run of 15 ms with the same checkpoints."""
    def box(name, test_end):
        case = tmp_path / name
        shutil.copytree(CASES / "hot-cold-box", case, ignore=shutil.ignore_patterns("output", "log.*"))
        text = (case / "case.toml").read_text()
        assert "test_end = 0.01\n" in text
        (case / "case.toml").write_text(text.replace("test_end = 0.01\n", f"test_end = {test_end}\n")
                                        + "checkpoint = 0.005\npictures = false\n")
        return case

    case, longer = box("box", 0.01), box("longer", 0.015)
    first = run(case, tmp_path / "out", 2, "--test")
    assert first["status"] == "completed" and first["time"] == pytest.approx(0.01)
    extended = run(case, tmp_path / "out", 2, "--test", "--restart", "--extend", "0.005")
    whole = run(longer, tmp_path / "whole", 2, "--test")
    assert extended == whole and whole["time"] == pytest.approx(0.015)
    for name in ("collisions.csv", "history.csv"):
        assert (tmp_path / "out" / name).read_bytes() == (tmp_path / "whole" / name).read_bytes(), name


def assert_continued(restarted, whole):
    """A restart on another number of ranks: the run's end, energy to rounding, collisions and
    heat within the gas's chaos between rank counts."""
    assert restarted["status"] == "completed" and restarted["steps"] == whole["steps"]
    assert abs(restarted["energy_balance_error"]) < 1e-12
    assert restarted["collisions"] == pytest.approx(whole["collisions"], rel=0.02)
    assert restarted["heat_moved"] == pytest.approx(whole["heat_moved"], rel=0.02)


@pytest.mark.long
def test_serial_checkpoint_continues_on_two_ranks(tmp_path):
    """hot-cold-box --test killed at step 6003 on one rank, continued from its 4 ms checkpoint
    with mpirun -np 2."""
    case = tmp_path / "box"
    shutil.copytree(CASES / "hot-cold-box", case, ignore=shutil.ignore_patterns("output", "log.*"))
    (case / "case.toml").write_text((case / "case.toml").read_text() + "\ncheckpoint = 0.004\npictures = false\n")
    whole = run(case, tmp_path / "whole", 1, "--test")
    cut = subprocess.run([sys.executable, "-c", STOPPER, "6003", "SIGKILL", "run", str(case), "--test", "--out",
                          str(tmp_path / "cut")], capture_output=True, text=True, env=ENV, timeout=600)
    assert cut.returncode == -9 and (tmp_path / "cut" / "checkpoint" / "manifest.json").is_file()
    restarted = run(case, tmp_path / "cut", 2, "--test", "--restart")
    assert grid(tmp_path / "cut") not in (None, "1 by 1 by 1")
    assert_continued(restarted, whole)


@pytest.mark.long
def test_script_on_two_ranks_stopped_while_pouring_restarts_bit_for_bit(tmp_path):
    """cases/silo-heat --test (a user's script: insertion, an STL tube, a shaken plate) on two
    ranks with a checkpoint every 6005 steps, stopped by SIGTERM at step 6003 and restarted on
    two ranks: byte for byte the two-rank run never stopped, insertions included (each rank's
    random generators are put back). The same checkpoint continued on one rank completes."""
    runs = {}
    for name in ("whole", "cut"):
        runs[name] = tmp_path / name / "silo-heat"
        shutil.copytree(CASES / "silo-heat", runs[name], ignore=shutil.ignore_patterns("output", "post"))
        toml = runs[name] / "case.toml"
        toml.write_text(toml.read_text() + "pictures = false\ncheckpoint = 0.030025\n")
    whole = run(runs["whole"], tmp_path / "whole-out", 2, "--test")
    assert grid(tmp_path / "whole-out") == "1 by 1 by 2"
    out = tmp_path / "out"
    cut = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", sys.executable, "-c", STOPPER, "6003", "SIGTERM",
                          "run", str(runs["cut"]), "--test", "--out", str(out)], capture_output=True, text=True,
                         env=ENV, timeout=600)
    assert cut.returncode == 143, cut.stdout[-2000:] + cut.stderr[-2000:]
    shutil.copytree(out, tmp_path / "out1")
    restarted = run(runs["cut"], out, 2, "--test", "--restart")
    assert restarted == whole
    for name in ("collisions.csv", "history.csv"):
        assert (out / name).read_bytes() == (tmp_path / "whole-out" / name).read_bytes(), name
    serial = run(runs["cut"], tmp_path / "out1", 1, "--test", "--restart")
    assert serial["status"] == "completed" and serial["inserted"] == 900 and serial["steps"] == whole["steps"]
    # measured 5.4e-12 (2e-16 on the same number of ranks; cause not found): the issue asks 1e-9
    assert abs(serial["energy_balance_error"]) < 1e-10
    assert serial["collisions"] == pytest.approx(whole["collisions"], rel=0.1)



def test_finished_insertion_stays_finished_restarted_on_two_ranks(tmp_path):
    """A serial pour by 'insert/pack ... insert_every once' (50 beads at step 1) stopped by
    SIGTERM at step 1403 and restarted on two ranks: the insertion is not made again (LIGGGHTS'
    own restart made it again at the step after the restart: 68 beads). Measured: 50 beads, 258
    collisions and the floor's heat as the serial run never stopped; asserted: the same beads,
    collisions and heat within the 2 % between rank counts, the balance to 1e-12."""
    case = pour(tmp_path, "pack_once")
    whole = run(case, tmp_path / "whole", 1)
    cut = subprocess.run([sys.executable, "-c", STOPPER, "1403", "SIGTERM", "run", str(case), "--out",
                          str(tmp_path / "cut")], capture_output=True, text=True, env=ENV, timeout=600)
    assert cut.returncode == 143, cut.stdout[-2000:] + cut.stderr[-2000:]
    restarted = run(case, tmp_path / "cut", 2, "--restart")
    assert grid(tmp_path / "cut") == "1 by 1 by 2"
    print(f"inserted {restarted['inserted']} ({whole['inserted']}), collisions {restarted['collisions']} "
          f"({whole['collisions']}), heat from the floor {restarted['heat_from_walls']:.6g} J "
          f"({whole['heat_from_walls']:.6g})")
    assert restarted["status"] == "completed" and restarted["inserted"] == whole["inserted"] == 50
    assert restarted["collisions"] == pytest.approx(whole["collisions"], rel=0.02)
    assert restarted["heat_from_walls"] == pytest.approx(whole["heat_from_walls"], rel=0.02)
    assert abs(restarted["energy_balance_error"]) < 1e-12

def test_bad_scene_under_mpirun_exits_2_without_hanging(tmp_path):
    """Rank 0 refuses the scene before LIGGGHTS starts and releases the other rank: the job
    ends with rank 0's exit code and its one-line message."""
    r = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", sys.executable, "-m", "pyhost", "run",
                        str(tmp_path / "missing")], capture_output=True, text=True, env=ENV, timeout=120)
    assert r.returncode == 2
    assert "missing/case.toml: no such scene file" in r.stderr


BREAKER = """
import sys
import pyhost.engines.dem as dem
from pyhost.cli import main
from mpi4py import MPI
if MPI.COMM_WORLD.Get_rank() == 0:
    calls, real = [0], dem.gather_arrays
    def gather_arrays(comm, arrays):
        calls[0] += 1
        if calls[0] == 4:           # the other rank is already inside this collective call (a harvest)
            raise RuntimeError("injected fault inside a collective call")
        return real(comm, arrays)
    dem.gather_arrays = gather_arrays
sys.exit(main(sys.argv[1:]))
"""


def test_error_inside_a_collective_call_ends_every_rank(tmp_path):
    """An error on rank 0 while the other rank waits inside a collective call cannot be
    unwound in order: the job ends through MPI_Abort with the error's message and exit code,
    never hangs."""
    r = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", sys.executable, "-c", BREAKER, "run",
                        str(CASES / "hot-cold-box"), "--test", "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, env=ENV, timeout=300)
    assert r.returncode == 1
    assert "injected fault inside a collective call" in r.stderr


def test_lasting_conduction_between_two_ranks_is_the_serial_one(tmp_path):
    """cases/two-sphere-conduction's smoke run (50 s) on two ranks, its script's grid set to cut
    the box at x = 5 mm, between the two held spheres: the temperatures of every history row equal the serial
    run's to 1e-12 K (the host gathers the pair on rank 0 and writes Temp back to each owner)."""
    case = tmp_path / "case"
    shutil.copytree(CASES / "two-sphere-conduction", case, ignore=shutil.ignore_patterns("output", "log.*"))
    script = case / "in.liggghts"
    script.write_text(script.read_text().replace("units si\n", "units si\nprocessors 2 1 1\n"))
    serial = run(case, tmp_path / "serial", 1, "--test")
    parallel = run(case, tmp_path / "two", 2, "--test")
    assert grid(tmp_path / "two") == "2 by 1 by 1"
    rows = [list(csv.DictReader(open(tmp_path / name / "history.csv"))) for name in ("serial", "two")]
    assert len(rows[0]) == len(rows[1]) == 51
    for a, b in zip(*rows):
        assert abs(float(a["T_group0"]) - float(b["T_group0"])) < 1e-12
        assert abs(float(a["T_group1"]) - float(b["T_group1"])) < 1e-12
    assert parallel["heat_conducted_contact"] == pytest.approx(serial["heat_conducted_contact"], rel=1e-12)
    assert abs(parallel["energy_balance_error"]) < 1e-12
