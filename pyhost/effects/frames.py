"""The frames: one row of history.csv and one VTK frame of the particles every output.every
seconds (for a script, by default, at the steps of its most frequent dump), and one at the end
of a completed run that did not end on one (``Coupling.finish``). The row's first columns are
the particles' (count, temperatures, heat content) and the run's totals; each other effect
adds its own columns after them (``Effect.columns``). The frame interval is this effect's
(``every["frame"]``, at each run: ``frame_every``).

Under MPI, in a run whose effects are only the balance, the collisions and the frames
(``pyhost.effects.balance.rank_effects_only``), a frame gathers no atom to rank 0 (``frame_on_rank``):
each rank writes its own piece of the VTK frame and sends rank 0 its sums (count, sum T,
min and max T, sum m c and sum m c T of each group), of which rank 0 makes the row; the
frame's .pvtu names the pieces (``pyhost.output.PieceSeries``). The row's means are then sums
over the ranks' sums: they may differ from a gathered frame's in the last digit."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pyhost.effects import Effect
from pyhost.effects.balance import rank_effects_only
from pyhost.engines.ranks import Broadcast
from pyhost.output import CsvLog, PieceSeries, VtkSeries, wait_piece, write_piece
from pyhost.tables import lookup

FRAME_EVERY = 1e-3
"""s between frames where output.every is 0 and the script has no dump (box scenes: always)."""

TOTAL_COLUMNS = ("heat_from_walls", "energy_in", "energy_out", "collisions", "capped", "clipped")
"""Totals of the run so far (summary.json's names) in every row."""


@dataclass(frozen=True)
class RankFrame:
    """What each rank needs for its part of a frame (``frame_on_rank``): the VTK folder
    (None: no VTK), the series' name and the frame's number, whether the particles have
    temperatures, the heat capacity of each material [J/(kg K)] and the material of each atom
    type, how the groups are known ("id" or "type") and their table (index into the history's
    T_group columns; -1: none), their number, and each id's entry temperature [K] (the
    ``temperature_change`` column)."""

    folder: str | None
    name: str
    number: int
    heat: bool
    capacity: np.ndarray
    type_material: np.ndarray
    known_by: str
    group: object
    groups: int
    T_first: Broadcast | None


def frame_on_rank(atoms, events, comm, spec: RankFrame) -> dict:
    """One rank's part of a frame (collective): its piece of the VTK frame written (by its
    output thread), and its sums for the history row: count, sum/min/max of T [K], and per
    group sum m c [J/K] and sum m c T [J] (the balance's C: mass times the material's heat
    capacity); the dtype and trailing shape of each VTK array (the .pvtu names them)."""
    rank = 0 if comm is None else comm.Get_rank()
    group_table = spec.group.get(comm) if isinstance(spec.group, Broadcast) else spec.group
    T_first = spec.T_first.get(comm) if spec.T_first is not None else None
    n = len(atoms.id)
    if spec.heat:
        T = atoms.T
        C = atoms.mass * spec.capacity[lookup(spec.type_material, atoms.type)]
    else:
        T, C = np.full(n, np.nan), np.ones(n)
    group = lookup(group_table, getattr(atoms, spec.known_by))
    groups = [(float(np.sum(C[g] * T[g])), float(np.sum(C[g])), bool(g.any()))
              for g in (group == k for k in range(spec.groups))]
    arrays = None
    if spec.folder is not None:
        change = T - T_first[atoms.id] if spec.heat else T
        columns = dict(id=atoms.id, type=atoms.type, radius=atoms.radius, velocity=atoms.v, temperature=T,
                       temperature_change=change)
        write_piece(spec.folder, spec.name, spec.number, rank, atoms.x, **columns)
        arrays = {k: (np.asarray(a).dtype.str, np.asarray(a).shape[1:]) for k, a in columns.items()}
    return dict(n=n, T_sum=float(T.sum()), T_min=float(T.min()) if n else math.inf,
                T_max=float(T.max()) if n else -math.inf, nan=bool(np.isnan(T).any()), groups=groups,
                CT=float(np.sum(C * T)), arrays=arrays)


def pieces_written(atoms, events, comm, folder: str, name: str) -> None:
    """This rank's pieces of the series on disk (``PieceSeries.flush``)."""
    wait_piece(folder, name)


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
        self._particles = None           # the VTK series, made once every effect is built (``particles``)
        if loop.dem.link is None:
            self.particles                  # (serially at once, as always)
        self.every = dict(frame=self.frame_every(0))

    @property
    def on_ranks(self) -> bool:
        """Whether its frames are made on each rank's own atoms (``rank_effects_only``)."""
        return rank_effects_only(self.loop)

    @property
    def particles(self):
        """The VTK series (None: no VTK): under MPI with only the balance's and the collisions'
        effects beside, written in pieces (``PieceSeries``), else one file per frame."""
        loop = self.loop
        if self._particles is None and loop.scene.output.vtk:
            mark = loop.logs.get("particles")
            self._particles = (PieceSeries(loop.out / "vtk", "particles", loop.dem.link.size, mark) if self.on_ranks
                               else VtkSeries(loop.out / "vtk", "particles", mark))
        return self._particles

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
        if self.on_ranks:
            return self.frame_on_ranks()
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

    def frame_on_ranks(self) -> None:
        """The frame with each rank's own atoms (``frame_on_rank``): no atom gathered to rank 0."""
        loop = self.loop
        heat = loop.heat
        balance = loop.find("balance")
        if heat:                        # (the balance brought up to date, new particles' temperatures set)
            balance.track_all()
        known = loop.known
        series = self.particles
        spec = RankFrame(None if series is None else str(series.folder), "particles",
                         0 if series is None else series.next_frame(), heat, loop.capacity,
                         np.asarray(loop.type_material), known.by,
                         Broadcast(known.group) if known.by == "id" else known.group, len(self.group_names),
                         Broadcast(balance.T_first_by_id) if heat and series is not None else None)
        parts = loop.dem.each_rank(frame_on_rank, spec, temperature=heat)
        n = sum(p["n"] for p in parts)
        if n == 0 or any(p["nan"] for p in parts):
            stats = (math.nan,) * 3
        else:
            stats = (sum(p["T_sum"] for p in parts) / n, min(p["T_min"] for p in parts), max(p["T_max"] for p in parts))
        means = []
        for k in range(len(self.group_names)):
            CT, C, there = (sum(p["groups"][k][c] for p in parts) for c in range(3))
            means.append(float(CT / max(C, 1e-300)) if there else math.nan)
        totals = tuple(loop.totals[k] for k in TOTAL_COLUMNS)
        self.history.write([(loop.t, loop.dem.step, n) + stats + tuple(means)
                            + (sum(p["CT"] for p in parts),) + totals])
        if series is not None:
            arrays = {k: np.empty((0,) + tuple(shape), dtype) for k, (dtype, shape) in parts[0]["arrays"].items()}
            series.add(loop.t, arrays)

    def flush(self) -> None:
        if isinstance(self.particles, PieceSeries):
            self.loop.dem.each_rank(pieces_written, str(self.particles.folder), "particles", temperature=False)
        if self.particles is not None:
            self.particles.flush()

    def state(self) -> tuple[dict, dict]:
        return dict(logs=dict(history=self.history.mark(),
                              particles=self.particles.frames if self.particles is not None else None)), {}

    def close(self) -> None:
        self.history.close()
