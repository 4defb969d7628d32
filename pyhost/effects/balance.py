"""Particle temperatures and their energy balance: inserted particles get their material's
temperature and bring their heat content in, departed ones take theirs out, a script's own
changes (``set ... Temp``, a changed mass) are counted as such, and at the end the residual of
sum(m c T) against all that came in and went out is summary.json's energy_balance_error.
Present when the scene's particles have temperatures (``particle_temperatures``). SI units.

The balance holds to round-off by construction (every change of a temperature the host does
not make itself is counted as one of its terms), so a completed run whose residual exceeds
TOLERANCE of all that came in fails (exit 3) after writing its results: something changed
temperatures that the host did not count, and the heat it reports cannot be trusted."""
from __future__ import annotations

import numpy as np

from pyhost.effects import Effect, by_id
from pyhost.engines.liggghts.script import ScriptError

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
        self.track(self.loop.dem.atoms(True))
        t = self.loop.totals
        self.CT0 = t.pop("energy_in")
        t["energy_in"] = 0.0

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
        top = int(ids.max(initial=0)) + 1
        if top > len(self.seen):
            grow = max(top, 2 * len(self.seen)) - len(self.seen)
            self.seen = np.r_[self.seen, np.zeros(grow, bool)]
            self.CT_by_id = np.r_[self.CT_by_id, np.zeros(grow)]
            self.M_by_id = np.r_[self.M_by_id, np.zeros(grow)]
            self.T_first_by_id = np.r_[self.T_first_by_id, np.full(grow, np.nan)]
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
                raise ScriptError(f"{loop.scene.path}: particle {atoms.id[k]} (type {atoms.type[k]}, materials.{name}) "
                                  f"starts at {atoms.T[k]:g} K: temperatures must be above 0 K; give "
                                  f"materials.{name}.temperature, or the script's fix heat/gran initial_temperature")
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
        self.track(self.loop.dem.atoms(True))

    def resync(self) -> None:
        """Before each run: heat content that the script's own commands changed since the last
        run (e.g. ``set ... property/atom Temp``) enters the balance as set by the script (at
        the masses last seen: a mass change is ``track``'s term)."""
        loop = self.loop
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
            raise ScriptError(f"{loop.scene.path}: particle {atoms.id[k]} (type {atoms.type[k]}) has the script's "
                              f"density {rho[bad[0]]:.6g} kg/m^3, materials.{name}.density is {want[bad[0]]:g}: "
                              "give both the same value")

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
        atoms = self.loop.dem.atoms(True)
        try:
            self.track(atoms)
        except ScriptError as exc:    # what stopped the run (a type without material): still a summary
            if status == "completed":
                raise
            summary["energy_balance"] = f"not computed: {exc}"
            return
        CT = float(np.sum(self.C * atoms.T))
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
