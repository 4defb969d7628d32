"""SIGINT, SIGTERM and SIGHUP stop a real run the same clean way: exit 128 + n, summary.json
saying where and why it stopped, complete CSV files, no process left, no pipes left."""
import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]


def descendants(pid: int) -> set[int]:
    """Every living process below pid (children, grandchildren, their own sessions too)."""
    parent = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            parent[int(stat.parent.name)] = int(fields[1])
        except (OSError, IndexError, ValueError):
            continue
    found, todo = set(), [pid]
    while todo:
        p = todo.pop()
        kids = {c for c, pp in parent.items() if pp == p}
        found |= kids
        todo += kids
    return found


def alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def interrupt(out: Path, case: str, sig: int, *, ready, extra=(), group=False):
    """Start a run in a session of its own, wait until ``ready(out)``, send ``sig`` (to the
    whole process group when ``group``, as a terminal's Ctrl-C does); return the finished
    process, the processes it had, the time the signal was sent (s) and its exit time (s)."""
    proc = subprocess.Popen([sys.executable, "-m", "pyhost", "run", f"cases/{case}", "--out", str(out), *extra],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    deadline = time.monotonic() + 120
    while not ready(out):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the run never got going"
        time.sleep(0.1)
    children = descendants(proc.pid)
    sent = time.monotonic()
    (os.killpg if group else os.kill)(proc.pid, sig)
    stdout, stderr = proc.communicate(timeout=60)
    return proc, children, stdout, stderr, time.monotonic() - sent


def check_clean_stop(out, proc, children, stderr, sig, end):
    assert proc.returncode == 128 + sig, stderr[-2000:]
    assert "Traceback" not in stderr and signal.Signals(sig).name in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"].startswith("stopped at t = ") and signal.Signals(sig).name in summary["status"]
    assert 0 <= summary["time"] < end
    rows = list(csv.reader(open(out / "history.csv")))
    assert all(len(r) == len(rows[0]) for r in rows)          # no half-written row
    assert not [p for p in children if alive(p)]


def history_started(out):
    return (out / "history.csv").exists() and (out / "history.csv").stat().st_size > 200


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_dry_run_stops_cleanly(tmp_path, sig):
    """hot-cold-box, 0.1 s of 1000 particles (about a minute): the signal lands mid-run."""
    proc, children, _, stderr, took = interrupt(tmp_path, "hot-cold-box", sig, ready=history_started)
    check_clean_stop(tmp_path, proc, children, stderr, sig, end=0.1)
    assert took < 10


@pytest.mark.parametrize("sig,group", [(signal.SIGTERM, False), (signal.SIGINT, True)])
def test_fluid_run_stops_cleanly_and_ends_the_solver(tmp_path, sig, group):
    """packed-bed-ergun --test: the solver runs in its own session, so a Ctrl-C to the
    terminal's process group reaches only the host, which reports an interrupt (not a solver
    failure), ends the solver and removes the pipes."""
    def solver_running(out):
        return history_started(out) and (out / "fluid" / ".link").exists()

    proc, children, _, stderr, took = interrupt(tmp_path, "packed-bed-ergun", sig, ready=solver_running,
                                                extra=("--test",), group=group)
    check_clean_stop(tmp_path, proc, children, stderr, sig, end=0.05)
    assert children, "the fluid solver was not seen running"
    assert "FluidError" not in stderr
    assert not (tmp_path / "fluid" / ".link").exists()
    assert took < 20
