"""``python -m pyhost bench accuracy``: error against cost of every evaluation path
(tools/bench_accuracy.py): a table on stdout, docs/accuracy-cost.csv and .png."""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "benchmarks: 'accuracy' = error against cost of exact, fast, closed-form and fitted paths"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("which", choices=("accuracy",), help="which benchmark")
    p.add_argument("--out", type=Path, default=Path("docs"), help="folder for the CSV and the PNG")
    p.add_argument("--repeats", type=int, default=5, help="timings per path (spread reported)")
    p.add_argument("--n", type=int, default=40, help="speeds per model in the fixed set of collisions")


def run(args) -> int:
    from pyhost.commands.fit import load_tool

    if args.repeats < 1 or args.n < 2:
        raise ValueError("--repeats must be >= 1 and --n >= 2")
    load_tool("bench_accuracy").run(args.out, args.repeats, args.n)
    return 0
