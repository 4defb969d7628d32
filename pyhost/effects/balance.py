"""Particle temperatures and their energy balance: inserted particles get their material's
temperature and bring their heat content in, departed ones take theirs out, a script's own
changes (``set ... Temp``, a changed mass) are counted as such, and at the end the residual of
sum(m c T) against all that came in and went out is summary.json's energy_balance_error.
Present when the scene's particles have temperatures (``particle_temperatures``). SI units.

The balance holds to round-off by construction (every change of a temperature the host does
not make itself is counted as one of its terms), so a completed run whose residual exceeds
TOLERANCE of all that came in fails (exit 3) after writing its results: something changed
temperatures that the host did not count, and the heat it reports cannot be trusted.

Under MPI, in a run whose only effects are the balance, the collisions and the frames (a dry
box with collision heat, no fix heat/gran: ``on_ranks``), no rank sends all its atoms to rank
0: each rank compares its own atoms with the balance's per-id tables (sent to every rank by
MPI's ``Bcast``), gives its new particles their starting temperature itself and sends rank 0
only what changed (new atoms, changed heat contents or masses) and its sums; which particles
departed comes from the bitwise OR of the ranks' bitmaps of the ids present (``track_on_rank``).
The per-id tables themselves (4 numbers per particle id) stay on rank 0.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pyhost.effects import Effect, by_id
from pyhost.engines.liggghts.script import ScriptError
from pyhost.engines.ranks import Broadcast, sum_bits
from pyhost.tables import lookup

RANK_EFFECTS = {"balance", "collisions", "frames"}
"""The effects with which, under MPI, the balance and the frames work on each rank's own atoms
(``on_ranks``); any other (a fluid, conduction, probes) reads gathered atoms and their ``C``."""


def on_ranks(loop) -> bool:
    """Whether, under MPI, the balance and the frames work on each rank's own atoms: the run's
    effects are only RANK_EFFECTS and no fix heat/gran's flux is followed (its histories are
    rank 0's)."""
    dem = loop.dem
    return rank_effects_only(loop) and not (dem.events is not None and dem.events.window)


def rank_effects_only(loop) -> bool:
    """Whether the run is under MPI and its effects are only RANK_EFFECTS (once all are built)."""
    return loop.dem.link is not None and len(loop.present) == sum(loop.find(n) is not None for n in RANK_EFFECTS)


def cold_message(where, i, t, name: str, T: float) -> str:
    """A particle starting at or below 0 K (``track``, ``track_on_rank``)."""
    return (f"{where}: particle {i} (type {t}, materials.{name}) starts at {T:g} K: temperatures must be above 0 K; "
            f"give materials.{name}.temperature, or the script's fix heat/gran initial_temperature")


def density_message(where, i, t, name: str, rho: float, want: float) -> str:
    """A script's particle whose density is not its material's (``check_densities``)."""
    return (f"{where}: particle {i} (type {t}) has the script's density {rho:.6g} kg/m^3, "
            f"materials.{name}.density is {want:g}: give both the same value")


@dataclass(frozen=True)
class RankTrack:
    """What each rank needs to bring the balance up to date with its own atoms
    (``track_on_rank``): the heat capacity of each material [J/(kg K)], the material of each
    atom type (-1: none), each material's density [kg/m^3] (a script's particles are checked
    against it; None: not checked), how the starting temperatures are known ("id" or "type")
    and their table [K] (NaN: keep LIGGGHTS' value), the balance's tables by id (seen as 0/1,
    mass [kg] and m c T [J] when last seen), and whether a script's changes since the last run
    are counted (``resync``)."""

    capacity: np.ndarray
    type_material: np.ndarray
    density: np.ndarray | None
    known_by: str
    known_T: object
    seen: Broadcast
    mass: Broadcast
    CT: Broadcast
    resync: bool = False


