"""A catalogue of bad inputs: each ends with its exit code (docs/exit-codes.md) and one line
naming the file and the key (or the option), never a traceback, and nothing written where a
run would write. Scene and CLI entries run in process in seconds (refused before any engine
starts); entries needing a real engine are in tests/engines/test_engine_fault_catalogue.py."""
import copy
import json
import resource
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from pyhost.cli import main

STEEL = dict(density=7800.0, youngs_modulus=210e9, poisson_ratio=0.3, yield_stress=300e6, heat_capacity=470.0,
             conductivity=45.0, dem=dict(youngs_modulus=2e8, restitution=0.9, poisson_ratio=0.3))
BASE = {   # cases/two-particles, shortened
    "effects": {"contact_heat": "A", "heat_path": "exact"},
    "materials": {"steel": STEEL},
    "particles": [dict(material="steel", count=1, radius=2e-3, temperature=400.0, positions=[[0.045, 0.005, 0.01]],
                       velocity=[0.2, 0.0, 0.0]),
                  dict(material="steel", count=1, radius=2e-3, temperature=300.0, positions=[[0.0492, 0.005, 0.01]],
                       velocity=[-0.2, 0.0, 0.0])],
    "domain": {"box": [0.0, 0.1, 0.0, 0.01, 0.0, 0.02], "gravity": [0.0, 0.0, 0.0]},
    "time": {"dem_step": 2e-7, "end": 2e-3},
    "output": {"every": 2e-4, "pictures": False},
}
NAN, INF = float("nan"), float("inf")


def setter(path, value):
    """A change of the scene: the value at a dotted path (ints index lists)."""
    def change(scene):
        *head, last = path
        node = scene
        for key in head:
            node = node[key]
        node[last] = value
    return change


def remove(path):
    def change(scene):
        *head, last = path
        node = scene
        for key in head:
            node = node[key]
        del node[last]
    return change


def group(**values):
    """Replace the particle groups by one region group of these values."""
    g = dict(material="steel", count=10, radius=1e-3, temperature=300.0, region=[0.0, 0.02, 0.0, 0.01, 0.0, 0.02])
    g.update(values)
    return setter(("particles",), [g])


def fluid(**values):
    def change(scene):
        scene["effects"]["fluid"] = True
        scene["fluid"] = dict(values)
    return change


def both(*changes):
    def change(scene):
        for c in changes:
            c(scene)
    return change


