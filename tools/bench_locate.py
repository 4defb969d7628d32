#!/usr/bin/env python3
"""What collheatFoam's LOCATE costs on bed-25k's mesh (2 x 30 x 90 cells, 15 x 150 x 450 mm):
24,750 points in the box, in the order of their height, located four times: a first request
(no guess of any point's cell yet), the same points again (each point's cell of the request
before is its guess), one point more (as after an insertion: the count changed) and that
again. Prints the four wall times [ms] of each request, host to solver and back.

    .venv/bin/python tools/bench_locate.py [--repeat 2]
    COLLHEAT_SOLVER=OTHER/collheatFoam .venv/bin/python tools/bench_locate.py    # another build

The machine is shared: compare builds alternately, in one run.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pyhost.engines.fluid_case import box_case  # noqa: E402
from pyhost.engines.openfoam import SOLVER, FluidSolver  # noqa: E402

LO, HI, CELLS, N = (-0.0075, -0.075, 0.0), (0.0075, 0.075, 0.45), (2, 30, 90), 24750


def once(rng) -> list[float]:
    x = rng.uniform(np.add(LO, 1e-4), np.subtract(HI, 1e-4), (N, 3))
    x = x[np.argsort(x[:, 2])]
    with tempfile.TemporaryDirectory() as d:
        case = box_case(Path(d) / "case", lo=LO, hi=HI, cells=CELLS, rho=1.2, nu=1e-5, dt=1e-4,
                        boundaries={f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")})
        with FluidSolver(case) as fluid:
            times = []
            for points in (x, x, np.r_[x, x[:1]], np.r_[x, x[:1]]):
                start = time.perf_counter()
                fluid.locate(points)
                times.append(time.perf_counter() - start)
    return times


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(1)
    print(f"solver {SOLVER}")
    print("   first    again  one more   again   [ms]")
    for _ in range(args.repeat):
        print("".join(f"{t * 1e3:8.1f} " for t in once(rng)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
