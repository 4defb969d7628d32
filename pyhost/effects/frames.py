"""The frames: one row of history.csv and one VTK frame of the particles every output.every
seconds (for a script, by default, at the steps of its most frequent dump), and one at the end
of a completed run that did not end on one (``Coupling.finish``). The row's first columns are
the particles' (count, temperatures, heat content) and the run's totals; each other effect
adds its own columns after them (``Effect.columns``). The frame interval is this effect's
(``every["frame"]``, at each run: ``frame_every``)."""
from __future__ import annotations

import math

import numpy as np

from pyhost.effects import Effect
from pyhost.output import CsvLog, VtkSeries

FRAME_EVERY = 1e-3
"""s between frames where output.every is 0 and the script has no dump (box scenes: always)."""

TOTAL_COLUMNS = ("heat_from_walls", "energy_in", "energy_out", "collisions", "capped", "clipped")
"""Totals of the run so far (summary.json's names) in every row."""


class Frames(Effect):
    """The T_group columns: the loop's ``known`` groups; ``others``: the effects whose columns
    follow, in order (those built before it: the registry has it last); the checkpoint's
    output marks to continue from: ``loop.logs``."""

    def __init__(self, loop):
        super().__init__(loop)
        logs = loop.logs
        self.group_names = list(loop.known.names)
        self.others = list(loop.present)
        self.columns = (("time", "step", "particles", "T_mean", "T_min", "T_max")
                        + tuple(f"T_group{k}" for k in range(len(self.group_names))) + ("sum_mcT",) + TOTAL_COLUMNS
                        + sum((e.columns for e in self.others), ()))
        self.history = CsvLog(loop.out / "history.csv", self.columns, logs.get("history"))
        self.particles = VtkSeries(loop.out / "vtk", "particles", logs.get("particles")) if loop.scene.output.vtk else None
        self.every = dict(frame=self.frame_every(0))

    def before_run(self, resumed: bool) -> None:
        self.every = dict(frame=self.frame_every(self.every["frame"]))   # (a script's dumps and time step now)

    def frame_every(self, before: int) -> int:
        """DEM steps between frames: output.every, or where it is 0 the interval of the
        script's most frequent dump as defined now (frames at the steps of its dumps), else
        FRAME_EVERY seconds. A script's run says it when it differs from ``before``."""
        loop = self.loop
        every = loop.scene.output.every
        dumps = loop.dem.dump_every() if every == 0 and loop.scene.scripted else 0
        n = dumps or max(1, round((every or FRAME_EVERY) / loop.dem.dt))
        if loop.scene.scripted and n != before:
            source = ("output.every" if every else "the script's most frequent dump" if dumps
                      else "the default: no dump in the script")
            print(f"frames and history rows every {n} steps ({n * loop.dem.dt:.4g} s; {source})")
        return n

    def frame(self) -> None:
        loop = self.loop
        heat = loop.heat
        balance = loop.find("balance")
        atoms = loop.dem.atoms(heat)
        T = atoms.T if heat else np.full(len(atoms.id), np.nan)
        if heat:                        # (the balance brought up to date: its C is these atoms')
            balance.track(atoms)
        C = balance.C if heat else np.ones(len(atoms.id))
        group = loop.known.of(loop.known.group, atoms)
        means = tuple(float(np.sum(C[group == k] * T[group == k]) / max(np.sum(C[group == k]), 1e-300))
                      if np.any(group == k) else math.nan for k in range(len(self.group_names)))
        stats = (float(T.mean()), float(T.min()), float(T.max())) if len(T) else (math.nan,) * 3
        totals = tuple(loop.totals[k] for k in TOTAL_COLUMNS)
        self.history.write([(loop.t, loop.dem.step, len(atoms.id)) + stats + means + (float(np.sum(C * T)),) + totals
                            + sum((e.row(atoms) for e in self.others), ())])
        if self.particles is not None:
            change = T - balance.T_first_by_id[atoms.id] if heat else T
            self.particles.write(loop.t, atoms.x, id=atoms.id, type=atoms.type, radius=atoms.radius,
                                 velocity=atoms.v, temperature=T, temperature_change=change)

    def flush(self) -> None:
        if self.particles is not None:
            self.particles.flush()

    def state(self) -> tuple[dict, dict]:
        return dict(logs=dict(history=self.history.mark(),
                              particles=self.particles.frames if self.particles is not None else None)), {}

    def close(self) -> None:
        self.history.close()