P0 = ("particles", 0)
SCENES = {   # id: (change, words the one-line message must hold)
    "materials is a number": (setter(("materials",), 5), ["materials"]),
    "walls is a number": (setter(("walls",), 5), ["walls"]),
    "a material is a number": (setter(("materials", "steel"), 5), ["materials.steel"]),
    "flat positions": (setter(P0 + ("positions",), [0.045, 0.005, 0.01]), ["particles[0].positions"]),
    "periodic as strings": (setter(("domain", "periodic"), ["no", "no", "no"]), ["domain.periodic", "booleans"]),
    "periodic too short": (setter(("domain", "periodic"), [True, True]), ["domain.periodic"]),
    "gravity with NaN": (setter(("domain", "gravity"), [0.0, 0.0, NAN]), ["domain.gravity[2]", "finite"]),
    "gravity infinite": (setter(("domain", "gravity"), [INF, 0.0, 0.0]), ["domain.gravity[0]", "finite"]),
    "box infinite": (setter(("domain", "box"), [0.0, INF, 0.0, 0.01, 0.0, 0.02]), ["domain.box[1]"]),
    "position NaN": (setter(P0 + ("positions",), [[NAN, 0.005, 0.01]]), ["particles[0].positions[0][0]"]),
    "velocity infinite": (setter(P0 + ("velocity",), [INF, 0.0, 0.0]), ["particles[0].velocity[0]"]),
    "velocity of two": (setter(P0 + ("velocity",), [1.0, 0.0]), ["particles[0].velocity"]),
    "wall on a periodic axis": (both(setter(("domain", "periodic"), [True, False, False]),
                                     setter(("walls",), [dict(plane="xlo", material="steel")])),
                                ["walls[0].plane", "periodic"]),
    "alpha_min 2": (fluid(alpha_min=2.0), ["fluid.alpha_min"]),
    "alpha_min 1": (fluid(alpha_min=1.0), ["fluid.alpha_min"]),
    "alpha_min 0": (fluid(alpha_min=0.0), ["fluid.alpha_min"]),
    "output.every below the step": (setter(("output", "every"), 1e-8), ["output.every", "dem_step"]),
    "test_end beyond end": (setter(("time", "test_end"), 1.0), ["time.test_end"]),
    "2.5e9 particles": (group(count=2_500_000_000, region=[0.0, 0.1, 0.0, 0.01, 0.0, 0.02]), ["particles", "32-bit"]),
    "particles overlapping 3 mm": (setter(("particles", 1, "positions"), [[0.046, 0.005, 0.01]]),
                                   ["particles[0].positions[0]", "particles[1].positions[0]", "overlap"]),
    "overlap across a periodic face": (both(setter(("domain", "periodic"), [True, False, False]),
                                            setter(P0 + ("positions",), [[0.0005, 0.005, 0.01]]),
                                            setter(("particles", 1, "positions"), [[0.0995, 0.005, 0.01]])),
                                       ["overlap", "periodic images"]),
    "bead 1 mm inside a wall": (both(setter(("walls",), [dict(plane="zlo", material="steel")]),
                                     setter(P0 + ("positions",), [[0.045, 0.005, 0.001]])),
                                ["particles[0].positions[0]", "wall zlo"]),
    "position outside the box": (setter(P0 + ("positions",), [[0.5, 0.005, 0.01]]),
                                 ["particles[0].positions[0]", "outside the box"]),
    "region outside the box": (group(region=[0.0, 0.02, 0.0, 0.01, 0.0, 0.05]), ["particles[0].region", "inside the box"]),
    "region wider than a periodic box": (both(setter(("domain", "periodic"), [True, True, True]),
                                              group(region=[-0.01, 0.11, 0.0, 0.01, 0.0, 0.02])),
                                         ["particles[0].region"]),
    "region too small for the count": (group(count=1000), ["particles[0].region", "holds"]),
    "DEM step too long for the speed": (setter(("time", "dem_step"), 5e-5), ["time.dem_step", "use dem_step <="]),
    "DEM step too long for the spread": (both(setter(P0 + ("velocity_spread",), 50.0), setter(("time", "dem_step"), 1e-5)),
                                         ["time.dem_step", "velocity_spread"]),
    "no particles": (setter(("particles",), []), ["particles"]),
    "unknown section": (setter(("particle",), {}), ["particle", "unknown section"]),
    "unknown material key": (setter(("materials", "steel", "colour"), "grey"), ["materials.steel.colour"]),
    "negative density": (setter(("materials", "steel", "density"), -1.0), ["materials.steel.density"]),
    "density a string": (setter(("materials", "steel", "density"), "heavy"), ["materials.steel.density"]),
    "radius a boolean": (setter(P0 + ("radius",), True), ["particles[0].radius"]),
    "radius zero": (setter(P0 + ("radius",), 0.0), ["particles[0].radius"]),
    "count not integer": (setter(P0 + ("count",), 1.5), ["particles[0].count"]),
    "restitution above one": (setter(("materials", "steel", "dem", "restitution"), 1.5),
                              ["materials.steel.dem.restitution"]),
    "Poisson ratio 0.5": (setter(("materials", "steel", "poisson_ratio"), 0.5), ["materials.steel.poisson_ratio"]),
    "b2 below b1": (setter(("materials", "steel", "b2"), 1.0), ["materials.steel.b2"]),
    "unknown material": (setter(P0 + ("material",), "gold"), ["particles[0].material", "gold"]),
    "region and positions": (setter(P0 + ("region",), [0.0, 0.1, 0.0, 0.01, 0.0, 0.02]), ["particles[0]", "either"]),
    "positions fewer than count": (setter(P0 + ("count",), 2), ["particles[0].positions"]),
    "box min above max": (setter(("domain", "box"), [0.1, 0.0, 0.0, 0.01, 0.0, 0.02]), ["domain.box"]),
    "step beyond end": (setter(("time", "dem_step"), 1.0), ["time.dem_step"]),
    "unknown contact model": (setter(("effects", "contact_heat"), "D"), ["effects.contact_heat"]),
    "unknown heat path": (setter(("effects", "heat_path"), "quick"), ["effects.heat_path"]),
    "feedback without model": (both(setter(("effects", "contact_heat"), "none"),
                                    setter(("effects", "restitution_feedback"), True)),
                               ["effects.restitution_feedback"]),
    "fluid without section": (setter(("effects", "fluid"), True), ["fluid", "missing"]),
    "fluid cells zero": (fluid(cells=[0, 1, 1]), ["fluid.cells"]),
    "inlet table decreasing": (fluid(inlet_table=[[0.0, 0.1], [0.0, 0.2]]), ["fluid.inlet_table"]),
    "inlet table and velocity": (fluid(inlet_table=[[0.0, 0.1]], inlet_velocity=1.0), ["fluid.inlet_table"]),
    "unknown drag law": (fluid(drag="stokes"), ["fluid.drag"]),
    "fluid ranks zero": (fluid(ranks=0), ["fluid.ranks"]),
    "fluid ranks above the cells across": (fluid(cells=[4, 1, 8], ranks=5), ["fluid.ranks = 5", "only 4 cells there"]),
    "missing time": (remove(("time",)), ["time", "missing"]),
    "sample_every zero": (setter(("time", "sample_every"), 0), ["time.sample_every"]),
    "contacts sampled (retired)": (setter(("time", "contacts"), "samples"), ["time.contacts", "retired"]),
    "wall temperature negative": (setter(("walls",), [dict(plane="zlo", material="steel", temperature=-1.0)]),
                                  ["walls[0].temperature"]),
    "wall plane unknown": (setter(("walls",), [dict(plane="top", material="steel")]), ["walls[0].plane"]),
}