def track_on_rank(atoms, events, comm, spec: RankTrack) -> dict:
    """One rank's part of ``EnergyBalance.track_ranks`` (collective): its new atoms given their
    starting temperature (in LIGGGHTS' Temp), and for rank 0 the ids, heat contents [J], masses
    [kg] and entry temperatures [K] of its new atoms and of those whose heat content or mass
    changed since the balance saw them, the sums of the terms, and the first problem found
    (a type without material, a particle at or below 0 K, a density other than the
    material's) instead of an exception (a follower must stay in step)."""
    seen, M_by, CT_by = spec.seen.get(comm).astype(bool), spec.mass.get(comm), spec.CT.get(comm)
    known_T = spec.known_T.get(comm) if isinstance(spec.known_T, Broadcast) else spec.known_T
    ids, T, mass, types = atoms.id, atoms.T, atoms.mass, atoms.type
    table = spec.type_material
    mat = np.where(types < len(table), lookup(table, types), -1)
    bits = np.zeros(len(seen), bool)
    inside = ids < len(seen)
    bits[ids[inside]] = True
    present = sum_bits(comm, np.packbits(bits))        # (collective: before any early return)
    out = dict(present=present, problem=None)
    if (mat < 0).any():
        out["problem"] = ("material", sorted(set(types[mat < 0].tolist())))
        return out
    old = np.zeros(len(ids), bool)
    old[inside] = seen[ids[inside]]
    new = ~old
    if spec.resync and old.any():         # a script's changes since the last run, at the masses last seen
        o = ids[old]
        m = np.where(M_by[o] > 0, M_by[o], mass[old])
        out["set_by_script"] = float(np.sum(m * spec.capacity[mat[old]] * T[old] - CT_by[o]))
    C = mass * spec.capacity[mat]
    T_entry = T[new].copy()
    if new.any():
        key = ids if spec.known_by == "id" else types
        T_set = lookup(known_T, key[new])
        T[new] += np.where(np.isnan(T_set), 0.0, T_set - T_entry)
        T_entry = np.where(np.isnan(T_set), T_entry, T_set)
        cold = np.flatnonzero(~(T[new] > 0))
        if len(cold):
            k = np.flatnonzero(new)[cold[0]]
            out["problem"] = ("cold", int(ids[k]), int(types[k]), int(mat[k]), float(T[k]))
            return out
        if spec.density is not None:
            rho = mass[new] / (4.0 / 3.0 * np.pi * atoms.radius[new] ** 3)
            want = spec.density[mat[new]]
            bad = np.flatnonzero(np.abs(rho / want - 1.0) > 1e-6)
            if len(bad):
                k = np.flatnonzero(new)[bad[0]]
                out["problem"] = ("density", int(ids[k]), int(types[k]), int(mat[k]), float(rho[bad[0]]),
                                  float(want[bad[0]]))
                return out
    out.update(new_ids=ids[new], new_T_entry=T_entry, new_CT=C[new] * T[new], new_mass=mass[new].copy(),
               energy_in=float(np.sum(C[new] * T_entry)))
    M_last = np.zeros(len(ids))
    M_last[inside] = M_by[ids[inside]]
    kept = old & (M_last > 0)
    o = ids[kept]
    dm = mass[kept] - M_by[o]
    out["mass_change"] = float(np.sum(spec.capacity[mat[kept]] * dm * T[kept])) if dm.any() else 0.0
    changed = (C[kept] * T[kept] != CT_by[o]) | (dm != 0)
    out.update(ids=o[changed], CT=(C[kept] * T[kept])[changed], mass=mass[kept][changed].copy())
    return out

TOLERANCE = 1e-9
"""Largest |energy_balance_error| of a completed run (relative to all that came in); round-off
gives at most 4e-16 on the tutorials of the corpus (tools/corpus.py, docs/tutorials.md) and
below 1e-12 on every case the tests run."""


