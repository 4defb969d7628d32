"""The DPMFoam importer (pyhost/engines/dpmfoam_case.py) on Debian's own DPMFoam tutorial,
lagrangian/DPMFoam/Goldschmidt (openfoam-examples, installed by tools/setup_engines.sh), and
the contact law it rests on. No engine runs here (tests/cases/test_dpmfoam_case.py runs one)."""
from __future__ import annotations

import math
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from plugins.dem.hertz import DemHertz, effective_modulus, hertz_collision_time, restitution_of_tsuji_alpha
from pyhost.engines.dpmfoam_case import DpmfoamError, convert, read_cloud
from pyhost.schema import SceneError
from pyhost.scene import load_scene
from pyhost.engines.liggghts.worlds import user_script

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
from dpmfoam_as_is import GLASS as MATERIAL  # noqa: E402  (the five real-material keys a user adds)

EXAMPLES = Path("/usr/share/doc/openfoam-examples/examples/lagrangian")
GOLDSCHMIDT = EXAMPLES / "DPMFoam" / "Goldschmidt"


@pytest.mark.parametrize("alpha", [0.01, 0.02, 0.3, 1.0])
def test_tsuji_damping_is_liggghts_hertz_damping(alpha):
    """OpenFOAM's spring-slider-dashpot, F = k delta^1.5 + alpha (m k)^(1/2) delta^(1/4) v with
    k = (4/3) E* R*^(1/2), and LIGGGHTS' hertz with the restitution the importer gives are one
    force law: equal to 1e-12 at any overlap, rate, radius and mass."""
    rng = np.random.default_rng(1)
    Ys = effective_modulus(1e8, 0.35, 1e8, 0.35)
    law = DemHertz(Ys, restitution_of_tsuji_alpha(alpha))
    delta, v = rng.uniform(1e-8, 1e-5, 50), rng.uniform(-2, 2, 50)
    R, m = rng.uniform(1e-4, 1e-2, 50), rng.uniform(1e-7, 1e-2, 50)
    k = 4.0 / 3.0 * Ys * np.sqrt(R)
    tsuji = k * delta**1.5 + alpha * np.sqrt(m * k) * delta**0.25 * v
    assert np.allclose(law.force(delta, v, R, m), tsuji, rtol=1e-12, atol=0)


def test_no_damping_is_elastic():
    assert restitution_of_tsuji_alpha(0.0) == 1.0
    with pytest.raises(ValueError, match="alpha"):
        restitution_of_tsuji_alpha(math.sqrt(5.0))


def test_goldschmidt_is_read_as_the_tutorial_says():
    cloud = read_cloud(GOLDSCHMIDT)
    assert cloud.phase == "air"
    assert cloud.positions.shape == (24750, 3)
    assert cloud.positions[0].tolist() == [-0.006, -0.0735, 0.0015]       # the positions file's first line
    assert (cloud.diameter, cloud.density, cloud.resolution, cloud.drag) == (0.0025, 2526.0, 12, "gidaspow")
    assert (cloud.pair.E, cloud.pair.nu, cloud.pair.mu) == (1e8, 0.35, 0.1)
    assert cloud.pair.e == pytest.approx(restitution_of_tsuji_alpha(0.02), rel=1e-15)
    assert np.allclose(cloud.lo, [-0.0075, -0.075, 0.0]) and np.allclose(cloud.hi, [0.0075, 0.075, 0.45])
    assert cloud.faces == {"xlo": "frontAndBack", "xhi": "frontAndBack", "ylo": "walls", "yhi": "walls",
                           "zlo": "bottom", "zhi": "top"}
    wall = cloud.walls["walls"]                 # wallSpringSliderDashpot
    assert (wall.E, wall.nu, wall.mu) == (1e8, 0.23, 0.09)
    assert wall.e == pytest.approx(restitution_of_tsuji_alpha(0.01), rel=1e-15)
    sym = cloud.walls["frontAndBack"]           # a symmetry patch: the rebound rule, the particles' modulus
    assert (sym.E, sym.nu, sym.e, sym.mu) == (1e8, 0.35, 0.97, 0.09)
    assert cloud.gas_walls == {"walls"}
    assert cloud.gravity.tolist() == [0.0, 0.0, -9.81]