def run_main(args, capsys):
    code = main([str(a) for a in args])
    err = capsys.readouterr().err
    return code, err


def assert_one_line(err, words):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.fixture
def no_engine(monkeypatch):
    """Fail at once, rather than run an engine in this process, if a scene got through."""
    def started(*args, **kwargs):
        raise AssertionError("an engine was started")
    monkeypatch.setattr("pyhost.engines.dem.Dem", started)
    monkeypatch.setattr("pyhost.world.start_fluid", started)


@pytest.mark.parametrize("name", SCENES)
def test_bad_scene_is_refused_before_any_engine(name, tmp_path, capsys, no_engine):
    change, words = SCENES[name]
    scene = copy.deepcopy(BASE)
    change(scene)
    case = tmp_path / "case"
    case.mkdir()
    (case / "case.toml").write_text(tomli_w.dumps(scene))
    code, err = run_main(["run", case, "--out", tmp_path / "out"], capsys)
    assert code == 2, err
    assert_one_line(err, [str(case / "case.toml"), *words])
    assert not (tmp_path / "out" / "summary.json").exists() and not (tmp_path / "out" / "dem").exists()


def user_fluid_case(folder: Path, ranks: int = 1) -> Path:
    """A user's OpenFOAM case of our own writing: a 1 cm box of 2 x 1 x 4 cells, faces named
    xlo .. zhi, gas in at zlo; rho in 0/rho (as CFDEM cases keep it), not in transportProperties."""
    from foamlib import FoamFile

    from pyhost.engines.fluid_case import box_case
    faces = dict(xlo="wall", xhi="wall", ylo="slip", yhi="slip", zlo=("inlet", (0.0, 0.0, 0.1)), zhi="outlet")
    box_case(folder, lo=(0, 0, 0), hi=(0.01, 0.005, 0.02), cells=(2, 1, 4), boundaries=faces, rho=1.2,
             nu=1.5e-5, nprocs=ranks)
    del FoamFile(folder / "constant" / "transportProperties")["rho"]
    (folder / "0" / "rho").write_text("FoamFile { version 2.0; format ascii; class volScalarField; object rho; }\n"
                                      "dimensions [1 -3 0 0 0 0 0];\ninternalField uniform 1.2;\n"
                                      'boundaryField { ".*" { type zeroGradient; } }\n')
    return folder


