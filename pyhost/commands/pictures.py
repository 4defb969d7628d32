"""``python -m pyhost pictures OUT``: pictures of a finished (or interrupted) run's output.

A separate process on purpose: Debian's libliggghts loads Debian's VTK 9.1, which clashes
with the VTK that pyvista brings (a segfault when both are in one process).
"""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "draw a run's pictures: temperatures.png and particles.png in its output folder"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", type=Path, help="output folder of a run (holds history.csv, vtk/)")


def run(args) -> int:
    from pyhost.cli import UserError
    from pyhost.pictures import plot_history, render_particles

    if not (args.out / "history.csv").exists():
        raise UserError(f"{args.out}: no history.csv: not the output folder of a run")
    made = [plot_history(args.out)]
    if (args.out / "vtk" / "particles.pvd").exists():
        made.append(render_particles(args.out))
    print("pictures:", *made)
    return 0


if __name__ == "__main__":      # what `run` starts: the same, without building every command's parser
    import sys
    from pyhost.cli import UserError
    try:
        sys.exit(run(argparse.Namespace(out=Path(sys.argv[1]))))
    except UserError as exc:
        sys.exit(f"error: {exc}")
