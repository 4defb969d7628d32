"""DPMFoam against this project on the same fluidized bed (cases/bed-25k), in one run.

What it measures: the wall time one simulated second costs each code on the bed of OpenFOAM's
DPMFoam Goldschmidt tutorial (24,750 glass beads of 2.5 mm, 15 x 150 x 450 mm, 2 x 30 x 90
cells, air at 1.875 m/s superficial), both from their initial placement (DPMFoam injects its
beads at t = 0 on the tutorial's 3 mm lattice; bed-25k places them on its own 2.625 mm
jittered lattice: cases/bed-25k/README.md lists every difference), for ``--time`` seconds
of bed time each:

- DPMFoam on a copy of Debian's tutorial (gunzipped; blockMesh first, as its Allrun does;
  endTime set to ``--time``, one write at the end): fluid step 2e-5 s, collisions
  sub-cycled inside it (``collisionResolutionSteps 12``), no heat;
- ``python -m pyhost run`` on a copy of cases/bed-25k/case.toml with ``time.end`` set to
  ``--time`` and no pictures: DEM step 5e-6 s (LIGGGHTS), fluid step 1e-4 s (collheatFoam),
  collision heat model A on the fast path.

Two figures per code: "total", the wall time of the whole command (start-up included:
DPMFoam reading the mesh and injecting, the host placing beads, starting LIGGGHTS and
the fluid solver, building the heat tables); "marching", the time-stepping alone (DPMFoam:
from the wall time its log prints its first "Time =" line to its end, the write of the end
time included; the host: its own rate printed at the end, from its first coupled step). Ratio = DPMFoam / this project, per
simulated second: above 1 means this project is faster.

Timings are ratios from one run on a shared machine (other jobs may run on the other core):
absolute times are only indicative; both codes run one after the other in this one run.

    .venv/bin/python tools/bench_dpmfoam.py                 # --time 0.01: about 5 min
    .venv/bin/python tools/bench_dpmfoam.py --time 0.02 --keep

Each code gets as many cores as ranks: serially the host's fluid takes turns with the DEM
(``[fluid] overlap = "never"``), as DPMFoam's fluid and particles do in one process; with
``--beside`` it advances beside the DEM on a second core (the default of a serial run on a
machine with one free, docs/mpi.md), which DPMFoam cannot.

``--np N`` (N > 1) runs both on N ranks: DPMFoam decomposed (method simple, N slabs along
y) under mpirun; the host as ``mpirun -np N python -m pyhost run`` (LIGGGHTS decomposed,
docs/mpi.md) with ``[fluid] ranks = N`` (collheatFoam decomposed in N slabs along y, like
DPMFoam; N <= 30, the mesh's cells in y).
"""
from __future__ import annotations

import argparse
import csv
import gzip
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pyhost.engines.openfoam import foam_env  # noqa: E402

TUTORIAL = Path("/usr/share/doc/openfoam-examples/examples/lagrangian/DPMFoam/Goldschmidt")
CASE = ROOT / "cases" / "bed-25k"
DPMFOAM_STEP = 2e-5           # s, the tutorial's deltaT


def copy_tutorial(dest: Path) -> Path:
    """A copy of the tutorial with every gzipped file unpacked (Debian gzips them)."""
    shutil.copytree(TUTORIAL, dest)
    for gz in dest.rglob("*.gz"):
        gz.with_suffix("").write_bytes(gzip.decompress(gz.read_bytes()))
        gz.unlink()
    return dest


def set_entry(path: Path, key: str, value: str) -> None:
    """Set one top-level ``key value;`` entry of an OpenFOAM dictionary."""
    text, n = re.subn(rf"^{key}\s+[^;]*;", f"{key} {value};", path.read_text(), count=1, flags=re.M)
    if n != 1:
        raise SystemExit(f"{path}: no entry '{key}' to set")
    path.write_text(text)


def mpirun(np: int) -> list[str]:
    return ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(np)] if np > 1 else []


def run_logged(cmd: list[str], cwd: Path, log: Path, env=None, mark: str | None = None) -> tuple[float, list]:
    """Run ``cmd`` in ``cwd`` with output to ``log``; its wall time [s] and the wall times
    (from its start) of the lines that begin with ``mark``. Exits on failure."""
    t0 = time.perf_counter()
    marks = []
    with open(log, "w") as out:
        proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env, text=True)
        for line in proc.stdout:
            if mark is not None and line.startswith(mark):
                marks.append(time.perf_counter() - t0)
            out.write(line)
        rc = proc.wait()
    wall = time.perf_counter() - t0
    if rc != 0:
        tail = "\n".join(log.read_text(errors="replace").splitlines()[-20:])
        raise SystemExit(f"{' '.join(cmd)} failed (exit code {rc}) in {cwd}; end of {log}:\n{tail}")
    return wall, marks


