"""The frames: one row of history.csv and one VTK frame of the particles every output.every
seconds (for a script, by default, at the steps of its most frequent dump), and one at the end
of a completed run that did not end on one (``Coupling.finish``). The row's first columns are
the particles' (count, temperatures, heat content) and the run's totals; each other effect
adds its own columns after them (``Effect.columns``)."""
from __future__ import annotations

import math

import numpy as np

from pyhost.effects import Effect
from pyhost.output import CsvLog, VtkSeries

TOTAL_COLUMNS = ("heat_from_walls", "energy_in", "energy_out", "collisions", "capped", "clipped")
"""Totals of the run so far (summary.json's names) in every row."""


class Frames(Effect):
    """The T_group columns: the loop's ``known`` groups; ``others``: the effects whose columns
    follow, in order; ``logs``: the checkpoint's output marks to continue from (None: a new
    run)."""

    def __init__(self, loop, others, logs: dict | None = None):
        super().__init__(loop)
        logs = logs or {}
        self.group_names = list(loop.known.names)
        self.others = others
        self.columns = (("time", "step", "particles", "T_mean", "T_min", "T_max")
                        + tuple(f"T_group{k}" for k in range(len(self.group_names))) + ("sum_mcT",) + TOTAL_COLUMNS
                        + sum((e.columns for e in others), ()))
        self.history = CsvLog(loop.out / "history.csv", self.columns, logs.get("history"))
        self.particles = VtkSeries(loop.out / "vtk", "particles", logs.get("particles")) if loop.scene.output.vtk else None
        self.last_step = None           # the loop's coupled steps at the last frame

    def frame(self) -> None:
        loop = self.loop
        self.last_step = loop.steps
        heat = loop.heat
        atoms = loop.dem.atoms(heat)
        T = atoms.T if heat else np.full(len(atoms.id), np.nan)
        if heat:                        # (the balance brought up to date: its C is these atoms')
            loop.balance.track(atoms)
        C = loop.balance.C if heat else np.ones(len(atoms.id))
        group = loop.known.of(loop.known.group, atoms)
        means = tuple(float(np.sum(C[group == k] * T[group == k]) / max(np.sum(C[group == k]), 1e-300))
                      if np.any(group == k) else math.nan for k in range(len(self.group_names)))
        stats = (float(T.mean()), float(T.min()), float(T.max())) if len(T) else (math.nan,) * 3
        totals = tuple(loop.totals[k] for k in TOTAL_COLUMNS)
        self.history.write([(loop.t, loop.dem.step, len(atoms.id)) + stats + means + (float(np.sum(C * T)),) + totals
                            + sum((e.row(atoms) for e in self.others), ())])
        if self.particles is not None:
            change = T - loop.balance.T_first_by_id[atoms.id] if heat else T
            self.particles.write(loop.t, atoms.x, id=atoms.id, type=atoms.type, radius=atoms.radius,
                                 velocity=atoms.v, temperature=T, temperature_change=change)

    def flush(self) -> None:
        if self.particles is not None:
            self.particles.flush()

    def state(self) -> tuple[dict, dict]:
        return dict(logs=dict(history=self.history.mark(),
                              particles=self.particles.frames if self.particles is not None else None),
                    frame_step=self.last_step), {}

    def restore(self, state: dict) -> None:
        self.last_step = state.get("frame_step")

    def close(self) -> None:
        self.history.close()
