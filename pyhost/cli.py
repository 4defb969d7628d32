"""Command line: ``python -m pyhost <command> ...``.

Each command lives in ``pyhost/commands/<name>.py`` and exposes ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int``. Commands are registered by name in
``COMMANDS``. A command ends with one line on stderr and the exit code of
:mod:`pyhost.exitcodes` (docs/exit-codes.md): 2 for errors the user can fix (``UserError``,
``ValueError``), 3 for a failed simulation, 128 + n for signal n (:mod:`pyhost.signals`);
a traceback only with ``--debug``.
"""
from __future__ import annotations

import argparse
import importlib
import re
import sys

from pyhost.exitcodes import UserError, classify  # noqa: F401  (UserError: for the commands)
from pyhost.signals import stopping

COMMANDS = ("collide", "demo", "run", "pictures", "fluidization", "fit", "paper", "post", "compare",
            "collisions", "dpmfoam")


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and negative numbers in exponent form (-2e-3) as values."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The command line's parser; ``only``: the command given, the one whose module is imported
    (the others are listed by name: importing every command took 0.24 s of each run's start)."""
    parser = Parser(
        prog="python -m pyhost",
        description="Heat conducted between colliding particles (Kosinski et al. 2014).",
    )
    debug = dict(action="store_true", help="show the traceback of an error")
    parser.add_argument("--debug", **debug)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=Parser)
    for name in COMMANDS:
        if only is not None and name != only:
            sub.add_parser(name)
            continue
        module = importlib.import_module(f"pyhost.commands.{name}")
        p = sub.add_parser(name, help=module.HELP, description=module.HELP,
                           formatter_class=argparse.ArgumentDefaultsHelpFormatter)
        module.add_arguments(p)
        p.add_argument("--debug", default=argparse.SUPPRESS, **{**debug, "help": argparse.SUPPRESS})
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    words = [a for a in (sys.argv[1:] if argv is None else argv) if not a.startswith("-")]
    parser = build_parser(words[0] if words and words[0] in COMMANDS else None)
    args = parser.parse_args(argv)
    try:
        with stopping():
            return int(args._run(args) or 0)
    except BaseException as exc:
        if args.debug or isinstance(exc, SystemExit):
            raise
        code, message = classify(exc)
        print(f"error: {message}", file=sys.stderr)
        return code
