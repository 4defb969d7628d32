"""Compare OUT/probes.csv of cases/heated-packed-bed with Beaulieu's experiment (reference/):
for each depth, the probe's temperature [C] at each experimental point after 900 s of heating
(the heating starts at the frozen stage, summary.json's frozen_stage.start), linearly
interpolated between the probe rows (every 10 s), and the largest |ours - experiment| [K].

    .venv/bin/python cases/heated-packed-bed/compare.py OUT [--after 900] [--tolerance 1.5]

Prints one line per depth; exit 1 when a depth misses the tolerance."""
from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
DEPTHS = {"T_40mm": "0.040", "T_60mm": "0.060", "T_73mm": "0.073"}


def compare(out: Path, after: float = 900.0) -> dict:
    """{probe: (max |error| [K], mean error [K], number of points)} after ``after`` s."""
    start = json.loads((out / "summary.json").read_text())["frozen_stage"]["start"]
    rows = list(csv.DictReader(open(out / "probes.csv")))
    t = np.array([float(r["time"]) for r in rows]) - start
    result = {}
    for probe, depth in DEPTHS.items():
        ours = np.array([float(r[probe]) for r in rows]) - 273.15
        ref = np.loadtxt(HERE / "reference" / f"steel_Beaulieu_{depth}_experiment.csv", delimiter=",", skiprows=1)
        keep = ref[:, 0] > after
        at = np.interp(ref[keep, 0], t[t >= 0], ours[t >= 0])
        err = at - ref[keep, 1]
        result[probe] = (float(np.abs(err).max()), float(err.mean()), int(keep.sum()))
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--after", type=float, default=900.0, help="s of heating before the comparison starts")
    ap.add_argument("--tolerance", type=float, default=1.5, help="K")
    args = ap.parse_args(argv)
    ok = True
    for probe, (worst, mean, n) in compare(args.out, args.after).items():
        ok &= worst <= args.tolerance
        print(f"{probe}: max |T - experiment| {worst:.2f} K, mean T - experiment {mean:+.2f} K over {n} points "
              f"after {args.after:g} s ({'within' if worst <= args.tolerance else 'MISSES'} {args.tolerance:g} K)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
