"""A user's blockMeshDict that reads as OpenFOAM but that blockMesh refuses: bad input
(exit 2) naming the file and blockMesh's own words, before LIGGGHTS or the solver starts,
where the run used to end as a failed simulation (exit 3)."""
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import tomli_w

from pyhost.engines.fluid_case import FACES, box_case

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

BASE = tomllib.loads((ROOT / "cases" / "two-particles" / "case.toml").read_text())
SCENE = dict(BASE, effects={"fluid": True}, fluid={"case": "fluid"}, output={"pictures": False})


def test_blockmesh_refusal_is_bad_input(tmp_path):
    """The xlo patch's face (0 4 6 3) is no face of the block: blockMesh stops with 'does
    not have neighbour cell face'."""
    case = tmp_path / "case"
    walls = {face: "wall" for face in FACES}
    fluid = box_case(case / "fluid", lo=(0, 0, 0), hi=(1, 1, 1), cells=(1, 1, 1), boundaries=walls, rho=1.2,
                     nu=1.5e-5)
    mesh = fluid / "system" / "blockMeshDict"
    mesh.write_text(mesh.read_text().replace("(0 4 7 3)", "(0 4 6 3)"))
    assert "0 4 6 3" in mesh.read_text()
    (case / "case.toml").write_text(tomli_w.dumps(SCENE))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith(f"error: {case / 'case.toml'}: fluid.case: {mesh}: blockMesh refuses it: ")
    assert "does not have neighbour cell face: 4(0 4 6 3)" in line and "Traceback" not in r.stderr
    assert not (tmp_path / "out" / "summary.json").exists()
    assert not (tmp_path / "out" / "fluid" / "log.collheatFoam").exists()
