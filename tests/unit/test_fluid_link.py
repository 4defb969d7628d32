"""The fluid link never waits for ever: small programs posing as collheatFoam simulate the
faults (never connects, dies, stops answering, blocks the request pipe) and the host ends each
with a FluidError naming what happened, within the time-out plus a small margin."""
import os
import stat
import sys
import time

import pytest

from pyhost.engines import openfoam
from pyhost.engines.fluid_case import box_case
from pyhost.engines.openfoam import FluidError, FluidSolver

TIMEOUT = 1.0       # s, given to the host
MARGIN = 2.0        # s, what the host may add (polling, killing, reaping)

# Each fake takes the solver's arguments (-case C -link L) and misbehaves at one point.
HEAD = f"""#!{sys.executable}
import os, struct, sys, time
link = sys.argv[sys.argv.index("-link") + 1]
"""
CONNECT = """fin = open(os.path.join(link, "rank0.in"), "rb", buffering=0)
fout = open(os.path.join(link, "rank0.out"), "wb", buffering=0)
fout.write(struct.pack("=i3dd", 1, 0.5, 0.5, 0.5, 1.0))
"""
FAKES = {
    "never_connects": HEAD + "time.sleep(600)\n",
    "dies_at_start": HEAD + "sys.exit(3)\n",
    "silent": HEAD + CONNECT + "fin.read(4)\ntime.sleep(600)\n",
    "dies_computing": HEAD + CONNECT + "fin.read(4)\nsys.exit(7)\n",
    "never_reads": HEAD + CONNECT + "time.sleep(600)\n",
}


@pytest.fixture
def fake(tmp_path, monkeypatch):
    def make(kind):
        exe = tmp_path / f"{kind}.py"
        exe.write_text(FAKES[kind])
        exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
        monkeypatch.setattr(openfoam, "SOLVER", exe)
        case = box_case(tmp_path / "case", lo=(0, 0, 0), hi=(1, 1, 1), cells=(1, 1, 1), rho=1.0, nu=1e-5,
                        boundaries={f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")})
        (case / "constant" / "polyMesh").mkdir(parents=True)
        (case / "constant" / "polyMesh" / "owner").write_text("")     # no blockMesh: a fake mesh
        return FluidSolver(case, timeout=TIMEOUT)
    return make


def no_process_left(fluid, pid):
    assert fluid.proc is None and not (fluid.case / ".link").exists()
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)


def timed_failure(call):
    start = time.monotonic()
    with pytest.raises(FluidError) as err:
        call()
    return str(err.value), time.monotonic() - start


def test_solver_that_never_connects_is_a_start_time_out(fake):
    fluid = fake("never_connects")
    message, took = timed_failure(lambda: fluid.__enter__())
    assert "start time-out" in message and "never opened the link" in message
    assert "SIGKILL" not in message
    assert TIMEOUT <= took < TIMEOUT + MARGIN


def test_solver_dying_at_start_gives_its_exit_code(fake):
    fluid = fake("dies_at_start")
    message, took = timed_failure(lambda: fluid.__enter__())
    assert "while starting (exit code 3)" in message
    assert took < MARGIN


@pytest.mark.parametrize("kind,words", [("silent", "did not answer within"),
                                        ("dies_computing", "exit code 7")])
def test_solver_failing_mid_run(fake, kind, words):
    fluid = fake(kind).start()
    pid = fluid.proc.pid
    message, took = timed_failure(lambda: fluid.advance(1e-3))
    assert words in message and "while computing" in message
    assert took < TIMEOUT + MARGIN
    fluid.stop()
    no_process_left(fluid, pid)


def test_full_request_pipe_times_out(fake):
    """A request larger than the pipe's buffer to a solver that does not read: the write
    itself has the deadline."""
    fluid = fake("never_reads").start()
    pid = fluid.proc.pid
    message, took = timed_failure(lambda: fluid.locate([[0.5, 0.5, 0.5]] * 100_000))
    assert "did not answer within" in message and "receiving a request" in message
    assert took < TIMEOUT + MARGIN
    fluid.stop()
    no_process_left(fluid, pid)


def test_stop_in_the_middle_of_an_exchange_kills_the_solver(fake):
    """An interrupt between request and answer: stop() must not speak the protocol."""
    fluid = fake("silent").start()
    pid = fluid.proc.pid
    fluid._busy = True
    start = time.monotonic()
    fluid.stop()
    assert time.monotonic() - start < MARGIN
    no_process_left(fluid, pid)


def test_solver_path_not_executable(fake):
    fluid = fake("silent")
    openfoam.SOLVER.chmod(0o644)
    message, _ = timed_failure(lambda: fluid.__enter__())
    assert "cannot start the fluid solver" in message and str(openfoam.SOLVER) in message


def test_the_fluid_runs_beside_the_dem_only_where_both_have_cores(monkeypatch):
    """[fluid] overlap: "always" and "never" as said; "auto" for a serial DEM when its cores
    hold one more process per fluid rank, never under mpirun (ranks bound to cores)."""
    from pyhost.effects import fluid

    assert fluid.overlapping("always", 4, 4) and not fluid.overlapping("never", 1, 1)
    monkeypatch.setattr(fluid.os, "sched_getaffinity", lambda pid: {0, 1})
    assert fluid.overlapping("auto", 1, 1)
    assert not fluid.overlapping("auto", 1, 2)          # 3 processes on 2 cores
    assert not fluid.overlapping("auto", 2, 1)          # under mpirun
    monkeypatch.setattr(fluid.os, "sched_getaffinity", lambda pid: {0})
    assert not fluid.overlapping("auto", 1, 1)
