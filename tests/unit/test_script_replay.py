"""The set-up a restarted script replays (pyhost.engines.liggghts.script.replay): pure logic on a script's
commands, no engine."""
from pathlib import Path

import pytest

from pyhost.engines.liggghts.script import ScriptError, read_script, replay

SCRIPT = """\
variable n index 100
atom_style granular
boundary f f f
region box block 0 1 0 1 0 1 units box
create_box 2 box
create_atoms 1 single 0.5 0.5 0.5 units box
group heavy type 2
set group all density 2500
velocity all set 0 0 -1
fix gravi all gravity 9.81 vector 0 0 -1
dump d all custom 100 one.dump id x y z
dump e all custom 100 post/many_*.dump id x y z
log run.log
print "pouring"
run ${n}
unfix gravi
write_restart mid.restart
run 200
fix shake all move/mesh mesh plate wiggle amplitude 0 0 1e-3 period 0.03
run 300
"""


@pytest.fixture
def commands(tmp_path):
    (tmp_path / "in.test").write_text(SCRIPT)
    return read_script(tmp_path / "in.test")


def texts(commands):
    return [c.text for c in commands]


def test_the_box_becomes_the_checkpoints_restart_and_what_it_holds_is_left_out(commands):
    """Interrupted in the second run (command 17 of the list): regions, variables, fixes and
    unfixes replayed in order, the box read from the checkpoint, atoms, groups, sets,
    velocities, prints and earlier restarts left out (the restart file holds them); earlier runs
    kept as markers; dumps and logs to one file append."""
    at = next(k for k, c in enumerate(commands) if c.text == "run 200")
    out = replay(commands, at, Path("/ck/dem.restart"))
    assert texts(out) == [
        "variable n index 100", "atom_style granular", "boundary f f f",
        "region box block 0 1 0 1 0 1 units box",
        "read_restart /ck/dem.restart",
        "fix gravi all gravity 9.81 vector 0 0 -1",
        "dump d all custom 100 one.dump id x y z", "dump_modify d append yes",
        "dump e all custom 100 post/many_*.dump id x y z",
        "log run.log append",
        "run ${n}",
        "unfix gravi",
    ]
    assert out[4].line == 5          # the read_restart stands at the script's create_box line


def test_program_follows_loops_jumps_and_includes_as_liggghts_input_loop(tmp_path):
    """LIGGGHTS' input loop without the engine: 'next' is the caller's (here: its variable is
    exhausted at the third pass, which skips one jump), an include is read in its place, a
    jump inside an 'if' branch drops the branch's other commands, a missing label is named;
    state() and restore() carry the position and the trace."""
    from pyhost.engines.liggghts.script import Program

    (tmp_path / "in.inc").write_text("print inc\n")
    (tmp_path / "in.loop").write_text("variable i loop 3\nlabel top\nrun 10\nnext i\njump SELF top\n"
                                      "include in.inc\nif x then y\nrun 1\nlabel out\nrun 2\njump SELF nowhere\n")
    p = Program(tmp_path / "in.loop", tmp_path)
    taken, passes = [], 0
    while (cmd := p.take()) is not None:
        taken.append(cmd.text)
        p.trace.append(cmd)
        if cmd.name == "next":
            passes += 1
            p.skip_jump = passes == 3
        if cmd.name == "if":
            p.push(cmd, ["print a", "jump SELF out", "print never"])
            state = p.state()
        if cmd.text == "run 2":
            break
    assert taken == ["variable i loop 3", "run 10", "next i", "run 10", "next i", "run 10", "next i", "print inc",
                     "if x then y", "print a", "run 2"]
    again = Program.restore(state, tmp_path)
    assert [c.text for c in again.trace] == taken[:-2]
    assert again.take().text == "print a" and again.take().text == "run 2"
    with pytest.raises(ScriptError, match=r"in.loop:11: 'jump SELF nowhere': no 'label nowhere'"):
        again.take()


def test_a_script_without_a_box_before_the_run_is_refused(tmp_path):
    (tmp_path / "in.nobox").write_text("atom_style granular\nrun 10\n")
    commands = read_script(tmp_path / "in.nobox")
    with pytest.raises(ScriptError, match="defines no box"):
        replay(commands, 1, Path("x"))


def test_the_files_a_script_reads_are_its_inputs_and_not_those_it_writes(tmp_path):
    """What a restart fingerprints besides the script (pyhost.engines.liggghts.script.input_files): the STL of a
    mesh (its 'file' keyword is read, a fix print's is written), a read_data file; not a dump,
    nor a restart file the script writes and reads back, nor a word that only looks like a file."""
    from pyhost.engines.liggghts.script import input_files

    (tmp_path / "meshes").mkdir()
    for name in ("meshes/wall.stl", "beads.data", "bed.restart", "out.dump", "printed.txt"):
        (tmp_path / name).write_text("x")
    (tmp_path / "in.run").write_text("""read_data beads.data
fix wall all mesh/surface file meshes/wall.stl type 1
fix told all print 100 "told" file printed.txt screen no
dump d all custom 100 out.dump id x y z
write_restart bed.restart
read_restart bed.restart
variable f string ${name}.stl
""")
    found = input_files(read_script(tmp_path / "in.run"), tmp_path)
    assert found == [tmp_path / "beads.data", tmp_path / "meshes" / "wall.stl"]
