"""``post --script`` on a script written as users write them (after Debian's heatTransfer
and packing tutorials): the time step through a variable (``timestep ${dt}``), the box from
variables, a primitive plane wall, a fix heat/gran with its own id, and VTK dumps with no box.
One sphere dropped 10 mm onto the floor: post finds its one wall impact from the dumps alone."""
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SOFT_DEM, steel_toml

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

SCRIPT = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
variable L equal 0.02
variable dt equal 1e-5
region box block 0 ${L} 0 ${L} 0 ${L} units box
create_box 1 box
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.8
fix m4 all property/global coefficientFriction peratomtypepair 1 0.3
fix m5 all property/global thermalConductivity peratomtype 1.0
fix m6 all property/global thermalCapacity peratomtype 800
pair_style gran model hertz tangential history
pair_coeff * *
timestep ${dt}
fix gravi all gravity 9.81 vector 0 0 -1
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
create_atoms 1 single 0.01 0.01 0.011 units box
set group all diameter 0.002 density 2500
fix heattransfer all heat/gran initial_temperature 300.
fix integr all nve/sphere
dump text all custom 20 post/dump.* id type x y z vx vy vz radius f_Temp[0]
dump vtk all custom/vtk 20 post/drop*.vtk id type x y z vx vy vz radius f_Temp[0]
run 6000
"""

SCENE = f"""[materials.glass]
types = [1]
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.22
yield_stress = 500e6
heat_capacity = 800.0
conductivity = 1.0
dem = {SOFT_DEM}

