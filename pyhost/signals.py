"""Interrupts: SIGINT, SIGTERM and SIGHUP all stop a command the same clean way.

Inside ``stopping()`` each of them raises :class:`Interrupted` in the main thread, which
unwinds like any error: the coupling loop writes summary.json with where and why it stopped,
the engines are closed, the fluid solver (in its own session, see pyhost.engines.openfoam) is ended,
and the command exits with 128 + the signal's number (130, 143, 129). A second signal during
that clean-up is ignored, so the clean-up is not cut short.
"""
from __future__ import annotations

import contextlib
import signal

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Interrupted(BaseException):
    """A stop asked for by a signal. A BaseException, as KeyboardInterrupt: no ``except
    Exception`` of the code it passes through takes it for an error to handle."""

    def __init__(self, signum: int):
        self.signum = signum
        super().__init__(f"{signal.Signals(signum).name} received")

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


_received: list[int] = []
_deferred: list[bool] = [False]


def check() -> None:
    """Raise :class:`Interrupted` again if a signal came: an exception raised by a handler can
    be swallowed where Python ignores exceptions (e.g. in os.fork's after-fork hooks), so the
    coupling loop asks once per chunk."""
    if _received:
        raise Interrupted(_received[0])


@contextlib.contextmanager
def deferred(on: bool = True):
    """Inside, a first signal is only noted and raised at the next :func:`check` (or at the
    end): the coupling loop stops at the end of a step, where its state is consistent and a
    checkpoint can be written (pyhost.checkpoint)."""
    before = _deferred[0]
    _deferred[0] = on or before          # inside a deferring block, deferral stays
    try:
        yield
    finally:
        _deferred[0] = before
    check()


@contextlib.contextmanager
def stopping():
    """Turn the first of SIGINT, SIGTERM, SIGHUP into :class:`Interrupted`; ignore the rest."""
    first = _received

    def handler(signum, frame):
        if not first:
            first.append(signum)
            if not _deferred[0]:
                raise Interrupted(signum)

    old = {s: signal.signal(s, handler) for s in SIGNALS}
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        first.clear()
        _deferred[0] = False
