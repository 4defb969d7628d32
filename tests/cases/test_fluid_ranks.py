"""The fluid exchange done on each LIGGGHTS rank (``pyhost.engines.fluid_ranks``) against the
gather path (every atom on rank 0, ``FluidSolver.particle_forces``): the same cells, fluid,
forces and per-cell fields, to the rounding of sums added rank by rank; the same failure when a
particle leaves the mesh. The bed is hot-cold-bed's (3,000 spheres, 10 x 1 x 32 cells) for
0.01 s: 100 exchanges."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = [pytest.mark.engines,
              pytest.mark.skipif(shutil.which("mpirun") is None, reason="no mpirun: tools/setup.sh --engines")]
CASES = Path(__file__).resolve().parents[2] / "cases"
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

# The host with fluid.ON_RANKS from FLUID_ON_RANKS ("" None, "0" False, "1" True); MESH_TOP [m]
# lowers the fluid mesh's top (the box case's hi z) below the bed; CROSS_CHECK: before each
# advance of the exchange on the ranks, rank 0 also gathers every atom and runs the gather path
# on the same fluid (its fields then put back), and prints the largest differences at the end.
DRIVER = """
import atexit, json, os, sys
import numpy as np
import pyhost.effects.fluid as fluid
import pyhost.engines.fluid_case as fluid_case
from pyhost.cli import main
from pyhost.effects import by_id
from pyhost.engines.fluid_ranks import force_on_rank

v = os.environ.get("FLUID_ON_RANKS", "")
fluid.ON_RANKS = None if v == "" else v == "1"
if os.environ.get("MESH_TOP"):
    real_box = fluid_case.box_case
    def box_case(path, *, hi, **kw):
        return real_box(path, hi=[hi[0], hi[1], float(os.environ["MESH_TOP"])], **kw)
    fluid_case.box_case = box_case
if os.environ.get("CROSS_CHECK"):
    worst, count = dict(force=0.0, alpha=0.0, ksl=0.0, us=0.0), [0, 0]
    real = fluid.FluidExchange.couple_on_ranks
    def couple_on_ranks(self):
        f, loop = self.fluid, self.loop
        advance = f.advance
        def checked(*args, **kwargs):
            fields = f._alpha.copy(), f._ksl.copy(), f._us.copy()
            parts = loop.dem.each_rank(force_on_rank, "collheat_fluid")
            ids, force = (np.concatenate([p[k] for p in parts]) for k in range(2))
            atoms = loop.dem.atoms(False)
            lo, hi, periodic = loop.dem.box()
            x = np.where(periodic, lo + np.mod(atoms.x - lo, hi - lo), atoms.x)
            gathered = f.particle_forces(x, atoms.v, 2.0 * atoms.radius)
            mine = by_id(ids, force, atoms.id)
            worst["force"] = max(worst["force"], np.abs(mine - gathered).max() / np.abs(gathered).max())
            for name, a, b in zip(("alpha", "ksl", "us"), fields, (f._alpha, f._ksl, f._us)):
                worst[name] = max(worst[name], np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))
            count[0] += 1
            count[1] += int(np.array_equal(mine, gathered))
            f._alpha, f._ksl, f._us = fields      # the run goes on with the ranks' fields
            return advance(*args, **kwargs)
        f.advance = checked
        try:
            return real(self)
        finally:
            f.advance = advance
    fluid.FluidExchange.couple_on_ranks = couple_on_ranks
    from mpi4py import MPI
    if MPI.COMM_WORLD.Get_rank() == 0:
        atexit.register(lambda: print("CROSS_CHECK", json.dumps(dict(worst, exchanges=count[0], equal=count[1]))))
