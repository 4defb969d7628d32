"""A DPMFoam case run as it is by DPMFoam itself and by this host after ``python -m pyhost
dpmfoam`` (tools/dpmfoam_as_is.py): Debian's lagrangian/DPMFoam/Goldschmidt with its positions
file cut to its first 2,500 beads (its ten lowest layers; the whole tutorial takes DPMFoam
about 2 min per 6 ms), 6 ms from rest, engines for real. The beads of its 3 mm lattice (2.5 mm
beads) touch nothing until the lowest layer, 0.25 mm above the floor, lands after about 8 ms:
until then each falls against the drag of the gas rising through the lattice."""
import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
from foamlib import FoamFile

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
from dpmfoam_as_is import dpmfoam, import_case, tutorial  # noqa: E402

BEADS, END, G = 2500, 0.006, 9.81


@pytest.mark.long
def test_imported_goldschmidt_runs_with_its_inlet_and_falls_as_in_dpmfoam(tmp_path):
    """The host's run of the imported tutorial (``--hot-below 0.012``: its four lowest layers
    start at 400 K, the rest at 300 K, a temperature per atom type, each type a temperature group
    of the history): every bead kept inside
    the box; the gas
    entering through the tutorial's interstitialInletVelocity (1.875 m/s superficial) carries
    the same superficial speed through each of the three lowest rows of cells, beads or none,
    within 0.5 % (continuity; the condition reads the host's fluid fraction); the balance
    closes; and the beads' mean vertical velocity is DPMFoam's on the same input within 8 %,
    both well off free fall (-g t = -0.0589 m/s): the drag carries about a third of the weight,
    which the test would see lost or doubled. Measured: host -0.0375, DPMFoam -0.0393 m/s
    (4.6 %; with 500 beads, a bed one cell high, DPMFoam's cell gas velocity at the bed's edge
    departs from its own fluxes and the two differ by 40 %: docs/dpmfoam.md)."""
    case = tutorial(tmp_path / "Goldschmidt", BEADS, END)
    out = import_case(case, tmp_path / "host", END, "--hot-below", "0.012")
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]

    frames = sorted((out / "output" / "vtk").glob("particles_*.vtu"))
    first = meshio.read(frames[0])      # the hot type at 400 K, the cold at 300 K, as the host set them
    hot = first.points[:, 2] < 0.012
    assert hot.sum() == 1000                                            # the four lowest layers
    T = first.point_data["temperature"]
    assert np.all(T[hot] == 400.0) and np.all(T[~hot] == 300.0)
    with open(out / "output" / "history.csv") as f:      # one group per type: the hot and the cold beads apart
        start = next(csv.DictReader(f))
    assert float(start["T_group0"]) == pytest.approx(400.0, abs=1e-9) and float(start["T_group1"]) == pytest.approx(300.0, abs=1e-9)
    frame = meshio.read(frames[-1])
    x, r_, v = frame.points, frame.point_data["radius"], frame.point_data["velocity"]
    assert len(x) == BEADS
    lo, hi = np.array([-0.0075, -0.075, 0.0]), np.array([0.0075, 0.075, 0.45])
    assert np.all(x - r_[:, None] > lo - 1e-4) and np.all(x + r_[:, None] < hi + 1e-4)

    gas = out / "output" / "fluid" / f"{END:g}"
    U = np.asarray(FoamFile(gas / "U")["internalField"], float).reshape(90, 60, 3)[..., 2]
    alpha = np.asarray(FoamFile(gas / "alpha")["internalField"], float).reshape(90, 60)
    assert alpha[0].mean() < 0.7                                      # the beads are in the lowest row
    for row in range(3):
        assert (alpha[row] * U[row]).mean() == pytest.approx(1.875, rel=0.005)

    vz = v[:, 2].mean()
    theirs, _, _ = dpmfoam(Path(shutil.copytree(case, tmp_path / "dpmfoam")), END)
    print(f"mean bead vz after {END} s: host {vz:.5f}, DPMFoam {theirs:.5f} m/s; free fall {-G * END:.5f}")
    assert vz == pytest.approx(theirs, rel=0.08)
    assert -0.8 * G * END < theirs < -0.2 * G * END and -0.8 * G * END < vz < -0.2 * G * END
    summary = json.loads((out / "output" / "summary.json").read_text())
    assert abs(summary["energy_balance_error"]) < 1e-12
    assert summary["groups"] == ["particles (type 1)", "particles (type 2)"]