def test_goldschmidt_converted(tmp_path):
    out = tmp_path / "gold"
    done = convert(GOLDSCHMIDT, out)
    cloud = read_cloud(GOLDSCHMIDT)
    # the DEM step: at most the 1 m/s Hertz collision over 12 steps, dividing the gas's 2e-5 s
    m = cloud.density * math.pi * cloud.diameter**3 / 6
    t_c = hertz_collision_time(effective_modulus(1e8, 0.35, 1e8, 0.35), cloud.diameter / 4, m / 2, 1.0)
    assert done["dt"] <= t_c / 12 and done["dt"] > t_c / 12 * (1 - 1 / done["couple_every"])
    assert done["couple_every"] * done["dt"] == pytest.approx(2e-5, rel=1e-14)
    assert done["retyped"] == ["top", "bottom"]         # inlet and outlet of the gas
    # the atoms written are the tutorial's positions, diameter and density
    rows = [ln.split() for ln in (out / "DEM" / "particles.data").read_text().split("Atoms")[1].splitlines()
            if ln.strip()]
    atoms = np.array(rows, float)
    assert atoms.shape == (24750, 7)
    assert np.array_equal(atoms[:, 4:], cloud.positions)
    assert set(atoms[:, 2]) == {0.0025} and set(atoms[:, 3]) == {2526.0}
    script = (out / "DEM" / "in.liggghts").read_text()
    planes = re.findall(r"primitive type (\d) ([xyz])plane (\S+)", script)
    assert sorted((a, float(v)) for _, a, v in planes) == sorted(
        [("x", -0.0075), ("x", 0.0075), ("y", -0.075), ("y", 0.075), ("z", 0.0), ("z", 0.45)])
    assert "timestep\t" + repr(done["dt"]) in script
    assert "fix\tgravi all gravity 9.81 vector 0.0 0.0 -1.0" in script
    rows = script.split("coefficientRestitution peratomtypepair 3 &\n\t")[1].split(" &\n\t")[:3]
    e = [[float(v) for v in row.split()[:3]] for row in rows]      # to the last digit, both ways round
    assert e[0] == [cloud.pair.e, cloud.walls["walls"].e, 0.97] and e[1][0] == e[0][1] and e[2][0] == 0.97
    # the gas: the phase's suffix gone everywhere, collheatFoam's names in place
    for f in (out / "CFD").rglob("*"):
        if f.is_file():
            assert ".air" not in f.read_text(), f
    assert (out / "CFD" / "0" / "U").is_file() and (out / "CFD" / "constant" / "turbulenceProperties").is_file()
    assert "div(alphaPhi,U)" in (out / "CFD" / "system" / "fvSchemes").read_text()
    # the tutorial itself is only read; a second import into the same folder is refused
    with pytest.raises(DpmfoamError, match="exists"):
        convert(GOLDSCHMIDT, out)


def test_hot_beads_are_a_type_of_their_own(tmp_path):
    """``hot_below``: the beads below it are atom type 1, the others 2, one material with a
    temperature per type; the walls' types follow."""
    out = tmp_path / "gold"
    done = convert(GOLDSCHMIDT, out, hot_below=0.1445, temperatures=(450.0, 290.0))
    cloud = read_cloud(GOLDSCHMIDT)
    rows = np.array([ln.split() for ln in (out / "DEM" / "particles.data").read_text().split("Atoms")[1].splitlines()
                     if ln.strip()], float)
    assert np.array_equal(rows[:, 1] == 1, cloud.positions[:, 2] < 0.1445) and done["hot"] == 12000
    script = (out / "DEM" / "in.liggghts").read_text()
    assert re.findall(r"primitive type (\d)", script) == ["4", "4", "3", "3", "3", "3"]
    (out / "case.toml").write_text((out / "case.toml").read_text() + MATERIAL)
    particles = load_scene(out / "case.toml").materials["particles"]
    assert particles.types == [1, 2] and (particles.temperature_of(1), particles.temperature_of(2)) == (450.0, 290.0)
    known = user_script(load_scene(out / "case.toml"))["known"]      # the history's groups: hot and cold apart
    assert known.names == ("particles (type 1)", "particles (type 2)") and list(known.group[1:]) == [0, 1]
    with pytest.raises(DpmfoamError, match="hot_below: 0.5 m is not inside"):
        convert(GOLDSCHMIDT, tmp_path / "other", hot_below=0.5)


