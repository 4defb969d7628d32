"""A user's blockMeshDict that reads as OpenFOAM but that blockMesh refuses: bad input
(exit 2) naming the file and blockMesh's own words, before LIGGGHTS or the solver starts,
where the run used to end as a failed simulation (exit 3)."""
import subprocess
import sys
from pathlib import Path

import pytest

from pyhost.engines.fluid_case import FACES, box_case

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

SCENE = """[effects]
fluid = true
[fluid]
case = "fluid"
[materials.steel]
density = 7800.0
youngs_modulus = 210e9
poisson_ratio = 0.3
yield_stress = 300e6
heat_capacity = 470.0
conductivity = 45.0
dem = { youngs_modulus = 2e8, restitution = 0.9 }
[[particles]]
material = "steel"
count = 1
radius = 1e-3
temperature = 300.0
positions = [[0.5, 0.5, 0.5]]
[domain]
box = [0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
[time]
dem_step = 2e-6
end = 1e-3
[output]
pictures = false
"""


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
    (case / "case.toml").write_text(SCENE)
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith(f"error: {case / 'case.toml'}: fluid.case: {mesh}: blockMesh refuses it: ")
    assert "does not have neighbour cell face: 4(0 4 6 3)" in line and "Traceback" not in r.stderr
    assert not (tmp_path / "out" / "summary.json").exists()
    assert not (tmp_path / "out" / "fluid" / "log.collheatFoam").exists()
