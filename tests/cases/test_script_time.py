"""A script's time as LIGGGHTS steps it: a settle at one time step, a run at another, a
'reset_timestep 0' between runs. The simulated time is the sum of each step's time step, and
every output carries it (monotonic) beside the step LIGGGHTS numbers; the script's own dumps
are those of plain 'liggghts -in'. Before, summary.json said 0.005 s for 0.025 s simulated and
the history's times went back at each change."""
import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_script_checks import header, run, toml

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

RUNS = """dump da all custom 500 atoms.dump id x y z vx vy vz
run 1000
timestep 5e-6
run 2000
reset_timestep 0
run 1000
"""
"""1000 steps of 1e-5 s, 2000 of 5e-6 s, then 1000 more numbered from 0 again: 0.025 s."""

TIME = 1000 * 1e-5 + 2000 * 5e-6 + 1000 * 5e-6
SCRIPT = header().replace("vel constant 0 0 0", "vel constant 0 0 -1") + RUNS


def native(tmp_path: Path, script: str) -> Path:
    """The script run by plain 'liggghts -in' in a folder of its own."""
    if shutil.which("liggghts") is None:
        pytest.fail("no liggghts: tools/setup.sh --engines installs it")
    folder = tmp_path / "native"
    folder.mkdir()
    (folder / "in.run").write_text(script)
    subprocess.run(["liggghts", "-in", "in.run", "-log", "none", "-screen", "/dev/null"], cwd=folder, check=True,
                   timeout=300)
    return folder


def dump_steps(path: Path) -> list[int]:
    lines = path.read_text().splitlines()
    return [int(lines[k + 1]) for k, ln in enumerate(lines) if ln == "ITEM: TIMESTEP"]


