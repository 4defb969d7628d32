"""Command line: ``python -m pyhost <command> ...``.

Each command lives in ``pyhost/commands/<name>.py`` and exposes ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int``. Commands are registered by name in
``COMMANDS``; errors the user can fix (``UserError``, ``ValueError``) print one line and exit 2.
"""
from __future__ import annotations

import argparse
import importlib
import re
import sys

COMMANDS = ("collide", "demo", "run", "pictures", "fluidization", "fit", "paper", "bench", "compare")


class UserError(Exception):
    """A problem with the user's input: printed as one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and negative numbers in exponent form (-2e-3) as values."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="python -m pyhost",
        description="Heat conducted between colliding particles (Kosinski et al. 2014).",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=Parser)
    for name in COMMANDS:
        module = importlib.import_module(f"pyhost.commands.{name}")
        p = sub.add_parser(name, help=module.HELP, description=module.HELP,
                           formatter_class=argparse.ArgumentDefaultsHelpFormatter)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except (UserError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except RuntimeError as exc:
        if not type(exc).__module__.startswith("pyhost."):      # an engine's error, e.g. LiggghtsError
            raise
        print(f"error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 2