def dpmfoam(case: Path, end: float, np: int) -> dict:
    """DPMFoam on the tutorial copy for ``end`` seconds: wall times and parcel count."""
    env = foam_env()
    control = case / "system" / "controlDict"
    set_entry(control, "endTime", repr(end))
    set_entry(control, "writeInterval", repr(end))
    run_logged(["blockMesh", "-case", str(case)], case, case / "log.blockMesh", env)
    if np > 1:
        decompose = case / "system" / "decomposeParDict"
        set_entry(decompose, "numberOfSubdomains", str(np))
        decompose.write_text(re.sub(r"n\s+\([^)]*\);", f"n (1 {np} 1);", decompose.read_text()))
        run_logged(["decomposePar", "-case", str(case)], case, case / "log.decomposePar", env)
    log = case / "log.DPMFoam"
    wall, marks = run_logged([*mpirun(np), "DPMFoam", "-case", str(case), *(["-parallel"] if np > 1 else [])],
                             case, log, env, mark="Time = ")
    steps = len(marks)              # a step starts at its "Time = " line; the run ends at the process's end
    if steps < 3:
        raise SystemExit(f"{log}: only {steps} time steps logged")
    parcels = re.findall(r"Current number of parcels\s*=\s*(\d+)", log.read_text(errors="replace"))
    return dict(total=wall, march=(wall - marks[0]) / (steps * DPMFOAM_STEP), steps=steps,
                particles=int(parcels[-1]) if parcels else None)


def host(folder: Path, end: float, np: int, beside: bool = False) -> dict:
    """``python -m pyhost run`` on a copy of bed-25k running ``end`` seconds (serially on one
    core at a time, unless ``beside``)."""
    case = folder / "case"
    case.mkdir(parents=True)
    text = (CASE / "case.toml").read_text()
    for key in ("end", "test_end"):          # test_end may not exceed end: not used here
        text, n = re.subn(rf"^{key} = [^\n#]*", f"{key} = {end!r} ", text, count=1, flags=re.M)
        if n != 1:
            raise SystemExit(f"{CASE / 'case.toml'}: no '{key} =' line in [time]")
    if np > 1:
        text = text.replace("\n[fluid]\n", f"\n[fluid]\nranks = {np}\n", 1)
    elif not beside:
        text = text.replace("\n[fluid]\n", '\n[fluid]\noverlap = "never"\n', 1)
    (case / "case.toml").write_text(text + "pictures = false\n")     # [output] is the last table
    log = folder / "log.run"
    wall, _ = run_logged([*mpirun(np), sys.executable, "-m", "pyhost", "run", str(case), "--out", str(folder / "output")],
                      ROOT, log)
    rates = re.findall(r"([0-9.eE+-]+) s simulated per s", log.read_text())
    summary = json.loads((folder / "output" / "summary.json").read_text())
    with open(folder / "output" / "history.csv") as f:
        last = list(csv.DictReader(f))[-1]
    return dict(total=wall, march=1.0 / float(rates[-1]), collisions=summary["collisions"],
                particles=int(last["particles"]))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--time", type=float, default=0.01, help="simulated time of each run [s] (default 0.01)")
    p.add_argument("--np", type=int, default=1, help="MPI ranks of each code (default 1)")
    p.add_argument("--keep", action="store_true", help="keep the run folders (printed)")
    p.add_argument("--beside", action="store_true",
                   help="serially, the host's fluid beside its DEM on a second core (default: one core, taking turns)")
    a = p.parse_args(argv)
    if a.time < 5 * DPMFOAM_STEP:
        p.error(f"--time must be at least {5 * DPMFOAM_STEP:g} s (5 DPMFoam steps)")
    if not 1 <= a.np <= 30:
        p.error("--np must be 1 to 30: collheatFoam cuts bed-25k's mesh into slabs along y, which has 30 cells")
    tmp = Path(tempfile.mkdtemp(prefix="bench_dpmfoam_"))
    try:
        t0 = time.perf_counter()
        ours = host(tmp / "bed-25k", a.time, a.np, a.beside)
        theirs = dpmfoam(copy_tutorial(tmp / "Goldschmidt"), a.time, a.np)
        print(f"bed of the Goldschmidt tutorial, {a.time:g} s of bed time from the initial placement, "
              f"{a.np} rank(s){', the fluid beside the DEM' if a.beside and a.np == 1 else ''}; one run on a shared machine ({time.perf_counter() - t0:.0f} s)")
        print(f"DPMFoam: {theirs['particles']} parcels, {theirs['steps']} steps of {DPMFOAM_STEP:g} s; "
              f"bed-25k: {ours['particles']} particles, {ours['collisions']} collisions (heat A, fast)")
        print(f"{'':10s} {'total wall [s]':>15s} {'wall s / sim s':>15s} {'marching wall s / sim s':>24s}")
        for name, r in (("DPMFoam", theirs), ("bed-25k", ours)):
            print(f"{name:10s} {r['total']:15.1f} {r['total'] / a.time:15.0f} {r['march']:24.0f}")
        print(f"{'ratio':10s} {'':15s} {theirs['total'] / ours['total']:15.2f} {theirs['march'] / ours['march']:24.2f}"
              "   (DPMFoam / bed-25k)")
    finally:
        if a.keep:
            print(f"runs kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
