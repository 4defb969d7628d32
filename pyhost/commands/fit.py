"""``python -m pyhost fit``: rebuild the fitted relations of ``plugins.heat.fit``.

Runs the exact path over a random design of materials, sizes, walls and speeds
(``plugins.heat.refit``), fits the constants with scipy, and prints them (as the Python
literal that ``plugins/heat/fit.py`` holds), the max and RMS relative errors of the fitted
and of the shipped constants, and Johnson's and Thornton's e on the same points.
"""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "rebuild the fitted relations for e, t_coll and Q (constants, errors, validity)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--n", type=int, default=800, help="collisions per model in the design")
    p.add_argument("--seed", type=int, default=2014, help="seed of the random design")
    p.add_argument("--csv", type=Path, default=None, help="write the design and both predictions here")


def run(args) -> int:
    import numpy as np

    from plugins.heat import fit as F
    from plugins.heat import refit as FR

    if args.n < 10:
        raise ValueError(f"--n must be at least 10, got {args.n}")
    hi = F.VALIDITY["v_hat"][1]
    print(f"design: {args.n} random pairs x models A, B, C by the exact path, "
          f"v0/v_y log-uniform in [1, {hi:g}], b1 in {F.VALIDITY['b1']}, b2/b1 in {F.VALIDITY['beta']}")
    data = FR.design(args.n, args.seed)
    k = FR.fit_all(data)
    print("\nfitted constants (paste into plugins/heat/fit.py):")
    print(FR.format_constants(k))
    print(f"\n{'model':>5} {'quantity':>8} {'n':>5} | {'max rel. err':>12} {'RMS':>9} | "
          f"shipped constants: {'max':>9} {'RMS':>9} | stated bound")
    new, shipped = FR.errors(data, k), FR.errors(data)
    for key in sorted(new):
        mx, rms, n = new[key]
        smx, srms, _ = shipped[key]
        print(f"{key[0]:>5} {key[1]:>8} {n:>5} | {mx:12.3g} {rms:9.3g} | "
              f"{'':>18} {smx:9.3g} {srms:9.3g} | {F.ERROR_BOUND[key]:.3g}")
    print("\nclassical e on the same (physical) points, relative error against each model:")
    for (m, name), (mx, rms) in sorted(FR.classical(data).items()):
        print(f"{m:>5} {name:>9}: max {mx:.3g}  RMS {rms:.3g}")
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        rows = []
        for m, d in data.items():
            pred = F.dimensionless(m, d["v_hat"], d["b1"], d["b2"], d["c"], k)
            for j in range(d["v_hat"].size):
                rows.append([ord(m) - ord("A"), d["v_hat"][j], d["b1"][j], d["b2"][j], d["physical"][j],
                             d["e"][j], pred["e"][j], d["t_coll"][j], pred["t_coll"][j], d["Q"][j], pred["Q"][j]])
        np.savetxt(args.csv, np.array(rows, float), delimiter=",", fmt="%.10g",
                   header="model(0=A),v_hat,b1,b2,physical,e,e_fit,t_coll_hat,t_coll_fit,Q_hat,Q_fit")
        print(f"csv: {args.csv}")
    return 0