def test_a_temperature_per_type_needs_one_per_type(tmp_path):
    convert(GOLDSCHMIDT, tmp_path / "gold", hot_below=0.1445)
    toml = tmp_path / "gold" / "case.toml"
    toml.write_text(toml.read_text().replace("temperature = [400.0, 300.0]", "temperature = [400.0]") + MATERIAL)
    with pytest.raises(SceneError, match=r"materials\.particles\.temperature: 1 temperatures for 2 types"):
        load_scene(toml)


def test_converted_case_needs_the_real_material(tmp_path):
    out = tmp_path / "gold"
    convert(GOLDSCHMIDT, out)
    with pytest.raises(SceneError, match=r"materials\.particles.*youngs_modulus"):
        load_scene(out / "case.toml")
    text = (out / "case.toml").read_text()
    (out / "case.toml").write_text(text + MATERIAL)
    scene = load_scene(out / "case.toml")
    assert scene.fluid.drag == "gidaspow" and scene.time.couple_every == 3
    assert scene.fluid.ddt_alpha is False and scene.fluid.case == "CFD" and scene.dem.script == "DEM/in.liggghts"
    assert scene.materials["particles"].types == [1]


def _variant(tmp_path, old: str, new: str) -> Path:
    case = tmp_path / "case"
    shutil.copytree(GOLDSCHMIDT, case)
    props = case / "constant" / "kinematicCloudProperties"
    text = props.read_text()
    assert old in text
    props.write_text(text.replace(old, new, 1))
    return case


@pytest.mark.parametrize("old, new, words", [
    ("nParticle       1;", "nParticle       10;", "nParticle 10"),
    ("cohesionEnergyDensity 0;", "cohesionEnergyDensity 1e3;", "cohesion"),
    ("gravity;", "gravity;\n        pressureGradient { U U.air; }", "pressureGradient"),
    ("ErgunWenYuDrag", "PlessisMasliyahDrag", "PlessisMasliyahDrag"),
    ("type            manualInjection;", "type            patchInjection;", "patchInjection"),
    ("b                   1.5;", "b                   1.0;", "b: 1.0"),
    ("type rebound;\n                e    0.97;\n                mu   0.09;\n            }\n            walls",
     "type escape;\n            }\n            walls", "bottom: type escape"),
])
def test_what_is_not_translated_is_refused(tmp_path, old, new, words):
    with pytest.raises(DpmfoamError, match=re.escape(words)) as err:
        read_cloud(_variant(tmp_path, old, new))
    assert "kinematicCloudProperties" in str(err.value)


@pytest.mark.parametrize("tutorial", ["MPPICFoam/Goldschmidt", "MPPICFoam/column", "MPPICFoam/cyclone",
                                      "MPPICFoam/injectionChannel"])
def test_mppic_parcels_are_refused(tutorial, tmp_path):
    """Debian's MP-PIC tutorials: parcels that never collide, not DEM particles."""
    with pytest.raises(DpmfoamError, match="collisionModel: none.*not DEM particles"):
        convert(EXAMPLES / tutorial, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_mesh_that_is_not_one_box_is_refused(tmp_path):
    case = tmp_path / "case"
    shutil.copytree(GOLDSCHMIDT, case)
    mesh = case / "system" / "blockMeshDict"
    mesh.write_text(mesh.read_text().replace("( 7.5  75 450)", "( 9.5  75 450)"))
    with pytest.raises(DpmfoamError, match="one axis-aligned box"):
        read_cloud(case)
