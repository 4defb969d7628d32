"""``python -m pyhost collide``: JSON keys, lists, models, methods, wall."""
import json
import signal
import time
from pathlib import Path
import subprocess
import sys

import pytest

from plugins.heat import Pair, collide

KEYS = "t_max delta_max a_max F_max delta_r delta_f R_bar t_r v1 e t_coll Q Q_closed_form regime flags".split()


def cli(*args):
    r = subprocess.run([sys.executable, "-m", "pyhost", "collide", *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_one_speed_gives_one_object_with_all_keys():
    out = cli("--model", "A", "--v0", "1.0", "--json")
    assert set(KEYS) <= set(out)
    assert out["Q"] == pytest.approx(collide(1.0, Pair(), "A").Q, rel=1e-12)


def test_several_speeds_all_models_fast_wall():
    out = cli("--model", "all", "--v0", "0.01", "2", "--method", "fast", "--wall", "--json")
    assert [(r["model"], r["v0"]) for r in out] == [(m, v) for m in "ABC" for v in (0.01, 2.0)]
    for r in out:
        ref = collide(r["v0"], Pair.wall(), r["model"])
        assert r["e"] == pytest.approx(ref.e, rel=1e-6)
        assert r["regime"] == ref.regime and r["flags"] == list(ref.flags)


def test_pair_options_are_used():
    out = cli("--v0", "0.5", "--R1", "1e-3", "--Estar", "2e11", "--Y", "1e9", "--dT", "-10", "--json")
    ref = collide(0.5, Pair(R1=1e-3, Estar=2e11, Y=1e9, dT=-10.0), "A")
    assert out["Q"] == pytest.approx(ref.Q, rel=1e-12) and out["Q"] < 0


def test_help_documents_units():
    r = subprocess.run([sys.executable, "-m", "pyhost", "collide", "--help"], capture_output=True, text=True)
    for text in ("[m/s]", "[Pa]", "[kg/m^3]", "[J/(kg K)]", "[W/(m K)]", "[K]"):
        assert text in r.stdout


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_command_line_is_read_stops_quietly(signum):
    """Ctrl-C in the first half second (while every command is imported) used to print a
    KeyboardInterrupt traceback: now one line and 128 + n."""
    p = subprocess.Popen([sys.executable, "-m", "pyhost", "run", "cases/two-particles", "--out", "/nonexistent/x"],
                         cwd=Path(__file__).resolve().parents[2], stderr=subprocess.PIPE, text=True)
    time.sleep(0.15)
    p.send_signal(signum)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 128 + signum, err
    assert "Traceback" not in err and "interrupted:" in err
