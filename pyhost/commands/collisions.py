"""``python -m pyhost collisions OUT [--csv]``: a run's collision log: how many rows and
columns, and with ``--csv`` the CSV form (OUT/collisions.csv, or the file given) of a log
written in binary columns (``output.collisions = "binary"``), byte for byte the file the run
would have written with ``output.collisions = "csv"``."""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "a run's collision log: rows and columns; --csv writes collisions.csv from the binary form"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", type=Path, help="output folder of a run (holds collisions/ or collisions.csv)")
    p.add_argument("--csv", nargs="?", type=Path, const=True, default=None, metavar="FILE",
                   help="write the CSV form of the binary log (default FILE: OUT/collisions.csv)")


def run(args) -> int:
    from pyhost.cli import UserError
    from pyhost.output import SCHEMA, collisions_to_csv, read_collisions

    binary = (args.out / "collisions" / SCHEMA).is_file()
    if args.csv is not None:
        if not binary:
            raise UserError(f"{args.out}: no binary collision log ({args.out / 'collisions' / SCHEMA}); "
                            "the run wrote collisions.csv itself" if (args.out / "collisions.csv").is_file()
                            else f"{args.out}: no collision log: not the output folder of a run with collisions")
        try:
            path = collisions_to_csv(args.out, None if args.csv is True else args.csv)
        except ValueError as exc:
            raise UserError(str(exc)) from None
        print(f"wrote {path}")
        return 0
    try:
        cols = read_collisions(args.out)
    except FileNotFoundError as exc:
        raise UserError(str(exc)) from None
    except ValueError as exc:
        raise UserError(str(exc)) from None
    n = len(next(iter(cols.values()))) if cols else 0
    print(f"{args.out}: {n} collisions ({'binary columns' if binary else 'collisions.csv'}), "
          f"columns: {', '.join(cols)}")
    return 0