def foam_edit(rel, key, value=None):
    """A change of the user's case: set (or with None delete) a key of one of its files."""
    def change(case):
        from foamlib import FoamFile
        f = FoamFile(case / "fluid" / rel)
        if value is None:
            del f[key]
        else:
            f[key] = value
    return change


def foam_rename(rel, old, new):
    """Rename a patch's entry of a field's boundaryField."""
    def change(case):
        from foamlib import FoamFile
        f = FoamFile(case / "fluid" / rel)
        f["boundaryField", new] = f["boundaryField", old]
        del f["boundaryField", old]
    return change


def foam_text(rel, text):
    def change(case):
        path = case / "fluid" / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.unlink() if text is None else path.write_text(text)
    return change


def foam_scene(**fluid_keys):
    def change(case):
        scene = copy.deepcopy(BASE)
        scene["effects"]["fluid"] = True
        scene["fluid"] = dict(case="fluid", **fluid_keys)
        (case / "case.toml").write_text(tomli_w.dumps(scene))
    return change


BLOCKS = ("FoamFile { version 2.0; format ascii; class dictionary; object blockMeshDict; }\n"
          "vertices ((0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1));\n"
          "blocks (hex (0 1 2 3 4 5 6 VERTEX) (1 1 1) simpleGrading (1 1 1));\n"
          "patches (wall xlo ((0 4 7 3)) wall xhi ((1 2 6 5)) wall ylo ((0 1 5 4)) wall yhi ((3 7 6 2))"
          " patch zlo ((0 3 2 1)) patch zhi ((4 5 6 7)));\n")
POLYMESH = ("FoamFile { version 2.0; format ascii; class polyBoundaryMesh; object boundary; }\n6 (\n"
            + "".join(f"{n} {{ type wall; inGroups List<word> 1(wall); nFaces 1; startFace {k}; }}\n"
                      for k, n in enumerate(("xlo", "xhi", "ylo", "yhi", "bottom", "zhi"))) + ")\n")
