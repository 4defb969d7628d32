#!/usr/bin/env python3
"""DPMFoam and this host on one DPMFoam case as it is: Debian's lagrangian/DPMFoam/Goldschmidt,
its positions file cut to its first ``--beads`` beads (its lowest layers; all 24,750 with
``--beads 0``), run ``--time`` seconds from rest by DPMFoam itself and by ``python -m pyhost run``
after ``python -m pyhost dpmfoam`` (with glass's real properties for the heat model). Printed,
for each code: the beads' mean vertical velocity, the gas's row means of fluid fraction,
interstitial and superficial vertical speed in the lowest rows of cells, and the wall time.

    .venv/bin/python tools/dpmfoam_as_is.py                      # 500 beads, 6 ms: about 30 s
    .venv/bin/python tools/dpmfoam_as_is.py --beads 0 --time 0.01

Timings are wall clock on a shared machine, one code after the other in one run.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import meshio
import numpy as np
from foamlib import FoamFile

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pyhost.engines.openfoam import run_utility  # noqa: E402

GOLDSCHMIDT = Path("/usr/share/doc/openfoam-examples/examples/lagrangian/DPMFoam/Goldschmidt")
GLASS = """youngs_modulus = 63e9
poisson_ratio = 0.23
yield_stress = 500e6
heat_capacity = 840.0
conductivity = 1.0
"""


def tutorial(dest: Path, beads: int, end: float) -> Path:
    """A copy of the tutorial with its first ``beads`` positions (0: all), ending at ``end``,
    written in ascii."""
    shutil.copytree(GOLDSCHMIDT, dest)
    gz = dest / "constant" / "kinematicCloudPositions.gz"
    positions = FoamFile(gz)[None]
    positions = positions[:beads] if beads else positions
    gz.unlink()
    body = "\n".join(f"({x!r} {y!r} {z!r})" for x, y, z in positions.tolist())
    (dest / "constant" / "kinematicCloudPositions").write_text(
        "FoamFile { version 2.0; format ascii; class vectorField; object kinematicCloudPositions; }\n"
        f"{len(positions)}\n(\n{body}\n)\n")
    control = FoamFile(dest / "system" / "controlDict")
    control["endTime"], control["writeInterval"], control["writeFormat"] = end, end, "ascii"
    return dest


def rows(folder: Path, u: str, alpha: str, shape=(90, 60)) -> list[tuple[float, float, float]]:
    """(mean fluid fraction, mean interstitial and mean superficial vertical speed [m/s]) of
    the three lowest rows of cells of the tutorial's 2 x 30 x 90 mesh."""
    U = np.asarray(FoamFile(folder / u)["internalField"], float).reshape(*shape, 3)[..., 2]
    a = np.asarray(FoamFile(folder / alpha)["internalField"], float).reshape(shape)
    return [(a[r].mean(), U[r].mean(), (a[r] * U[r]).mean()) for r in range(3)]


def import_case(case: Path, out: Path, end: float, *options: str, frames: bool = False) -> Path:
    """``python -m pyhost dpmfoam CASE OUT [options]``, then what its case.toml asks a user
    for: the beads' real material (soda-lime glass), and [time] end = ``end`` [s]; unless
    ``frames``, one output frame at the end and no pictures. RuntimeError with the command's
    words if it fails."""
    r = subprocess.run([sys.executable, "-m", "pyhost", "dpmfoam", str(case), str(out), *options], cwd=ROOT,
                       capture_output=True, text=True)
    if r.returncode:
        raise RuntimeError(f"python -m pyhost dpmfoam failed: {r.stderr.strip()}")
    toml = (out / "case.toml").read_text() + GLASS
    toml += "" if frames else f"\n[output]\nevery = {end!r}\npictures = false\n"
    (out / "case.toml").write_text(toml.replace("\n[time]\n", f"\n[time]\nend = {end!r}\n"))
    return out


def host(case: Path, out: Path, end: float) -> tuple[float, float, list]:
    import_case(case, out, end)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "pyhost", "run", str(out)], check=True, cwd=ROOT,
                   stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    frame = meshio.read(sorted((out / "output" / "vtk").glob("particles_*.vtu"))[-1])
    return frame.point_data["velocity"][:, 2].mean(), wall, rows(out / "output" / "fluid" / f"{end:g}", "U", "alpha")


def dpmfoam(case: Path, end: float) -> tuple[float, float, list]:
    run_utility(case, "blockMesh")
    t0 = time.perf_counter()
    run_utility(case, "DPMFoam")
    wall = time.perf_counter() - t0
    folder = case / f"{end:g}"
    U = np.asarray(FoamFile(folder / "lagrangian" / "kinematicCloud" / "U")[None], float)
    return U[:, 2].mean(), wall, rows(folder, "U.air", "alpha.air")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--beads", type=int, default=500, help="the first N positions of the tutorial (0: all 24,750)")
    p.add_argument("--time", type=float, default=0.006, help="simulated time [s] (default 0.006)")
    p.add_argument("--keep", action="store_true", help="keep the run folders")
    a = p.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="dpmfoam_as_is_"))
    print(f"runs in {tmp} (kept if one fails)")
    case = tutorial(tmp / "Goldschmidt", a.beads, a.time)
    theirs = dpmfoam(Path(shutil.copytree(case, tmp / "dpmfoam")), a.time)
    ours = host(case, tmp / "host", a.time)
    print(f"Goldschmidt, first {a.beads or 'all'} beads, {a.time:g} s from rest; "
          f"free fall: {-9.81 * a.time:.4f} m/s")
    for name, (vz, wall, gas) in (("DPMFoam", theirs), ("host", ours)):
        print(f"{name:8s} mean bead vz {vz:+.4f} m/s, wall {wall:.1f} s; lowest rows (alpha, U_z, alpha U_z): "
              + "; ".join(f"{r[0]:.3f} {r[1]:.3f} {r[2]:.3f}" for r in gas))
    if not a.keep:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
