"""Bad input raises ValueError naming the parameter; the CLI prints one line and exits 2."""
import math
import subprocess
import sys

import pytest

from plugins.heat import MODELS, Pair, collide
from plugins.heat.fast import collide_fast


@pytest.mark.parametrize("name", ["R1", "R2", "rho1", "rho2", "Estar", "Y", "b1", "c1", "c2", "k1", "k2"])
@pytest.mark.parametrize("value", [0.0, -1.0, math.nan])
def test_nonpositive_or_nan_parameter_named(name, value):
    with pytest.raises(ValueError, match=name):
        Pair(**{name: value})


def test_b2_not_above_b1():
    with pytest.raises(ValueError, match="b2"):
        Pair(b1=2.0, b2=2.0)


def test_nan_temperature_difference():
    with pytest.raises(ValueError, match="dT"):
        Pair(dT=math.nan)


@pytest.mark.parametrize("v0", [0.0, -1.0, math.nan, math.inf])
def test_bad_speed(v0):
    with pytest.raises(ValueError, match="v0"):
        collide(v0)
    with pytest.raises(ValueError, match="v0"):
        collide_fast([1.0, v0])


def test_unknown_model_lists_choices():
    with pytest.raises(ValueError, match="A, B, C"):
        MODELS.lookup("D")


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "pyhost", "collide", *args], capture_output=True, text=True)


@pytest.mark.parametrize("args,word", [(["--R1", "-2e-3"], "R1"), (["--v0", "0"], "v0"),
                                       (["--b2", "1.0"], "b2"), (["--Y", "nan"], "Y")])
def test_cli_bad_input_one_line_exit_2(args, word):
    r = run_cli(*args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and word in lines[0], r.stderr


@pytest.mark.parametrize("line, message", [
    ("jump SELF ${where}", "a jump to a file or label given as a variable is not supported"),
    ("jump in.missing", "'jump in.missing': no script"),
    ('if "${a} > 1" then', "'if' needs a condition, 'then' and a command"),
    ('if "${a} > 1" then "print hi" else "shell cd post"', "'shell cd': it would move the host's own working folder"),
    ("shell cd post", "'shell cd': it would move the host's own working folder"),
    ("run 100 upto every 10 \"print x\"", "'run ... upto ... every' is not supported by the host"),
    ("delete_atoms region out", "'delete_atoms' renumbers the remaining atoms' ids .* add 'compress no'"),
    ("delete_atoms region out compress yes", "'delete_atoms' renumbers"),
    ("units cgs", "'units cgs': the host's contact models, heat and energy balance are in SI"),
    ("fix integr all multisphere", "fix multisphere: rigid clumps of spheres .* are not supported"),
    ("fix pts1 all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 50",
     "fix particletemplate/multisphere: rigid clumps"),
])
def test_script_commands_the_host_cannot_couple_are_refused_when_read(tmp_path, line, message):
    """Found when the script is read, before any engine time, wherever they stand."""
    from pyhost.engines.liggghts.script import ScriptError, read_script

    (tmp_path / "in.x").write_text(f"variable a equal 2\nrun 10\n{line}\n")
    with pytest.raises(ScriptError, match=rf"in.x:3: .*{message}"):
        read_script(tmp_path / "in.x")


def test_delete_atoms_keeping_the_ids_is_read(tmp_path):
    """``delete_atoms ... compress no`` keeps the ids the host follows each particle by (a
    pour on two ranks with it: the balance's terms are those of the deleted particles,
    docs/liggghts-tutorials.md)."""
    from pyhost.engines.liggghts.script import read_script

    (tmp_path / "in.x").write_text("run 10\ndelete_atoms region out compress no\nrun 10\n")
    assert [c.text for c in read_script(tmp_path / "in.x")] == ["run 10", "delete_atoms region out compress no",
                                                                 "run 10"]


def test_a_primitive_wall_placed_by_a_variable_is_read():
    """Debian's hydrogel tutorial places its walls at ${sizeX}: LIGGGHTS has the geometry (the
    contact recorder reads it from the fix), the host needs only the wall's kind and type; it
    used to refuse the script ("primitive wall the host cannot read")."""
    from pyhost.engines.liggghts.script import Command, ScriptError, parse_wall

    wall = parse_wall(Command("fix wall_right all wall/gran model hertz tangential history primitive type 2 "
                              "xplane ${sizeX}", "in.x", 5))
    assert wall.primitive == ("xplane", None) and wall.type == 2
    plain = parse_wall(Command("fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
                               "in.x", 6))
    assert plain.primitive == ("zplane", (0.0,))
    with pytest.raises(ScriptError, match=r"in.x:7: primitive wall the host cannot read"):
        parse_wall(Command("fix w all wall/gran model hertz tangential history primitive type ${t} zplane 0.0",
                           "in.x", 7))


def test_a_script_walls_temperature_is_read_as_written():
    """The temperature a script gives a wall for its fix heat/gran: a primitive wall/gran's
    'temperature' keyword, a mesh's in its fix mesh/surface (a number or a $variable, as
    written); a wall without one has none; an unfixed wall is gone."""
    from pyhost.engines.liggghts.script import Command, ScriptInfo

    info = ScriptInfo()
    for n, line in enumerate(["fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0 "
                              "temperature 350.", "fix lid all wall/gran model hertz tangential history primitive "
                              "type 1 zplane 0.1", "fix hot all mesh/surface file a.stl type 1 temperature ${Th}",
                              "fix cold all mesh/surface file b.stl type 1",
                              "fix drum all wall/gran model hertz tangential history mesh n_meshes 2 meshes hot cold"]):
        info.learn(Command(line, "in.x", n + 1))
    assert info.wall_temperatures("floor") == ["350."] and info.wall_temperatures("lid") == []
    assert info.wall_temperatures("drum") == ["${Th}"] and info.wall_temperatures("nowhere") == []
    info.learn(Command("unfix floor", "in.x", 9))
    assert info.wall_temperatures("floor") == []


@pytest.mark.parametrize("line, files", [
    ("dump dmp all custom 5000 ../DEM/post/dump.liggghts_run id type x y z", []),     # LIGGGHTS makes its folder
    ('fix extra all print 100 "${time} ${vx}" file ../DEM/post/velocity.txt title "#" screen no',
     ["../DEM/post/velocity.txt"]),
    ("fix av all ave/time 1 10 10 c_t append out/t.txt", ["out/t.txt"]),
    ("write_restart post/restart/liggghts.restart", []),                               # this one too
    ("write_data post/x.data", ["post/x.data"]),
    ("restart 1000 post/a.restart post/b.restart", ["post/a.restart", "post/b.restart"]),
    ("restart 0", []),
    ("write_dump all custom post/last.dump id x", []),
    ("fix Temp all property/atom Temp scalar yes yes no 0.0", []),
])
def test_a_scripts_output_files_are_found(line, files):
    """The files a LIGGGHTS command opens without making their folder (settlingTestMPI's fix
    print into DEM/post: the host makes it), read from each command's words in LIGGGHTS'
    order; dumps and write_restart are left out, LIGGGHTS makes their folders itself."""
    from pyhost.engines.liggghts.script import Command, output_files

    assert output_files(Command(line, "in.test", 1)) == files
