"""``python -m pyhost fluidization OUT``: a fluid run's pressure drop against Ergun and its
minimum fluidization velocity against Wen-Yu (pyhost/fluidization.py)."""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "fluidization curve of a run with a stepped fluid.inlet_table: Ergun and Wen-Yu"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", type=Path, help="output folder of a run (scene.json, history.csv)")
    p.add_argument("--no-plot", action="store_true", help="skip fluidization.png")


def run(args) -> int:
    from pyhost.fluidization import measure, plot, report

    curve = measure(args.out)
    print(report(curve, args.out))
    if not args.no_plot:
        print("picture:", plot(curve, args.out))
    return 0