FLUID_CASES = {   # id: (changes of the valid user case, words the one-line message must hold)
    "rho nowhere": ([foam_text("0/rho", None)], ["transportProperties has no rho and there is no 0/rho"]),
    "0/rho not uniform": ([foam_edit("0/rho", "internalField", np.full(8, 1.2))],
                          ["0/rho: internalField: the gas density must be one uniform"]),
    "0/rho negative": ([foam_edit("0/rho", "internalField", -1.0)], ["0/rho: internalField", "uniform positive"]),
    "rho a word": ([foam_edit("constant/transportProperties", "rho", "air")], ["transportProperties: rho: must be a number", "'air'"]),
    "nu missing": ([foam_edit("constant/transportProperties", "nu")], ["transportProperties: nu: missing"]),
    "0/U patch misnamed": ([foam_rename("0/U", "zhi", "top")],
                           ["0/U: boundaryField", "patch 'zhi'", "system/blockMeshDict", "instead of 'top'"]),
    "0/p patch missing": ([foam_edit("0/p", ("boundaryField", "xlo"))], ["0/p: boundaryField", "patch 'xlo'"]),
    "0/p regex not matching": ([foam_edit("0/p", ("boundaryField", "xlo")), foam_edit("0/p", ("boundaryField", "xhi")),
                                foam_edit("0/p", ("boundaryField", '"x(l|h)i"'), {"type": "zeroGradient"})],
                               ["0/p: boundaryField", "patch 'xlo'"]),
    "polyMesh without points": ([foam_text("constant/polyMesh/owner", "")],
                                ["constant/polyMesh: has owner but lacks points, faces, neighbour, boundary"]),
    "polyMesh patch without entry": ([foam_text(f"constant/polyMesh/{name}", "")
                                      for name in ("owner", "points", "faces", "neighbour")]
                                     + [foam_text("constant/polyMesh/boundary", POLYMESH)],
                                     ["0/U: boundaryField", "patch 'bottom'", "constant/polyMesh/boundary"]),
    "blockMeshDict not OpenFOAM": ([foam_text("system/blockMeshDict", BLOCKS.replace("(0 1 1));", "(0 1 1);"))],
                                   ["system/blockMeshDict: OpenFOAM cannot read it", "system/blockMeshDict at line 5"]),
    "block names a missing vertex": ([foam_text("system/blockMeshDict", BLOCKS.replace("VERTEX", "8"))],
                                     ["system/blockMeshDict: blocks", "from 0 to 7"]),
    "blockMeshDict without blocks": ([foam_edit("system/blockMeshDict", "blocks")], ["blockMeshDict: blocks: missing"]),
    "CFDEM's fvOption for two phases": ([foam_text("system/fvOptions", "FoamFile { version 2.0; format ascii; "
                                                  "class dictionary; object fvOptions; }\nmomentumSource { type "
                                                  "meanSupVelocityForce; active yes; meanSupVelocityForceCoeffs "
                                                  "{ twoPhase true; } }\n")],
                                       ["system/fvOptions: momentumSource: meanSupVelocityForce with twoPhase true"]),
    "subdomains differ from ranks": ([foam_scene(ranks=2)],
                                     ["decomposeParDict: numberOfSubdomains: 1, but fluid.ranks = 2"]),
    "simple split differs from ranks": ([foam_scene(ranks=2), foam_edit("system/decomposeParDict",
                                                                         "numberOfSubdomains", 2)],
                                        ["decomposeParDict: simpleCoeffs.n: [1, 1, 1] makes 1"]),
}


def fluid_case_with(changes, tmp_path):
    case = tmp_path / "case"
    case.mkdir()
    user_fluid_case(case / "fluid")
    foam_scene()(case)
    for change in changes:
        change(case)
    return case


@pytest.mark.parametrize("name", FLUID_CASES)
def test_bad_user_fluid_case_is_refused_before_any_engine(name, tmp_path, capsys, no_engine):
    """Mistakes in a user's OpenFOAM case that collheatFoam would only find at its start."""
    changes, words = FLUID_CASES[name]
    case = fluid_case_with(changes, tmp_path)
    code, err = run_main(["run", case, "--out", tmp_path / "out"], capsys)
    assert code == 2, err
    assert_one_line(err, [str(case / "case.toml"), "fluid.case", *words])
    assert not (tmp_path / "out" / "summary.json").exists()


@pytest.mark.parametrize("changes", [[], [foam_scene(ranks=2), foam_edit("system/decomposeParDict",
                                                                           "numberOfSubdomains", 2),
                                          foam_edit("system/decomposeParDict", ("coeffs", "n"), [2, 1, 1])],
                                     [foam_text("system/blockMeshDict", BLOCKS.replace("VERTEX", "7"))],
                                     [foam_edit("0/p", "boundaryField", {'".*"': {"type": "zeroGradient"}}),
                                      foam_edit("0/U", "boundaryField", {"wall": {"type": "noSlip"},
                                                                         '"(y.*|z.*)"': {"type": "slip"}})]],
                         ids=["0/rho", "two ranks", "old-style patches", "regex and group entries"])
def test_valid_user_fluid_case_is_accepted(changes, tmp_path):
    """The catalogue's valid user case (rho in 0/rho) and valid variants pass the checks."""
    from pyhost.scene import load_scene
    assert load_scene(fluid_case_with(changes, tmp_path) / "case.toml").fluid.case == "fluid"


