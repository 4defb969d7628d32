"""OpenFOAM's own lagrangian tutorials (Debian's openfoam-examples) as the fluid case of a box
scene: their gas runs under collheatFoam with the host's particles, the case as the user has
it. What the host adapts in its copy (fluid_case.adopt_other_solver: the phase's suffix of
MPPICFoam's and DPMFoam's fields, 0.orig, gzipped dictionaries) is said; a case it cannot run
is refused before any engine, naming everything it lacks at once. Each needed three to five
hand edits before (U.air gave only 'lacks 0/U')."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = Path("/usr/share/doc/openfoam-examples/examples/lagrangian")
sys.path.insert(0, str(ROOT / "tools"))
from corpus import TUTORIALS  # noqa: E402  (the corpus's entries: one set of scenes)

ENTRIES = {t.name: t for t in TUTORIALS}


def copy(tmp_path, name: str) -> Path:
    tut = ENTRIES[name]
    if not (EXAMPLES.parent / tut.source).is_dir():
        pytest.fail("no openfoam-examples: tools/setup_engines.sh installs it")
    case = tmp_path / name
    shutil.copytree(EXAMPLES.parent / tut.source, case)
    (case / "case.toml").write_text(tut.case_toml.replace("end = 0.01", "end = 0.004"))
    return case


def test_mppicfoams_column_runs_as_written(tmp_path):
    """MPPICFoam's column (U.air, turbulenceProperties.air, gzipped cloud positions): the gas
    runs 4 ms under 20 beads falling from 0.2-0.28 m; the notes say what was adapted; no bead
    leaves the mesh, the balance closes, the pressure drop is taken along gravity (-z)."""
    case = copy(tmp_path, "MPPICFoam_column")
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert ("fluid case: the gas phase 'air' (continuousPhase) read as collheatFoam's single gas: its suffix "
            "dropped from names (0/U.air -> 0/U; constant/turbulenceProperties.air -> "
            "constant/turbulenceProperties)") in r.stdout
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert s["inserted"] == 20 and s["departed"] == 0 and abs(s["energy_balance_error"]) < 1e-12
    assert s["time"] == pytest.approx(0.004, rel=1e-9)
    assert (case / "0" / "U.air").is_file() and not (case / "0" / "U").exists()   # the user's case untouched


@pytest.mark.parametrize("name, words", [
    ("MPPICFoam_cyclone", "constant/polyMesh: the case's mesh is snappyHexMesh's (system/snappyHexMeshDict)"),
    ("icoUncoupled_hopper", "lacks what collheatFoam needs: 0/p; system/fvSolution solvers p; system/fvSolution "
                            "solvers U; system/fvSolution PIMPLE (or PISO) dictionary"),
])
def test_a_case_the_host_cannot_run_is_refused_naming_all_it_lacks(tmp_path, name, words):
    """The cyclone's mesh is snappyHexMesh's, which the host does not run; the hopper's solver
    moves no gas (no p, no solvers, no PIMPLE): each refused when the scene is read, every gap
    named in one message, before LIGGGHTS or the solver starts."""
    from pyhost.scene import SceneError, load_scene

    case = copy(tmp_path, name)
    with pytest.raises(SceneError) as err:
        load_scene(case / "case.toml")
    assert words in str(err.value) and f"{case} (as the host adapts it)" in str(err.value)


def test_a_dictionary_openfoam_cannot_read_is_named_before_the_engines(tmp_path):
    """A '{' too many in fvSchemes stopped the solver at its start (exit 3); now the scene is
    refused naming the file and OpenFOAM's own words and line (foamDictionary decides where
    foamlib cannot read a file)."""
    from pyhost.scene import SceneError, load_scene

    case = copy(tmp_path, "MPPICFoam_column")
    schemes = case / "system" / "fvSchemes"
    schemes.write_text(schemes.read_text().replace("gradSchemes\n{", "gradSchemes\n{{", 1))
    with pytest.raises(SceneError, match=rf"{case} \(as the host adapts it\)/system/fvSchemes: OpenFOAM cannot read "
                                         r"it: Found \{ but expected \} file: system/fvSchemes at line \d+"):
        load_scene(case / "case.toml")


def test_the_inlet_speed_of_a_users_case_is_read_from_its_inlets(tmp_path):
    """MPPICFoam's injectionChannel lets its gas in through two patches at (18.7939, +-6.8404, 0)
    m/s, each perpendicular to its face: history.csv's u_inlet is that speed, 20.0000437 m/s, to
    1e-9 (it was NaN for every user's case); the closed column has none (NaN)."""
    import csv
    import math

    for name, want in (("MPPICFoam_injectionChannel", math.hypot(18.7939, 6.8404)), ("MPPICFoam_column", None)):
        case = copy(tmp_path, name)
        toml = case / "case.toml"
        toml.write_text(toml.read_text().replace("end = 0.004", "end = 0.001"))
        r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(tmp_path / name)],
                           capture_output=True, text=True, cwd=ROOT, timeout=600)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        with open(tmp_path / name / "history.csv") as f:
            speeds = [float(row["u_inlet"]) for row in csv.DictReader(f)]
        assert len(speeds) >= 2
        if want is None:
            assert all(math.isnan(u) for u in speeds)
        else:
            assert speeds == pytest.approx([want] * len(speeds), rel=1e-9)