def test_time_is_summed_across_timestep_changes_and_resets(tmp_path):
    """40 spheres falling at 1 m/s onto the floor, over the three runs: summary.json's time is
    0.025 s to 1e-12, history's times rise strictly and are the sums of the steps' time steps
    at the steps LIGGGHTS numbers (its 'step' column: 0 .. 3000, then 500, 1000: the frames
    of the script's dump but the third run's first, whose time step 3000's row has), each
    collision's time lies in its run's span at its own step's time, and the script's dump is
    byte for byte plain LIGGGHTS' (the forked trial of a run's set-up wrote the frame of step 0
    a second time after the reset)."""
    plain = native(tmp_path, SCRIPT)
    r, s = run(tmp_path, SCRIPT, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert s["time"] == pytest.approx(TIME, rel=1e-12, abs=0)
    assert s["steps"] == 4000 and s["step"] == 1000
    assert abs(s["energy_balance_error"]) < 1e-12
    assert (tmp_path / "atoms.dump").read_bytes() == (plain / "atoms.dump").read_bytes()
    with open(tmp_path / "out" / "history.csv") as f:
        rows = [(float(r["time"]), int(r["step"])) for r in csv.DictReader(f)]
    # the dump's frames, but the third run's first (step 0 at 0.02 s: the time of step 3000's)
    assert dump_steps(plain / "atoms.dump") == [0, 500, 1000, 1500, 2000, 2500, 3000, 0, 500, 1000]
    assert [k for _, k in rows] == [0, 500, 1000, 1500, 2000, 2500, 3000, 500, 1000]
    expected = [0.0, 0.005, 0.01, 0.0125, 0.015, 0.0175, 0.02, 0.0225, 0.025]
    assert np.allclose([t for t, _ in rows], expected, rtol=1e-12, atol=0)
    assert all(b > a for (a, _), (b, _) in zip(rows, rows[1:]))
    with open(tmp_path / "out" / "collisions.csv") as f:
        hits = [(float(r["time"]), int(r["step"])) for r in csv.DictReader(f)]
    assert s["collisions"] == len(hits) > 40
    times = np.array([t for t, _ in hits])
    assert np.all(np.diff(times) >= 0)
    for t, k in hits:          # the step's time, in the run that step number belongs to at that time
        run_of = 0 if t <= 0.01 else 1 if t <= 0.02 else 2
        want = [k * 1e-5, 0.01 + (k - 1000) * 5e-6, 0.02 + k * 5e-6][run_of]
        assert t == pytest.approx(want, rel=1e-12), (t, k)
    assert sum(t > 0.02 for t in times) > 0          # collisions in the run after the reset too


def restarts_bit_for_bit(tmp_path: Path, script: str, case_toml: str, stop_at: int, said: str) -> tuple[dict, str]:
    """The script run whole, then again stopped by SIGTERM at step ``stop_at`` (its checkpoint
    there ``said``) and restarted: collisions.csv, history.csv and summary.json equal to the
    bit. Returns the summary and what the restart printed."""
    from conftest import STOPPER

    r, whole = run(tmp_path, script, case_toml)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    cut = tmp_path / "cut"
    stopped = subprocess.run([sys.executable, "-c", STOPPER, str(stop_at), "SIGTERM", "run", str(tmp_path), "--out",
                              str(cut)], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert stopped.returncode == 128 + 15, stopped.stdout[-3000:] + stopped.stderr[-3000:]
    assert said in stopped.stdout
    again = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(cut), "--restart"],
                           capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert again.returncode == 0, again.stdout[-3000:] + again.stderr[-3000:]
    for name in ("collisions.csv", "history.csv"):
        assert (cut / name).read_bytes() == (tmp_path / "out" / name).read_bytes(), name
    assert json.loads((cut / "summary.json").read_text()) == whole
    return whole, again.stdout


def test_a_restart_across_a_time_step_change_continues_the_clock(tmp_path):
    """The same script with a checkpoint every 2.5 ms, stopped by SIGTERM in its second run (at
    the smaller time step) and restarted: it goes through the reset_timestep and its third run,
    and collisions.csv, history.csv and summary.json equal the uninterrupted run's to the bit."""
    whole, _ = restarts_bit_for_bit(tmp_path, SCRIPT, toml().replace("[output]\n", "[output]\ncheckpoint = 0.0025\n"),
                                    2000, "checkpoint at t = 0.015 s (step 2000)")
    assert whole["time"] == pytest.approx(TIME, rel=1e-12, abs=0)


def collision(row) -> tuple:
    """(time [s], the smaller id, the other id or 0 for a wall) of a collision log's row."""
    i, j = int(row["i"]), int(row["j"])
    return (float(row["time"]),) + ((min(i, j), max(i, j)) if j else (i, 0))


@pytest.mark.long
def test_post_places_the_dumps_in_the_scripts_runs(tmp_path):
    """post --script on the dumps of the same run (positions at every step, one file through
    the reset): it reads the script's time steps and reset, so it accepts the frames whose
    steps go back at the reset and finds the run's own collisions, at the run's time to 1e-12 (a
    touch the dumped positions' 6 digits decide may come one step apart), with the dump interval of the last run (5e-6 s). Before, it refused the dumps after
    the reset ('timestep goes backwards') and put every collision at step x the last dt."""
    script = SCRIPT.replace("run 1000\n", "dump every all custom 1 every.dump id type x y z vx vy vz radius\n"
                                          "run 1000\n", 1)
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    walls = "".join(f"[[walls]]\nfix = \"{w}\"\nmaterial = \"glass\"\n" for w in ("walls", "walls2"))
    (tmp_path / "scene.toml").write_text((tmp_path / "case.toml").read_text() + walls)
    p = subprocess.run([sys.executable, "-m", "pyhost", "post", str(tmp_path / "every.dump"), "--scene",
                        str(tmp_path / "scene.toml"), "--script", str(tmp_path / "in.run"), "--out",
                        str(tmp_path / "post"), "--model", "A"], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    summary = json.loads((tmp_path / "post" / "summary.json").read_text())
    assert summary["complete"] is True and summary["frames"] == 4001     # counts 0 .. 4000: step 0 after the reset is count 3000 again, skipped
    assert summary["dump_interval_s"] == pytest.approx(5e-6, rel=1e-9)
    import gzip
    with gzip.open(tmp_path / "post" / "collisions.csv.gz", "rt") as f:
        found = sorted(collision(r) for r in csv.DictReader(f))
    with open(tmp_path / "out" / "collisions.csv") as f:
        ran = sorted(collision(r) for r in csv.DictReader(f))
    assert len(found) == len(ran) == s["collisions"]
    assert [(i, j) for _, i, j in found] == [(i, j) for _, i, j in ran]
    # at the run's time; a touch decided by the dumped positions' 6 digits may come one step apart
    t_post, t_run = np.array([t for t, _, _ in found]), np.array([t for t, _, _ in ran])
    same = np.isclose(t_post, t_run, rtol=1e-12, atol=0)
    print(f"{same.sum()} of {len(same)} collisions at the same time; largest difference "
          f"{np.abs(t_post - t_run).max():.3g} s")
    assert np.all(np.abs(t_post - t_run) <= 1e-5 * (1 + 1e-9)) and same.mean() > 0.95
