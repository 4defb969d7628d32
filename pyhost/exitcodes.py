"""Exit codes of ``python -m pyhost`` (docs/exit-codes.md) and the one-line message of each
way a command can end. Tracebacks are for ``--debug`` only."""
from __future__ import annotations

import os

from pyhost.signals import Interrupted

DONE = 0
INTERNAL = 1            # a bug of ours: the message asks for --debug and a report
BAD_INPUT = 2           # the scene, an argument, a file or folder given: named in the message
FAILED = 3              # the simulation ran and failed: diverged, particle lost, solver died


class UserError(Exception):
    """A problem with the user's input: printed as one line, exit status 2 (also importable
    from pyhost.cli, where commands take it)."""


class SimulationFailed(RuntimeError):
    """A run that started from valid input and failed (exit code 3)."""


def classify(exc: BaseException) -> tuple[int, str]:
    """Exit code and message for an exception that ended a command."""
    from pyhost.engines.openfoam import FluidError

    if isinstance(exc, Interrupted):
        return exc.exit_code, (f"interrupted: {exc}; stopped cleanly (a run that had begun says where in its "
                               "summary.json)")
    if isinstance(exc, KeyboardInterrupt):
        return 130, "interrupted"
    if isinstance(exc, (SimulationFailed, FluidError)):
        return FAILED, f"simulation failed: {type(exc).__name__}: {exc}"
    if isinstance(exc, (UserError, ValueError)):
        return BAD_INPUT, str(exc)
    if isinstance(exc, UnicodeDecodeError):
        return BAD_INPUT, f"not UTF-8 text: {exc}"
    if isinstance(exc, OSError):
        where = " -> ".join(str(f) for f in (exc.filename, exc.filename2) if f is not None)
        return BAD_INPUT, f"{where or 'a file'}: {exc.strerror or os.strerror(exc.errno or 0) or exc}"
    if isinstance(exc, RuntimeError) and type(exc).__module__.startswith("pyhost."):   # e.g. LiggghtsError
        return BAD_INPUT, f"{type(exc).__name__}: {exc}"
    return INTERNAL, (f"internal error: {type(exc).__name__}: {exc} (run `python -m pyhost --debug ...` "
                      f"for the traceback and report it)")