{steel_toml()}
[[walls]]
fix = "floor"
material = "steel"
temperature = 350.0
"""


@pytest.fixture(scope="module")
def drop(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drop")
    (folder / "post").mkdir()
    (folder / "in.drop").write_text(SCRIPT)
    (folder / "scene.toml").write_text(SCENE)
    r = subprocess.run(["liggghts", "-in", "in.drop", "-screen", "/dev/null", "-log", "log.drop"], cwd=folder,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:]
    return folder


def post(folder, dumps, out):
    r = subprocess.run([sys.executable, "-m", "pyhost", "post", str(folder / "post" / dumps), "--scene",
                        str(folder / "scene.toml"), "--script", str(folder / "in.drop"), "--out", str(folder / out),
                        "--model", "A"], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return json.loads((folder / out / "summary.json").read_text())


def first_impact(folder, out):
    import csv
    import gzip
    with gzip.open(folder / out / "collisions.csv.gz", "rt") as f:
        rows = list(csv.DictReader(f))
    return rows, float(rows[0]["v0"])


def test_text_dumps_with_a_variable_time_step_and_a_primitive_floor(drop):
    """The time step comes from LIGGGHTS' own evaluation of ${dt}; the floor, a primitive
    zplane at the box's z lo, is placed from --script. The sphere's first impact at the
    free-fall speed from 10 mm, sqrt(2 g h) = 0.443 m/s, within 1 %."""
    summary = post(drop, "dump.*", "text")
    rows, v0 = first_impact(drop, "text")
    print(f"{len(rows)} wall collisions; first at v0 = {v0:.4f} m/s")
    assert summary["collisions"]["particle_wall"] >= 1 and summary["collisions"]["particle_particle"] == 0
    assert v0 == pytest.approx(math.sqrt(2 * 9.81 * 0.010), rel=0.01)


def test_vtk_dumps_take_the_box_from_the_script(drop):
    """The same from the custom/vtk dumps, which hold no box: the box of the script's
    create_box (from ${L}); the same collisions as from the text dumps."""
    text = post(drop, "dump.*", "text2")
    vtk = post(drop, "drop*.vtk", "vtk")
    assert vtk["collisions"] == text["collisions"]
    assert first_impact(drop, "vtk")[1] == pytest.approx(first_impact(drop, "text2")[1], rel=1e-4)


def test_temperature_column_of_a_heat_gran_fix_id(tmp_path):
    """A script that dumps its fix heat/gran by id (``f_heattransfer``: LIGGGHTS writes the
    temperature there) gives post the particles' temperatures: the scene needs none, and the
    impact on the 350 K floor moves heat into the 300 K sphere; and post says that heat/gran's
    own conduction is not in its temperatures."""
    (tmp_path / "post").mkdir()
    script = SCRIPT.replace("radius f_Temp[0]\ndump vtk", "radius f_heattransfer\ndump vtk")
    (tmp_path / "in.drop").write_text(script.replace("dump vtk all custom/vtk 20 post/drop*.vtk id type x y z vx vy vz "
                                                     "radius f_Temp[0]\n", ""))
    (tmp_path / "scene.toml").write_text(SCENE)
    r = subprocess.run(["liggghts", "-in", "in.drop", "-screen", "/dev/null", "-log", "log.drop"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:]
    assert "f_heattransfer" in (tmp_path / "post" / "dump.0").read_text()
    summary = post(tmp_path, "dump.*", "out")
    print(summary["heat_J"])
    assert summary["heat_J"]["A"] > 0
    assert any("fix heat/gran (heattransfer)" in w and "not by heat/gran's conduction" in w for w in summary["warnings"])


def test_values_given_as_variables_read_as_their_numbers(tmp_path):
    """A script whose values post reads are variables, as users write them: the DEM modulus
    ``${E}`` (an equal-style formula), the floor at ``${zfloor}`` (from LIGGGHTS' command line:
    ``liggghts -var zfloor 0.0``, post's ``--var zfloor 0.0``), and its runs ``run ${half}`` with
    a Temp set ``${Tset}`` between them. post on the run's dumps with that script gives what it
    gives with the same script in plain numbers, to the last digit: the set followed at step
    3,000 (before the impact at about 4,500: 320 K against the 350 K floor), the same impact and
    heat. Without the --var, the floor's variable is named in the warnings and the floor left out."""
    plain = (SCRIPT.replace("run 6000\n", "run 3000\nset group all property/atom Temp 320\nrun 3000\n"))
    variables = (plain.replace("youngsModulus peratomtype 5e6", "youngsModulus peratomtype ${E}")
                 .replace("zplane 0.0", "zplane ${zfloor}")
                 .replace("run 3000\n", "run ${half}\n")
                 .replace("Temp 320", "Temp ${Tset}")
                 .replace("variable dt equal 1e-5\n", "variable dt equal 1e-5\nvariable E equal 5*10^6\n"
                          "variable half equal 6000/2\nvariable Tset index 320\n"))
    assert variables.count("${half}") == 2 and "${zfloor}" in variables
    (tmp_path / "post").mkdir()
    (tmp_path / "in.drop").write_text(plain)
    (tmp_path / "in.vars").write_text(variables)
    (tmp_path / "scene.toml").write_text(SCENE)
    r = subprocess.run(["liggghts", "-in", "in.drop", "-screen", "/dev/null", "-log", "log.drop"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:]

    def run(script, out, *var):
        r = subprocess.run([sys.executable, "-m", "pyhost", "post", str(tmp_path / "post" / "dump.*"), "--scene",
                            str(tmp_path / "scene.toml"), "--script", str(tmp_path / script), "--out",
                            str(tmp_path / out), "--model", "A", *var], capture_output=True, text=True, cwd=ROOT,
                           timeout=300)
        assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
        return json.loads((tmp_path / out / "summary.json").read_text())

    numbers = run("in.drop", "plain")
    given = run("in.vars", "vars", "--var", "zfloor", "0.0")
    print(numbers["heat_J"], numbers["temperature_sets"], given["warnings"])
    [done] = given["temperature_sets"]
    assert done["steps"] == [3000] and done["commands"][0].endswith("set group all property/atom Temp 320")
    assert numbers["collisions"]["particle_wall"] >= 1
    assert given["collisions"] == numbers["collisions"] and given["heat_J"] == numbers["heat_J"]
    assert first_impact(tmp_path, "vars") == first_impact(tmp_path, "plain")

    missing = run("in.vars", "missing")
    assert any("zfloor: not defined (give --var zfloor VALUE)" in w for w in missing["warnings"])
    assert missing["collisions"]["particle_wall"] == 0
