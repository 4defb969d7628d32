"""The set-up a restarted script replays (pyhost.script.replay): pure logic on a script's
commands, no engine."""
from pathlib import Path

import pytest

from pyhost.script import ScriptError, read_script, replay

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


def test_an_if_before_the_interrupted_run_is_refused_naming_its_line(tmp_path):
    (tmp_path / "in.if").write_text(SCRIPT.replace('print "pouring"', 'if "${n} > 10" then "set group all vx 1"'))
    commands = read_script(tmp_path / "in.if")
    at = next(k for k, c in enumerate(commands) if c.text == "run 200")
    with pytest.raises(ScriptError, match=r"in.if:14: an 'if' before the interrupted run"):
        replay(commands, at, Path("x"))


def test_a_script_without_a_box_before_the_run_is_refused(tmp_path):
    (tmp_path / "in.nobox").write_text("atom_style granular\nrun 10\n")
    commands = read_script(tmp_path / "in.nobox")
    with pytest.raises(ScriptError, match="defines no box"):
        replay(commands, 1, Path("x"))


def test_the_files_a_script_reads_are_its_inputs_and_not_those_it_writes(tmp_path):
    """What a restart fingerprints besides the script (pyhost.script.input_files): the STL of a
    mesh (its 'file' keyword is read, a fix print's is written), a read_data file; not a dump,
    nor a restart file the script writes and reads back, nor a word that only looks like a file."""
    from pyhost.script import input_files

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
