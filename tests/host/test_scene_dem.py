"""The scene DEM on the real LIGGGHTS: the fluid-force array starts at zero, however many engines
the process built before (the array is uninitialised memory until set).

The engines are built in a fresh Python process: the bridge tries each command in a forked
copy, and a fork of a process where another test already started MPI can hang in MPI."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "packed-bed-ergun" / "case.toml"

SCRIPT = """
import json, sys
import numpy as np
from pathlib import Path
from pyhost.engines.liggghts.worlds import box_world
from pyhost.engines.dem import FLUID_FIX, Dem
from pyhost.scene import load_scene
from pyhost.engines.liggghts.script import read_script
scene = load_scene(sys.argv[1])
g, dt = np.array(scene.domain.gravity), scene.time.dem_step
result = []
for k in range(4):
    out = Path(sys.argv[2]) / f"run{k}"
    script, _ = box_world(scene, out)
    dem = Dem(out / "dem")
    for cmd in read_script(script)[:-1]:
        dem.command(cmd)
    dem.prepare(heat=False, fluid_force=True)
    force = float(np.abs(dem.lmp.external_force(FLUID_FIX)).max())
    v0 = dem.atoms(False).v.copy()
    dem.run(1)
    result.append((force, float(np.abs(dem.atoms(False).v - v0 - g * dt).max())))
    dem.lmp.close()
print(json.dumps(result))
"""


def test_first_step_feels_gravity_only(tmp_path):
    """Free particles of the lattice (no contact yet): one step changes v by g dt exactly,
    for each of four engines built in turn in one process."""
    from pyhost.scene import load_scene

    r = subprocess.run([sys.executable, "-c", SCRIPT, str(CASE), str(tmp_path)], capture_output=True,
                       text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    scene = load_scene(CASE)
    g_dt = abs(scene.domain.gravity[2]) * scene.time.dem_step                # m/s
    for k, (force, dv_error) in enumerate(json.loads(r.stdout.strip().splitlines()[-1])):
        assert force == 0.0, k
        assert dv_error <= 1e-12 * g_dt, k
