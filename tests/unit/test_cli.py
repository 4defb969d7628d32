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


def caught(pid: int, signum: int) -> bool:
    """Whether process ``pid`` has a handler of its own for ``signum`` (Linux: SigCgt)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    mask = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigCgt:")), 16)
    return bool(mask >> (signum - 1) & 1)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_command_line_is_read_stops_quietly(signum, tmp_path):
    """Ctrl-C while the command line is read (every command imported) used to print a
    KeyboardInterrupt traceback: now one line and 128 + n, and nothing written. The signal is
    sent as soon as pyhost/__main__.py has its handlers (the kernel's caught-signal mask of the
    process has SIGTERM, which Python itself does not catch), before the imports are done:
    a fixed delay missed the window once the imports got faster."""
    p = subprocess.Popen([sys.executable, "-m", "pyhost", "run", "cases/two-particles", "--out", str(tmp_path / "x")],
                         cwd=Path(__file__).resolve().parents[2], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 30.0
    while not caught(p.pid, signal.SIGTERM):
        assert time.monotonic() < deadline and p.poll() is None, "pyhost never installed its handlers"
        time.sleep(0.0005)
    p.send_signal(signum)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 128 + signum, err
    assert "Traceback" not in err and "interrupted:" in err
    assert not (tmp_path / "x").exists()


def test_comparison_model_hertz_is_the_closed_form_of_eqs_31_32():
    """``collide --model hertz``: Sun & Chen's elastic Hertz heat with the paper's published
    constants, Q = 0.87093 pi R* delta_max dT t_coll^(1/2) / sigma and t_coll = 2.8683
    (m*^2 / (R* E*^2 v0))^(1/5) (to their 5 digits); e is null (no restitution)."""
    out = cli("--model", "hertz", "--v0", "0.001", "0.1", "1", "--json")
    pair = Pair()
    for row, v0 in zip(out, (0.001, 0.1, 1.0)):
        d_max = (15 * pair.mstar * v0**2 / (16 * pair.Estar * pair.Rstar**0.5)) ** 0.4
        t_coll = 2.8683 * (pair.mstar**2 / (pair.Rstar * pair.Estar**2 * v0)) ** 0.2
        Q = 0.87093 * 3.141592653589793 * pair.Rstar * d_max * pair.dT * t_coll**0.5 / pair.sigma
        assert row["model"] == "hertz" and row["v0"] == v0 and row["e"] is None
        assert row["t_coll"] == pytest.approx(t_coll, rel=2e-5)
        assert row["Q"] == pytest.approx(Q, rel=2e-5)


def test_comparison_models_on_the_dem_contact_need_it():
    """softened conducts over the DEM's softened contact: without --dem-Estar and --dem-e it is
    refused (exit 2, naming them); with them it is the plugin's model on that DemPair."""
    r = subprocess.run([sys.executable, "-m", "pyhost", "collide", "--model", "softened", "--v0", "1"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--dem-Estar" in r.stderr and "--dem-e" in r.stderr
    from plugins.heat.comparison import COMPARISON, DemPair
    out = cli("--model", "softened", "--v0", "1", "--dem-Estar", "5e6", "--dem-e", "0.9", "--json")
    ref = COMPARISON["softened"].heat(1.0, Pair(), DemPair(Ystar=5e6, restitution=0.9, Ystar_original=Pair().Estar))
    assert out["Q"] == pytest.approx(float(ref["Q"]), rel=1e-12) and out["e"] is None


def test_a_command_imports_its_own_module_only():
    """A run's start imports the module of the command given, not all eleven (0.24 s of
    imports before): 'run --help' loads pyhost.commands.run (and the pictures' module it uses)
    and none of the others, while the
    top level's help still lists every command."""
    probe = ("import sys; from pyhost.cli import main\n"
             "try:\n    main(['run', '--help'])\nexcept SystemExit:\n    pass\n"
             "print(sorted(m for m in sys.modules if m.startswith('pyhost.commands.')))")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    loaded = set(eval(r.stdout.strip().splitlines()[-1]))
    assert "pyhost.commands.run" in loaded and loaded <= {"pyhost.commands.run", "pyhost.commands.pictures"}, loaded
    top = subprocess.run([sys.executable, "-m", "pyhost", "--help"], capture_output=True, text=True, timeout=60)
    from pyhost.cli import COMMANDS
    assert top.returncode == 0 and all(name in top.stdout for name in COMMANDS)