def base_case(tmp_path):
    case = tmp_path / "case"
    case.mkdir(exist_ok=True)
    (case / "case.toml").write_text(tomli_w.dumps(BASE))
    return case


def test_base_scene_is_valid():
    """The catalogue's base passes validation: each entry fails for its own change only."""
    from pyhost.scene import load_scene
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        assert load_scene(base_case(Path(d)) / "case.toml").time.end == 2e-3


def file_fault(kind):
    def make(tmp_path):
        case = tmp_path / "case"
        case.mkdir()
        if kind == "folder":
            (case / "case.toml").mkdir()
        elif kind == "latin-1":
            (case / "case.toml").write_bytes(tomli_w.dumps(BASE).encode() + b"# caf\xe9\n")
        elif kind == "toml":
            (case / "case.toml").write_text("[time\n")
        return case
    return make


FILES = {
    "case.toml is a folder": (file_fault("folder"), ["is a folder"]),
    "non-UTF-8 bytes": (file_fault("latin-1"), ["not UTF-8", "line ", "0xe9"]),
    "not TOML": (file_fault("toml"), ["not valid TOML"]),
    "no case.toml": (file_fault("none"), ["no such scene file"]),
}


@pytest.mark.parametrize("name", FILES)
def test_bad_scene_file(name, tmp_path, capsys):
    make, words = FILES[name]
    case = make(tmp_path)
    code, err = run_main(["run", case, "--out", tmp_path / "out"], capsys)
    assert code == 2
    assert_one_line(err, [str(case / "case.toml"), *words])


def out_fault(kind):
    def make(tmp_path):
        out = tmp_path / "out"
        if kind == "file":
            out.write_text("not a folder")
        elif kind == "under a file":
            (tmp_path / "f").write_text("")
            out = tmp_path / "f" / "out"
        elif kind == "another run":
            out.mkdir()
            (out / "summary.json").write_text('{"status": "completed"}')
        return out
    return make


OUTS = {
    "--out is a file": (out_fault("file"), ["--out", "is a file"]),
    "--out under a file": (out_fault("under a file"), ["--out", "cannot write"]),
    "--out holds another run": (out_fault("another run"), ["--out", "--overwrite"]),
}


@pytest.mark.parametrize("name", OUTS)
def test_bad_output_folder(name, tmp_path, capsys):
    make, words = OUTS[name]
    out = make(tmp_path)
    code, err = run_main(["run", base_case(tmp_path), "--out", out], capsys)
    assert code == 2
    assert_one_line(err, [str(out), *words])
    if name == "--out holds another run":
        assert json.loads((out / "summary.json").read_text()) == {"status": "completed"}   # nothing lost


def test_full_disk_is_a_message_and_leaves_no_half_file(tmp_path):
    """A file size limit stands in for a full disk: scene.json cannot be written."""
    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (1000, 1000))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(base_case(tmp_path)), "--out", str(out)],
                       capture_output=True, text=True, preexec_fn=small_files)
    assert r.returncode == 2
    assert_one_line(r.stderr, ["scene.json", "File too large"])
    assert not (out / "scene.json").exists() and not list(out.glob(".*.tmp"))


WRITERS = {  # id: (the writing, in a process whose files may not exceed 300 bytes; the file named)
    "a VTK frame": ("s = VtkSeries(out / 'vtk', 'particles'); s._indexed = 1e18\n"
                    "s.write(0.0, np.random.rand(100, 3), T=np.random.rand(100)); s.flush()", "vtk/particles_00000.vtu"),
    "the .pvd index": ("s = VtkSeries(out / 'vtk', 'particles'); s.frames = [(k * 0.1, f'f{k}.vtu') for k in range(20)]\n"
                       "s.flush()", "vtk/particles.pvd"),
    "a CSV log's header": ("CsvLog(out / 'history.csv', tuple(f'column_{k}' for k in range(40)))", "history.csv"),
    "the DEM's particle data": ("from pyhost.engines.liggghts.box_input import place_particles, write_data\n"
                                "from pyhost.scene import load_scene\n"
                                "scene = load_scene(out.parent / 'case' / 'case.toml')\n"
                                "write_data(out / 'particles.data', scene, place_particles(scene))", "particles.data"),
}


