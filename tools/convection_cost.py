"""Measures the cost of gas-particle convection: cases/hot-cold-gas-bed (1200 beads, collision
heat model A) run once with its convection (Gunn: gas energy equation + exchange every
coupling) and once with ``[effects] convection = "none"`` (no energy equation, nothing extra
through the pipes), for the same simulated time, and the ratio of their wall times, and of their CPU times
(host, LIGGGHTS and solver: less disturbed by other work on the machine). One run each, VTK
and pictures off: the machine's noise is in the figures.

Run: .venv/bin/python tools/convection_cost.py [--end 0.05]
"""
from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import tomli_w

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "hot-cold-gas-bed" / "case.toml"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--end", type=float, default=0.05, help="simulated time of each run [s]")
    args = p.parse_args()
    times, cpu = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for convection in ("none", tomllib.loads(CASE.read_text())["effects"]["convection"]):
            data = tomllib.loads(CASE.read_text())
            data["effects"]["convection"] = convection
            data["time"]["end"] = args.end
            data["output"] = dict(every=args.end, vtk=False, pictures=False)
            folder = Path(tmp) / convection
            folder.mkdir()
            (folder / "case.toml").write_text(tomli_w.dumps(data))
            start, used = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
            r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder)], cwd=ROOT,
                               capture_output=True, text=True)
            times[convection] = time.perf_counter() - start
            now = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu[convection] = now.ru_utime + now.ru_stime - used.ru_utime - used.ru_stime
            if r.returncode != 0:
                print(r.stdout[-2000:], r.stderr[-2000:])
                return 1
            print(f"convection = {convection!r}: {times[convection]:.2f} s wall time, {cpu[convection]:.2f} s CPU "
                  f"for {args.end:g} s simulated")
    on = [k for k in times if k != "none"][0]
    print(f"cost of convection: {times[on] / times['none']:.3f} x the wall time and "
          f"{cpu[on] / cpu['none']:.3f} x the CPU time of the run without it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