class EnergyBalance(Effect):
    """Each particle's heat content m c T [J], mass [kg] and entry temperature [K] by id, as
    when last seen; ``C``: m c [J/K] of the atoms last seen, in their order."""

    TOTALS = dict(inserted=0, departed=0, energy_in=0.0, energy_out=0.0, energy_set_by_script=0.0,
                  energy_mass_change=0.0, heat_from_sources=0.0, heat_from_script_walls=0.0)

    def __init__(self, loop):
        super().__init__(loop)
        self.CT_by_id = np.zeros(0)       # m c T of each id when last seen [J] (energy balance)
        self.M_by_id = np.zeros(0)        # mass of each id when last seen [kg] (0: not known)
        self.T_first_by_id = np.zeros(0)  # temperature each id came in with [K] (the frames' change)
        self.seen = np.zeros(0, bool)
        self.C = np.zeros(0)
        self.CT0 = 0.0
        self.residual = self.came_in = None

    def at_run(self, walls) -> None:
        """At each of a script's runs: its fix heat/gran checked against the scene."""
        self.check_heat_gran()

    def begin(self, resumed: bool) -> None:
        """The particles at the start: their heat content is the balance's start, not energy in
        (a restart: the checkpoint's start)."""
        if resumed:
            return
        self.track_all()
        t = self.loop.totals
        self.CT0 = t.pop("energy_in")
        t["energy_in"] = 0.0

    def _grow(self, top: int) -> None:
        """The tables by id long enough for ids below ``top`` (at least doubled when they grow)."""
        if top > len(self.seen):
            grow = max(top, 2 * len(self.seen)) - len(self.seen)
            self.seen = np.r_[self.seen, np.zeros(grow, bool)]
            self.CT_by_id = np.r_[self.CT_by_id, np.zeros(grow)]
            self.M_by_id = np.r_[self.M_by_id, np.zeros(grow)]
            self.T_first_by_id = np.r_[self.T_first_by_id, np.full(grow, np.nan)]

    def track(self, atoms, departures: bool = True) -> None:
        """Inserted particles: their material's temperature (if the scene gives one) and their
        heat content enters the balance; departed ones (deleted, lost) leave it with the heat
        content they had when last seen; particles whose mass changed since they were last seen
        (a script's fix adapt, set ... density) change their heat content by c dm T, the
        balance's ``energy_mass_change`` (at the current T: the heat the host moved in between
        went in at the old mass's capacity, so the two add up to the change of m c T exactly).
        ``departures=False``: ``atoms`` are some of the particles (a partial harvest), the
        absent ones have not departed."""
        loop, totals = self.loop, self.loop.totals
        ids = atoms.id
        self._grow(int(ids.max(initial=0)) + 1)
        mat = loop.materials_of(atoms.type)
        C = atoms.mass * loop.capacity[mat]
        new = ~self.seen[ids]
        T_entry = atoms.T[new]                 # the heat content each new atom came in with
        if loop.dem.events is not None and loop.dem.events.window:
            # under heat/gran an atom seen some steps after its insertion may have been conducted
            # to since: the recorder noted its Temp at its first step, which is what came in
            came, T_came, _ = loop.dem.events.appeared()
            if len(came) and new.any():
                first = by_id(came, T_came, ids[new], missing=np.nan)
                T_entry = np.where(np.isnan(first), T_entry, first)
        if new.any():
            T_set = loop.known.of(loop.known.T, atoms, new)
            atoms.T[new] += np.where(np.isnan(T_set), 0.0, T_set - T_entry)    # what it was conducted kept
            T_entry = np.where(np.isnan(T_set), T_entry, T_set)
            cold = new & ~(atoms.T > 0)
            if cold.any():
                k = np.flatnonzero(cold)[0]
                name = list(loop.scene.materials)[mat[k]]
                raise ScriptError(cold_message(loop.scene.path, atoms.id[k], atoms.type[k], name, atoms.T[k]))
            if loop.scene.scripted:
                self.check_densities(atoms, new, mat)
            totals["inserted"] += int(new.sum())
            totals["energy_in"] += float(np.sum(C[new] * T_entry))
            self.T_first_by_id[ids[new]] = T_entry
        old = ~new & (self.M_by_id[ids] > 0)
        dm = atoms.mass[old] - self.M_by_id[ids[old]]
        if dm.any():
            totals["energy_mass_change"] += float(np.sum(loop.capacity[mat[old]] * dm * atoms.T[old]))
        present = np.zeros(len(self.seen), bool)
        present[ids] = True
        gone = self.seen & ~present if departures else present[:0]
        if gone.any():
            totals["departed"] += int(gone.sum())
            totals["energy_out"] += float(self.CT_by_id[gone].sum())
            self.seen[gone] = False
            self.M_by_id[gone] = 0.0
        self.seen[ids] = True
        self.CT_by_id[ids] = C * atoms.T
        self.M_by_id[ids] = atoms.mass
        self.C = C

    def before_run(self, resumed: bool) -> None:
        if not resumed:         # (a restart continues a run: no script command came in between)
            self.resync()

    def end_run(self) -> None:
        self.track_all()

    def track_all(self, resync: bool = False) -> float | None:
        """``track`` of every particle: serially on LIGGGHTS' own arrays, under MPI on gathered
        atoms, or, where the run allows (``on_ranks``), on each rank's own (``track_ranks``).
        Returns sum(m c T) [J] of the particles now when the ranks computed it, else None."""
        if on_ranks(self.loop):
            return self.track_ranks(resync)
        if resync:
            self.resync()
        else:
            self.track(self.loop.dem.atoms(True))
        return None

    def track_ranks(self, resync: bool = False) -> float:
        """``track`` (and with ``resync``, ``resync``'s term first) on each rank's own atoms:
        rank 0 gets what changed, not every atom (``track_on_rank``); raises the same
        ScriptErrors as ``track``. Returns sum(m c T) [J] of the particles now."""
        loop, totals = self.loop, self.loop.totals
        known = loop.known
        density = np.array([m.density for m in loop.materials]) if loop.scene.scripted else None
        spec = RankTrack(loop.capacity, np.asarray(loop.type_material), density, known.by,
                         Broadcast(known.T) if known.by == "id" else known.T, Broadcast(self.seen.view(np.uint8)),
                         Broadcast(self.M_by_id), Broadcast(self.CT_by_id), resync)
        parts = loop.dem.each_rank(track_on_rank, spec)
        for p in parts:
            self._raise(p["problem"])
        if resync:
            totals["energy_set_by_script"] += sum(p.get("set_by_script", 0.0) for p in parts)
        present = np.unpackbits(parts[0]["present"], count=len(self.seen)).astype(bool)
        new_ids = np.concatenate([p["new_ids"] for p in parts])
        gone = self.seen & ~present
        self._grow(int(new_ids.max(initial=0)) + 1)
        if len(new_ids):
            totals["inserted"] += len(new_ids)
            totals["energy_in"] += sum(p["energy_in"] for p in parts)
        totals["energy_mass_change"] += sum(p["mass_change"] for p in parts)
        if gone.any():
            totals["departed"] += int(gone.sum())
            totals["energy_out"] += float(self.CT_by_id[:len(gone)][gone].sum())
            self.seen[:len(gone)][gone] = False
            self.M_by_id[:len(gone)][gone] = 0.0
        for p in parts:
            self.seen[p["new_ids"]] = True
            self.T_first_by_id[p["new_ids"]] = p["new_T_entry"]
            self.CT_by_id[p["new_ids"]] = p["new_CT"]
            self.M_by_id[p["new_ids"]] = p["new_mass"]
            self.CT_by_id[p["ids"]] = p["CT"]
            self.M_by_id[p["ids"]] = p["mass"]
        self.C = None               # (no atoms on rank 0 to align it with)
        return float(self.CT_by_id[self.seen].sum())

    def _raise(self, problem) -> None:
        """A rank's problem (``track_on_rank``) as ``track`` says it."""
        if problem is None:
            return
        loop = self.loop
        names = list(loop.scene.materials)
        if problem[0] == "material":
            loop.materials_of(np.array(problem[1]))         # (TypeMaterials' own message)
        if problem[0] == "cold":
            _, i, t, mat, T = problem
            raise ScriptError(cold_message(loop.scene.path, i, t, names[mat], T))
        if problem[0] == "density":
            _, i, t, mat, rho, want = problem
            raise ScriptError(density_message(loop.scene.path, i, t, names[mat], rho, want))

    def resync(self) -> None:
        """Before each run: heat content that the script's own commands changed since the last
        run (e.g. ``set ... property/atom Temp``) enters the balance as set by the script (at
        the masses last seen: a mass change is ``track``'s term)."""
        loop = self.loop
        if on_ranks(loop):
            self.track_ranks(resync=True)
            return
        atoms = loop.dem.atoms(True)
        known = np.zeros(len(atoms.id), bool)
        inside = atoms.id < len(self.seen)
        known[inside] = self.seen[atoms.id[inside]]
        if known.any():
            ids = atoms.id[known]
            m = np.where(self.M_by_id[ids] > 0, self.M_by_id[ids], atoms.mass[known])
            C = m * loop.capacity[loop.materials_of(atoms.type[known])]
            # atom by atom: an unchanged atom adds exactly 0, whatever the order LIGGGHTS holds them in
            loop.totals["energy_set_by_script"] += float(np.sum(C * atoms.T[known] - self.CT_by_id[ids]))
        self.track(atoms)

    def check_densities(self, atoms, new, mat) -> None:
        """A script gives its particles their density (templates, set ... density); the contact
        models and the heat capacity use the material's: the two must agree (to 1e-6)."""
        loop = self.loop
        rho = atoms.mass[new] / (4.0 / 3.0 * np.pi * atoms.radius[new] ** 3)
        want = np.array([m.density for m in loop.materials])[mat[new]]
        bad = np.flatnonzero(np.abs(rho / want - 1.0) > 1e-6)
        if len(bad):
            k = np.flatnonzero(new)[bad[0]]
            name = list(loop.scene.materials)[mat[k]]
            raise ScriptError(density_message(loop.scene.path, atoms.id[k], atoms.type[k], name, rho[bad[0]],
                                              want[bad[0]]))

    def check_heat_gran(self) -> None:
        """At each of a script's runs: a fix heat/gran that appeared has its capacities checked
        (``check_capacities``); the event recorder follows one defined after the first run from
        the run after it (``Dem.follow_heat_gran``)."""
        if self.loop.dem.info.heat_gran:
            self.check_capacities()

    def check_capacities(self) -> None:
        """A script's fix heat/gran integrates Temp with its own thermalCapacity: it must be the
        scene's heat capacity of each type's material, else the two would disagree on energy."""
        loop = self.loop
        types = np.flatnonzero(loop.type_material >= 0)
        script = loop.dem.type_values("thermalCapacity", types)
        scene = loop.capacity[loop.type_material[types]]
        bad = np.flatnonzero(np.abs(script / scene - 1) > 1e-12)
        if len(bad):
            t = types[bad[0]]
            fix = loop.dem.info.fixes.get(loop.dem.info.globals.get("thermalCapacity"))
            raise ScriptError(f"{loop.scene.path}: atom type {t}: the script's thermalCapacity {script[bad[0]]:g} "
                              + (f"({fix.where()}) " if fix is not None else "")
                              + f"differs from materials.{list(loop.scene.materials)[loop.type_material[t]]}"
                              f".heat_capacity {scene[bad[0]]:g} J/(kg K): give both the same value")

    def flush(self) -> None:
        """Its totals up to date (a checkpoint, the end): what the script's fix heat/gran added
        since the last flush from its sources and from its walls with a temperature, which the
        contact event recorder sums at every step."""
        events = self.loop.dem.events
        if events is not None and events.window:
            sources, walls = events.heat_gran_heat()
            self.loop.totals["heat_from_sources"] += sources
            self.loop.totals["heat_from_script_walls"] += walls

    def state(self) -> tuple[dict, dict]:
        atoms = self.loop.dem.atoms(True)
        return (dict(CT0=self.CT0),
                dict(CT_by_id=self.CT_by_id, seen=self.seen, M_by_id=self.M_by_id, T_first_by_id=self.T_first_by_id,
                     T_ids=atoms.id, T=atoms.T))

    def restore(self, state: dict) -> None:
        self.CT0 = state["CT0"]
        self.CT_by_id, self.seen = state["CT_by_id"], state["seen"]
        self.M_by_id = state.get("M_by_id", np.zeros(len(self.seen)))
        self.T_first_by_id = state.get("T_first_by_id", np.full(len(self.seen), np.nan))
        if "T" in state:       # Temp as it was (a script's fix may not keep it in the restart)
            atoms = self.loop.dem.atoms(True)
            atoms.T[:] = by_id(state["T_ids"], state["T"], atoms.id)

    def finish(self, summary: dict, status: str) -> None:
        """The energy balance: the residual of sum(m c T) now against the start, what the walls
        (the host's and heat/gran's) and the script's heat sources gave, what came in and went
        out, what the script set and what convection moved [J], relative to all that came in."""
        try:
            if on_ranks(self.loop):
                CT = self.track_ranks()
            else:
                atoms = self.loop.dem.atoms(True)
                self.track(atoms)
                CT = float(np.sum(self.C * atoms.T))
        except ScriptError as exc:    # what stopped the run (a type without material): still a summary
            if status == "completed":
                raise
            summary["energy_balance"] = f"not computed: {exc}"
            return
        t = self.loop.totals
        self.came_in = (self.CT0 + t["energy_in"] + abs(t["energy_set_by_script"]) + abs(t["energy_mass_change"])
                        + abs(t["heat_from_sources"]) + abs(t["heat_from_script_walls"]))
        self.residual = (CT - self.CT0 - t["heat_from_walls"] - t["energy_in"] + t["energy_out"]
                         - t["energy_set_by_script"] - t["energy_mass_change"] - t["heat_convected"]
                         - t["heat_from_sources"] - t["heat_from_script_walls"]
                         + t["heat_gran_walls_undone"])   # J (heat/gran's walls during collisions: taken back)
        error = self.residual / max(self.came_in, 1e-300)       # relative to all that came in
        summary.update(sum_mcT_start=self.CT0, sum_mcT_end=CT, energy_balance_error=error)
        if status == "completed" and not abs(error) <= TOLERANCE:
            self.failure = (f"energy balance broken: the particles' sum(m c T) is {self.residual:.6g} J off what "
                            f"came in, went out and was set by the script ({error:.3g} of all that came in, "
                            f"allowed {TOLERANCE:g}): something changed particle temperatures during the runs "
                            "that the host does not count (a fix of the script other than heat/gran?); the "
                            "terms are in summary.json")
            summary["status"] = f"failed at the end: {self.failure}"