@pytest.mark.parametrize("name", WRITERS)
def test_full_disk_names_the_file(name, tmp_path):
    """A full disk (a file size limit stands in) while a run's output is written: the message
    named 'a file' (the write or flush that failed names none); it names the file, and a
    frame or an index cut short is not left behind."""
    code, file = WRITERS[name]
    case = tmp_path / "case"
    case.mkdir()
    scene = copy.deepcopy(BASE)
    group(count=50)(scene)
    (case / "case.toml").write_text(tomli_w.dumps(scene))
    program = ("import resource, signal, numpy as np\nfrom pathlib import Path\n"
               "from pyhost.output import CsvLog, VtkSeries\nfrom pyhost.exitcodes import classify\n"
               f"out = Path({str(tmp_path / 'out')!r}); out.mkdir()\n"
               "resource.setrlimit(resource.RLIMIT_FSIZE, (300, 300)); signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
               "try:\n" + "".join(f"    {line}\n" for line in code.splitlines())
               + "except OSError as exc:\n    print(classify(exc)[1])\n")
    r = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert r.stdout.strip() == f"{tmp_path / 'out' / file}: File too large", r.stdout + r.stderr
    assert not list((tmp_path / "out").rglob("*.vtu")) and not list((tmp_path / "out").rglob("*.tmp"))


CLI = {  # id: (arguments, exit code, words)
    "unknown command": (["fly"], 2, ["invalid choice"]),
    "run without case": (["run"], 2, ["case"]),
    "collide v0 1e300": (["collide", "--v0", "1e300"], 2, ["--v0", "overflow"]),
    "collide v0 1e300 fast": (["collide", "--v0", "1e300", "--method", "fast"], 2, ["--v0", "overflow"]),
    "collide R 1e100": (["collide", "--R1", "1e100", "--R2", "1e100"], 2, ["R1=1e+100", "double precision"]),
    "collide E* 1e300": (["collide", "--Estar", "1e300"], 2, ["Estar=1e+300"]),
    "collide dT 1e308": (["collide", "--dT", "1e308"], 2, ["dT=1e+308"]),
    "collide v0 negative": (["collide", "--v0", "-1"], 2, ["v0"]),
    "collide v0 not a number": (["collide", "--v0", "fast"], 2, ["--v0"]),
    "collide model D": (["collide", "--model", "D"], 2, ["--model"]),
    "collide R1 zero": (["collide", "--R1", "0"], 2, ["R1"]),
    "collide Y NaN": (["collide", "--Y", "nan"], 2, ["Y"]),
    "pictures of no run": (["pictures", "/nonexistent"], 2, ["history.csv"]),
    "post --var without its script": (["post", "dump.*", "--scene", "scene.toml", "--var", "n", "5"], 2,
                                      ["--var", "--script"]),
}


@pytest.mark.parametrize("name", CLI)
def test_bad_command_line(name, capsys):
    args, code, words = CLI[name]
    try:
        got, err = run_main(args, capsys)
    except SystemExit as exit_:            # argparse's own errors
        got, err = exit_.code, capsys.readouterr().err
    assert got == code, err
    assert "Traceback" not in err and all(w in err for w in words), err


def strict_json(text):
    def no_constant(name):
        raise AssertionError(f"{name} in JSON output")
    return json.loads(text, parse_constant=no_constant)


@pytest.mark.parametrize("args,flag", [(["--v0", "1e6"], "delta_max_exceeds_radius"),
                                       (["--v0", "1e6", "--method", "fast"], "delta_max_exceeds_radius"),
                                       (["--v0", "1e4", "--method", "fit"], "outside_fit_range"),
                                       (["--v0", "4000", "--model", "hertz"], "delta_max_exceeds_radius"),
                                       (["--v0", "1", "--b1", "1.5", "--b2", "3", "--method", "fit"],
                                        "outside_fit_range")])
