"""The loop's effects: each thing the coupled run does for a scene, with what it owns.

``pyhost.loop.Coupling`` runs the DEM in chunks and hands the particles to a list of effects,
built from what the scene asks for (``Scene.effects_summary``): no fluid exchange for a dry
scene, no collision heat for an isothermal one. An effect owns its history.csv columns
(``columns`` and ``row``), the run's totals it adds to (``TOTALS``, their starting values; the
loop keeps every effect's in one dict, ``loop.totals``, written to summary.json), its part of
a checkpoint (``state`` and ``restore``) and its files. A new output column is one line of one
effect's ``columns`` and ``row``, a new total one entry of its ``TOTALS``; a new effect is one
module here and one line in ``Coupling`` (two if it has totals: ``pyhost.loop.totals``).

Hooks, called by the loop on every effect in the list's order (the defaults do nothing):

    start()        once, before the first frame
    couple()       every coupling interval (time.couple_every DEM steps)
    row(atoms)     its history values at a frame, in the order of ``columns``
    frame()        its files at a frame
    state()        (JSON values, arrays) for a checkpoint; restore(state) takes them back
    flush()        its files whole on disk and its totals up to date (a checkpoint, the end)
    finish(summary, status)   its part of summary.json; an invariant found broken at the end
                   of a completed run goes in ``failure`` (the run then fails, exit 3, after
                   its summary is written and its files closed)
    close()        its files closed (after the summary)
"""
from __future__ import annotations

import numpy as np


class Effect:
    """One thing the loop does; ``loop`` is the ``pyhost.loop.Coupling`` that runs it."""

    columns: tuple = ()
    TOTALS: dict = {}                 # the summary's totals it adds to, with their values at the start
    failure: str | None = None        # what its finish found broken (a completed run only)

    def __init__(self, loop):
        self.loop = loop

    def start(self) -> None:
        pass

    def couple(self) -> None:
        pass

    def row(self, atoms) -> tuple:
        return ()

    def frame(self) -> None:
        pass

    def state(self) -> tuple[dict, dict]:
        return {}, {}

    def restore(self, state: dict) -> None:
        pass

    def flush(self) -> None:
        pass

    def finish(self, summary: dict, status: str) -> None:
        pass

    def close(self) -> None:
        pass


def by_id(ids, values, wanted, missing=None):
    """``values`` (aligned with the atom ids ``ids``) for the ids ``wanted``, in their order;
    an id not among ``ids`` gets ``missing`` (None: every one must be there)."""
    ids = np.asarray(ids)
    order = np.argsort(ids, kind="stable")
    at = np.minimum(np.searchsorted(ids, wanted, sorter=order), max(len(ids) - 1, 0))
    rows = order[at]
    if missing is None:
        return np.asarray(values)[rows]
    found = ids[rows] == wanted
    return np.where(found, np.asarray(values)[rows], missing)
