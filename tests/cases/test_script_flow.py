"""A script's control flow run as LIGGGHTS' own input loop runs it (pyhost.engines.liggghts.script.Program):
label/jump loops over 'next' variables, a loop left by an 'if' that jumps out, an 'if' with
runs in its branches, a jump to another file, 'run N every M' and 'quit'. Each is compared
with plain 'liggghts -in' on the same script: the same steps, and its dump file byte for byte;
every run inside is coupled (the host's collisions and energy balance see it). The host used
to refuse them all."""
import json
import subprocess
import sys
from pathlib import Path

import pytest
from test_script_checks import HEAD, run, toml
from test_script_time import dump_steps, restarts_bit_for_bit

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

# 27 spheres on a lattice falling at 3 m/s onto the floor (created, not inserted: a restart's
# replay leaves create_atoms to the restart file)
BOX = HEAD.split("region fill")[0].format(types=1, E="5e6", nu="0.3", e="0.5", mu="0.5") + """\
region fill block 0.004 0.016 0.004 0.016 0.004 0.016 units box
lattice sc 0.005
create_atoms 1 region fill
set group all diameter 0.002 density 2500
velocity all set 0 0 -3
fix integr all nve/sphere
dump da all custom 50 atoms.dump id x y z vx vy vz
"""

FLOWS = {
    "loop": ("variable i loop 3\nlabel stage\nrun 200\nprint \"stage $i done\"\nnext i\njump SELF stage\nrun 100\n",
             700),
    "if_jump_out": ("variable k loop 10\nlabel top\nrun 100\nif \"$k >= 3\" then \"jump SELF done\"\nnext k\n"
                    "jump SELF top\nlabel done\nrun 50\n", 350),
    "if_runs": ("variable n equal 2\nif \"${n} > 5\" then \"run 10\" elif \"${n} > 1\" \"run 300\" \"print mid\" "
                "else \"run 1\"\nif \"$(step) >= 300\" then \"run 100\"\nif \"$(step) < 300\" then \"run 5000\"\n", 400),
    "run_every": ("variable s equal step\nrun 400 every 100 \"print 'at ${s}'\" \"variable t equal ${s}\"\n"
                  "run 100 every 50 NULL\n", 500),
    "quit": ("run 200\nif \"$(step) >= 200\" then quit\nrun 5000\n", 200),
    "every_pre_no": ("run 200 pre no every 50 NULL\n", 200),
    "other_file": ("run 100\njump in.second go\n", 250),
}
SECOND = "run 99999\nlabel go\nrun 150\n"


@pytest.mark.parametrize("flow", sorted(FLOWS))
def test_control_flow_runs_as_in_plain_liggghts(tmp_path, flow):
    body, steps = FLOWS[flow]
    script = BOX + body
    (tmp_path / "in.second").write_text(SECOND)
    plain = tmp_path / "native"         # (the jumped-to file beside the script in both folders)
    plain.mkdir()
    (plain / "in.second").write_text(SECOND)
    (plain / "in.run").write_text(script)
    done = subprocess.run(["liggghts", "-in", "in.run", "-log", "none", "-screen", "/dev/null"], cwd=plain,
                          timeout=300)
    assert done.returncode == (1 if flow == "quit" else 0)   # (LIGGGHTS 3.8's quit ends with exit 1)
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert s["steps"] == steps
    assert dump_steps(plain / "atoms.dump")[-1] // 50 * 50 == steps // 50 * 50
    assert (tmp_path / "atoms.dump").read_bytes() == (plain / "atoms.dump").read_bytes()
    assert s["collisions"] >= 9 and abs(s["energy_balance_error"]) < 1e-12


@pytest.mark.long
def test_a_restart_inside_a_loop_goes_on_where_the_loop_stood(tmp_path):
    """The loop left by an 'if' (four runs of 100 steps, its variable at 2 of 10 when stopped)
    with a checkpoint every 1 ms, stopped by SIGTERM at step 250 and restarted: the restart
    replays what the script ran (the 'next's included, so the variable is where it was), ends
    the interrupted run and goes on through the loop; collisions.csv, history.csv and
    summary.json equal the uninterrupted run's to the bit."""
    whole, said = restarts_bit_for_bit(tmp_path, BOX + FLOWS["if_jump_out"][0],
                                       toml().replace("[output]\n", "[output]\ncheckpoint = 0.001\n"), 250,
                                       "checkpoint at t = 0.0025 s (step 250)")
    assert whole["steps"] == 350 and "restarted in this run, 50 steps to go" in said


@pytest.mark.parametrize("flow", ["loop", pytest.param("if_runs", marks=pytest.mark.long)])
def test_control_flow_on_two_ranks_is_the_serial_run(tmp_path, flow):
    """Under mpirun -np 2 every rank follows rank 0's input loop (the if's branch is LIGGGHTS'
    on all ranks, the next's on each): the same steps and collisions.csv byte for byte."""
    logs = {}
    for ranks in (1, 2):
        folder = tmp_path / str(ranks)
        folder.mkdir()
        r, s = run(folder, BOX + FLOWS[flow][0], toml(), ranks=ranks)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        assert s["steps"] == FLOWS[flow][1] and abs(s["energy_balance_error"]) < 1e-12
        logs[ranks] = (folder / "out" / "collisions.csv").read_bytes()
    assert logs[1] == logs[2]