def test_collision_outside_validity_is_flagged_in_valid_json(args, flag, capsys):
    code = main(["collide", "--json", *args])
    out, err = capsys.readouterr()
    assert code == 0
    row = strict_json(out)
    assert flag in row["flags"] and flag in err


def test_collision_inside_validity_has_no_flag(capsys):
    assert main(["collide", "--json", "--v0", "1"]) == 0
    assert strict_json(capsys.readouterr().out)["flags"] == []


def test_corrupt_table_cache_is_rebuilt_with_a_warning(tmp_path, monkeypatch):
    from plugins.heat import fast
    from plugins.heat.table_cache import CacheWarning
    monkeypatch.setenv("COLLHEAT_CACHE", str(tmp_path))
    fast.table.cache_clear()
    try:
        good = fast.collide_fast([1.0], model="B")["Q"]
        fast.table.cache_clear()
        stored = next(tmp_path.glob("table-B-*.npy"))
        data = bytearray(stored.read_bytes())
        data[len(data) // 2] ^= 0xFF
        stored.write_bytes(bytes(data))
        with pytest.warns(CacheWarning, match="corrupt"):
            again = fast.collide_fast([1.0], model="B")["Q"]
        assert again == good
        fast.table.cache_clear()
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("error", CacheWarning)   # the rebuilt table is sound
            assert fast.collide_fast([1.0], model="B")["Q"] == good
    finally:
        fast.table.cache_clear()


def test_fluid_mesh_rebuilt_when_its_inputs_change(tmp_path):
    from pyhost.engines.fluid_case import box_case
    walls = {f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")}
    make = lambda cells: box_case(tmp_path, lo=(0, 0, 0), hi=(1, 1, 1), cells=cells, boundaries=walls, rho=1.0, nu=1e-5)
    mesh = make((2, 2, 2)) / "constant" / "polyMesh"
    mesh.mkdir()
    (mesh / "owner").write_text("built")
    make((2, 2, 2))
    assert (mesh / "owner").exists()               # same inputs: the mesh is kept
    make((2, 2, 3))
    assert not mesh.exists()                       # other cells: built anew by the next start


@pytest.mark.parametrize("where", ["before", "after"])
def test_debug_shows_the_error_itself(where, tmp_path):
    """--debug (before or after the command) lets the exception through, for its traceback."""
    from pyhost.scene import SceneError
    args = ["run", str(tmp_path / "missing")]
    with pytest.raises(SceneError, match="no such scene file"):
        main(["--debug", *args] if where == "before" else [*args, "--debug"])


POST_SCENE = """[materials.glass]
types = [1]
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.22
yield_stress = 500e6
heat_capacity = 800.0
conductivity = 1.0
dem = { youngs_modulus = 5e6, restitution = 0.8, poisson_ratio = 0.3 }
"""


@pytest.mark.parametrize("script,line", [("fix m1 all property/global youngsModulus peratomtype ${E}\n", 2),
                                         ("variable E2 equal 2*${E}\nfix m1 all property/global youngsModulus "
                                          "peratomtype ${E2}\n", 3)],
                         ids=["used directly", "through a variable"])
def test_post_var_not_a_number(script, line, tmp_path, capsys):
    """``post --var E abc``, where the script's property/global takes ${E}: LIGGGHTS would put
    the word in the command and post used the scene's modulus with exit 0; refused before any
    dump is read, naming the variable, its value and the script's line."""
    (tmp_path / "in.s").write_text("units si\n" + script + "timestep 1e-5\n")
    (tmp_path / "scene.toml").write_text(POST_SCENE)
    code, err = run_main(["post", tmp_path / "dump.*", "--scene", tmp_path / "scene.toml", "--script",
                          tmp_path / "in.s", "--var", "E", "abc", "--out", tmp_path / "out"], capsys)
    assert code == 2, err
    assert_one_line(err, ["--var E 'abc'", "not a number", f"in.s: line {line}", "youngsModulus"])
    assert not (tmp_path / "out").exists()