sys.exit(main(sys.argv[1:]))
"""


def bed(tmp_path, extra=""):
    """hot-cold-bed for 0.01 s, a frame every 1 ms, the fluid on two ranks, no pictures."""
    case = tmp_path / "bed"
    shutil.copytree(CASES / "hot-cold-bed", case, ignore=shutil.ignore_patterns("output", "log.*"))
    text = (case / "case.toml").read_text()
    for old, new in (("test_end = 0.05", "test_end = 0.01"), ("every = 0.01", "every = 0.001"),
                     ('sides = "slip"', 'sides = "slip"\nranks = 2')):
        assert old in text
        text = text.replace(old, new)
    (case / "case.toml").write_text(text + "pictures = false\n" + extra)
    return case


def run(case, out, ranks, env=None, code=0):
    cmd = [sys.executable, "-c", DRIVER, "run", str(case), "--test", "--out", str(out)]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd
    r = subprocess.run(cmd, capture_output=True, text=True, env=dict(ENV, **(env or {})), timeout=600)
    assert r.returncode == code, r.stdout[-3000:] + r.stderr[-3000:]
    return r


def cross_check(r) -> dict:
    check = json.loads(r.stdout.split("CROSS_CHECK", 1)[1].splitlines()[0])
    print(check)
    assert check["exchanges"] == 101                     # the start's and one every 1e-4 s
    return check


def test_exchange_on_each_rank_equals_the_gathered_one(tmp_path):
    """On two ranks, at each of the 101 exchanges: each particle's force as the gather path
    computes it on the same fluid (bit for bit: measured), and the cells' fluid fraction, Ksl
    and Us (bit for bit). LIGGGHTS cuts the box at x = 20 mm, a face of the fluid's cells: a
    cell's particles are on one rank, except those past the cut until LIGGGHTS' next neighbour
    build. The whole run against the gather path's: the same collisions.csv and history.csv
    (a fluid run's frames gather the atoms on both paths, and its bed height is theirs)."""
    case = bed(tmp_path)
    check = cross_check(run(case, tmp_path / "ranks", 2, dict(CROSS_CHECK="1")))
    for name in ("force", "alpha", "ksl", "us"):
        assert check[name] == 0.0, name
    run(case, tmp_path / "gathered", 2, dict(FLUID_ON_RANKS="0"))
    a, b = ((tmp_path / on / "collisions.csv").read_bytes() for on in ("ranks", "gathered"))
    assert a == b and a.count(b"\n") > 100
    a, b = (np.genfromtxt(tmp_path / on / "history.csv", delimiter=",", names=True) for on in ("ranks", "gathered"))
    assert len(a) == len(b) == 11
    for column in a.dtype.names:
        assert np.array_equal(a[column], b[column], equal_nan=True), column


def test_exchange_on_ranks_cutting_through_cells_equals_the_gathered_one_to_rounding(tmp_path):
    """The same bed on 7 x 1 x 32 cells: LIGGGHTS' cut at x = 20 mm halves the fourth column of
    cells, whose sums each rank adds over its own particles, then the ranks together (the
    gather path: over all particles in their order). At each of the 101 exchanges every force
    within 1e-12 of the largest force, the fluid fraction, Ksl and Us within 1e-12 of their
    largest (measured: forces 2.6e-16, fraction 4.4e-16, Ksl and Us 2.2e-15; 100 of the 101
    exchanges differ in some bit)."""
    case = bed(tmp_path)
    toml = case / "case.toml"
    toml.write_text(toml.read_text().replace("cells = [10, 1, 32]", "cells = [7, 1, 32]"))
    check = cross_check(run(case, tmp_path / "ranks", 2, dict(CROSS_CHECK="1")))
    for name in ("force", "alpha", "ksl", "us"):
        assert check[name] <= 1e-12, name


def test_exchange_on_the_one_rank_of_a_serial_run_is_the_gather_path_bit_for_bit(tmp_path):
    """Serially (forced on: fluid.ON_RANKS = True) the one rank's sums are the gather path's
    sums, in the same order: collisions.csv, history.csv and the VTK frames are the same
    bytes. This holds only if every particle gets OpenFOAM's own cell from the mesh's planes
    and its cell's fluid from the LOCATE of the cell centres."""
    case = bed(tmp_path, "")
    run(case, tmp_path / "ranks", 1, dict(FLUID_ON_RANKS="1"))
    run(case, tmp_path / "gathered", 1, dict(FLUID_ON_RANKS="0"))
    for name in ["collisions.csv", "history.csv"] + sorted(p.name for p in (tmp_path / "gathered" / "vtk").iterdir()):
        sub = "" if name.endswith(".csv") else "vtk"
        a, b = ((tmp_path / on / sub / name).read_bytes() for on in ("ranks", "gathered"))
        assert a == b, name


def test_a_particle_outside_the_mesh_fails_the_run_naming_it_as_the_gather_path(tmp_path):
    """The fluid mesh's top lowered to 20 mm, below the upper half of the bed (up to 30 mm): at
    the first exchange, exit 3 with the same message on the ranks as gathered (the count of
    particles outside, the first in rank order by id, its position and velocity)."""
    case = bed(tmp_path)
    lines = {}
    for on in ("", "0"):
        r = run(case, tmp_path / f"out{on}", 2, dict(FLUID_ON_RANKS=on, MESH_TOP="0.02"), code=3)
        lines[on] = [line for line in r.stderr.splitlines() if "outside the fluid's mesh" in line]
        summary = json.loads((tmp_path / f"out{on}" / "summary.json").read_text())
        assert "LeftTheMesh" in summary["status"]
    assert len(lines[""]) == 1 and lines[""] == lines["0"]
    count = int(lines[""][0].split(" particle(s) are outside")[0].rsplit(" ", 1)[1])
    assert 500 < count < 3000, lines[""]


def test_checkpoint_of_the_exchange_on_the_ranks_holds_the_forces_and_continues_as_gathered(tmp_path):
    """The bed on two ranks with a checkpoint at its end (0.01 s): the fluid forces the
    checkpoint keeps, gathered from the ranks' LIGGGHTS, are the gather path's (ids and forces,
    bit for bit); continued for 2 ms more (--restart --extend), it gives the gathered run's
    collisions.csv."""
    case = bed(tmp_path, "checkpoint = 0.02\n")
    forces = {}
    for on in ("", "0"):
        out = tmp_path / f"out{on}"
        run(case, out, 2, dict(FLUID_ON_RANKS=on))
        with np.load(out / "checkpoint" / "host.npz") as saved:
            forces[on] = saved["fluid_ids"], saved["fluid_force"]
        r = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", sys.executable, "-c", DRIVER, "run", str(case),
                            "--test", "--out", str(out), "--restart", "--extend", "0.002"], capture_output=True,
                           text=True, env=dict(ENV, FLUID_ON_RANKS=on), timeout=600)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert len(forces[""][0]) == 3000 and np.abs(forces[""][1]).max() > 0
    for k in range(2):
        assert np.array_equal(forces[""][k], forces["0"][k])
    a, b = ((tmp_path / f"out{on}" / "collisions.csv").read_bytes() for on in ("", "0"))
    assert a == b and a.count(b"\n") > 100
