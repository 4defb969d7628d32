"""The coupling loop: read this file first.

A scene's DEM is a LIGGGHTS script (the user's, or the box world generated from case.toml),
run command by command by ``run_scene``; each ``run N`` becomes ``Coupling.advance(N)``:

    every DEM chunk:   dem.run(n)
    every sample:      track_particles   (inserted particles get their material's temperature,
                                          departed ones leave the energy balance)
                       sample_contacts   (LIGGGHTS' own contact lists; a new contact is a
                                          collision: impact speed, plugin heat, exchange in Temp;
                                          an ended one gets the model's restitution if asked;
                                          a script's fix heat/gran is undone during t_coll)
    every coupling:    couple_fluid      (fluid force on particles, particles' fraction to fluid;
                                          with convection, gas-particle heat over the interval:
                                          particles' Temp now, the opposite heat into the gas)
    every frame:       write_frame       (history.csv, VTK)

Temperatures live in LIGGGHTS' per-atom ``Temp``: the host reads and writes them there and
keeps no copy. The loop builds only what the scene asks for (``Scene.effects_summary``): no
contact sampling for an isothermal scene without restitution feedback. How a contact is
classified (collision, then enduring) is told in ``pyhost.collisions``.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plugins import convection
from plugins.dem.hertz import DemHertz, effective_modulus
from plugins.dem.impulse import restitution_impulse
from plugins.heat.batch import evaluate_flagged, side_heat
from plugins.heat.exchange import exchange_heat, temperature_difference
from pyhost.collisions import WALL_BASE, ContactTracker, contact_keys
from pyhost.dem_input import script_dem_contacts
from pyhost import checkpoint, signals
from pyhost.engines.dem import Dem
from pyhost.engines.events import BEGIN, END
from pyhost.failures import particles_lost
from pyhost.engines.liggghts import LiggghtsError
from pyhost.outdir import write_atomic
from pyhost.output import ColumnLog, CsvLog, Progress, VtkSeries, collision_kinds
from pyhost.script import ScriptError, parse_run, replay

HARVEST_EVERY = 1000
"""DEM steps between harvests of the contact events at most (they are also taken at every
frame, fluid exchange, checkpoint and sample): bounds the recorder's buffer and the wait of a
signal (a stop is taken between two DEM chunks)."""
COLLISION_COLUMNS = ("time", "i", "j", "wall", "v0", "Q", "e", "t_coll", "model")
OPEN_COLUMNS = ("start", "t_coll", "e", "v0", "nx", "ny", "nz")
"""What the host keeps of each open contact: start time [s], model duration [s], the model's
restitution (NaN: none to impose), impact speed [m/s] and unit normal at the start."""
FLUID_COLUMNS = ("u_inlet", "pressure_drop", "bed_height")
GAS_COLUMNS = ("T_gas_mean", "gas_energy", "heat_convected", "heat_convected_gross", "heat_through_fluid_boundaries",
               "heat_moved")


@dataclass(frozen=True)
class HostWall:
    """A LIGGGHTS wall as the host sees it: its fix id (and the index of the mesh within a
    mesh wall fix: each mesh is a wall of its own), its real material (index into the
    scene's materials) and its fixed temperature [K] (NaN: adiabatic)."""

    fix: str
    material: int
    temperature: float
    mesh: int = 0


def layer_pressure_drop(fluid) -> float:
    """Mean pressure [Pa] of the fluid's lowest cell layer less that of its highest. Layers
    are matched with a tolerance: cell centres of one layer differ in their last digits."""
    p, _ = fluid.fields()
    z = fluid.cell_centres[:, 2]
    tol = 1e-6 * (z.max() - z.min())
    return float(p[z < z.min() + tol].mean() - p[z > z.max() - tol].mean())


class Coupling:
    """The coupled run of a scene on a prepared ``Dem``; ``advance(n)`` runs n DEM steps,
    ``finish()`` writes and returns the summary.

    ``type_material``: material index of each atom type (index = type; -1: none);
    ``groups``: (names, function atoms -> group index per atom) for the history columns;
    ``walls``: the HostWall of every LIGGGHTS wall, in the order of their contact codes;
    ``initial_T``: function (atoms, mask of new atoms) -> their starting temperature [K]
    (NaN: keep the value LIGGGHTS holds). The contacts present at the start (overlaps as
    placed, a script's read_restart of a settled bed) are not collisions: open and enduring.
    ``resume``: a checkpoint's state (pyhost.checkpoint) to continue from, its logs appended to.
    """

    def __init__(self, scene, dem: Dem, out: Path, *, type_material, groups, walls, initial_T, fluid=None,
                 end: float | None = None, progress_every: float = 5.0, keep_all: np.ndarray | None = None,
                 resume: dict | None = None):
        self.scene, self.dem, self.out, self.fluid = scene, dem, Path(out), fluid
        self.effects = scene.effects_summary()
        self.materials = script_dem_contacts(scene, dem) if scene.scripted else list(scene.materials.values())
        self.type_material = np.asarray(type_material, int)
        self.group_names, self.group_of = groups
        self.initial_T = initial_T
        self.keep_all = keep_all         # box scenes: group of each id; losing any particle is a failure
        self.before = None
        self.update_walls(walls)
        self.capacity = np.array([m.heat_capacity for m in self.materials])
        self.tracker = ContactTracker()
        self.info = np.empty((0, len(OPEN_COLUMNS)))   # per open contact, rows aligned with tracker.open_keys
        self.t0_step = dem.step
        self.t = dem.step * dem.dt
        self.steps = 0
        self.totals = dict(collisions=0, particle_particle=0, particle_wall=0, heat_moved=0.0,
                           heat_from_walls=0.0, capped=0, clipped=0, heat_gran_undone=0.0,
                           inserted=0, departed=0, energy_in=0.0, energy_out=0.0, energy_set_by_script=0.0,
                           energy_mass_change=0.0, outside_model_range=0,
                           heat_convected=0.0, heat_convected_gross=0.0)
        self.CT_by_id = np.zeros(0)      # m c T of each id at its last sample [J] (energy balance)
        self.M_by_id = np.zeros(0)       # mass of each id at its last sample [kg] (0: not known)
        self.T_first_by_id = np.zeros(0)  # temperature each id came in with [K] (the frames' change)
        self.seen = np.zeros(0, bool)
        self.warned = set()
        self.heat = self.effects["particle_temperatures"]
        self.convection = self.effects["convection"] and fluid is not None
        self.laws = {}
        self.check_heat_gran()
        if resume is None:
            self.track_particles(dem.atoms(self.heat))
            self.CT0 = self.totals.pop("energy_in")
            self.totals["energy_in"] = 0.0
        logs = resume["logs"] if resume else {}
        columns = COLLISION_COLUMNS + tuple(f"Q_{m}" for m in scene.effects.heat_models[1:])
        self.collisions = (ColumnLog(self.out / "collisions", collision_kinds(columns), logs.get("collisions"))
                           if scene.output.collisions == "binary"
                           else CsvLog(self.out / "collisions.csv", columns, logs.get("collisions")))
        self.history = CsvLog(self.out / "history.csv", ("time", "particles", "T_mean", "T_min", "T_max")
                              + tuple(f"T_group{k}" for k in range(len(self.group_names)))
                              + ("sum_mcT", "heat_from_walls", "energy_in", "energy_out", "collisions",
                                 "capped", "clipped") + (FLUID_COLUMNS if fluid is not None else ())
                              + (GAS_COLUMNS if self.convection else ()), logs.get("history"))
        self.frames = VtkSeries(self.out / "vtk", "particles", logs.get("particles")) if scene.output.vtk else None
        self.fluid_frames = (VtkSeries(self.out / "vtk", "fluid", logs.get("fluid"))
                             if fluid is not None and scene.output.vtk else None)
        self.fluid_force = (np.zeros(0, np.int64), np.zeros((0, 3)))   # ids and force [N] of the last coupling
        self.progress = Progress(end or math.inf, progress_every)
        self.events = dem.events is not None     # contacts recorded inside LIGGGHTS (else sampled)
        self.t_coll_of = {}                      # (key, begin step) -> t_coll [s] of pair collisions under heat/gran
        self.restitution = self.events and scene.effects.restitution_feedback and self.effects["particle_temperatures"]
        self.targets = {}                        # key -> (separation speed, normal) the recorder imposes at the end
        sampled = self.effects["contact_extraction"] and (not self.events or dem.sampled_walls())
        self.every = dict(sample=scene.time.sample_every if sampled else 0,
                          harvest=(scene.time.sample_every if self.restitution else HARVEST_EVERY) if self.events else 0,
                          frame=max(1, round(scene.output.every / dem.dt)),
                          couple=scene.time.couple_every if fluid is not None else 0,
                          checkpoint=round(scene.output.checkpoint / dem.dt) if scene.output.checkpoint else 0)
        if self.events:                      # the walls' contacts now are open ones: one that begins at
            dem.events.sync()                # the next step is a collision (prepare's set-up left the lists)
        self.command, self.run_left = -1, 0  # the script's run under way (its index) and its steps to go
        self.inputs = ()                     # the script's files (a restart checks them)
        self.ready = resume is not None      # a consistent state to checkpoint (after start())
        self.resumed = resume is not None    # the next advance continues the checkpoint's run
        self.checkpoint_step = -1            # the step of the last checkpoint written
        if resume is not None:
            self.restore(resume)

    def update_walls(self, walls) -> None:
        """The LIGGGHTS walls as the host sees them (a script may add walls between runs)."""
        self.walls = walls
        self.wall_index = {(w.fix, w.mesh): k for k, w in enumerate(walls)}
        self.T_wall = np.array([w.temperature if self.effects["wall_heat"] else np.nan for w in walls])
        self.wall_material = np.array([w.material for w in walls], int)
        if self.dem.events is not None:
            self.dem.event_planes(self.wall_index)

    def start(self) -> None:
        """The first fluid exchange and the first frame (after construction, so that an
        interrupt from here on finds a coupling to write its summary)."""
        if self.ready:                    # resumed: the checkpoint's state is all there is
            return
        if self.every["sample"]:
            self.open_present()
        T_gas = self.fluid.temperature() if self.convection else None
        if self.fluid is not None:
            self.couple_fluid()
        # the solver starts from the first fluid fraction it gets (no flow displaces the gas of
        # the particles as placed): the gas's initial heat content with that fraction
        self.gas_energy0 = float(np.sum(self.fluid.heat_capacity() * T_gas)) if self.convection else 0.0
        self.write_frame()
        self.ready = True

    def advance(self, n: int) -> None:
        """n coupled DEM steps: the loop of the module doc. With checkpoints, a signal stops it
        only at the end of a step, where the state is whole (``signals.deferred``), and a
        checkpoint is written there (``run_scene``), periodic checkpoints asked for or not."""
        with signals.deferred():
            self._advance(n)

    def _advance(self, n: int) -> None:
        if self.heat and not self.resumed:  # (a restart continues a run: no script command came in between)
            self.resync()
        self.resumed = False
        self.run_left = n
        while n > 0:
            step = self.dem.step - self.t0_step
            chunk = min([n] + [k - step % k for k in self.every.values() if k])
            if self.keep_all is not None and (self.before is None or self.before[4] != self.dem.step):
                self.note_before(self.dem.atoms(False))
            self.dem.run(chunk)
            if self.keep_all is not None and self.dem.count() < len(self.before[1]):
                self.lost()
            n -= chunk
            self.run_left = n
            self.steps += chunk
            step += chunk
            self.t = self.dem.step * self.dem.dt
            due = {name: k and step % k == 0 for name, k in self.every.items()}
            if self.events and self.harvest_alone(due):
                self.harvest_partly()
            elif due["sample"] or (self.events and any(due.values())):
                atoms = self.dem.atoms(self.heat)
                self.track_particles(atoms)
                if self.events:
                    self.harvest(atoms, final=bool(due["checkpoint"]))
                if due["sample"]:
                    self.sample_contacts(atoms)
                if self.keep_all is not None:
                    self.note_before(atoms)         # spares a gather of all atoms under MPI
            if due["couple"]:
                self.couple_fluid()
            if due["frame"]:
                self.write_frame()
            if due["checkpoint"]:
                checkpoint.write(self)
            self.progress.update(self.t, f", {self.totals['collisions']} collisions")
            signals.check()
        if self.heat or self.events:
            atoms = self.dem.atoms(self.heat)
            self.track_particles(atoms)
            if self.events:
                self.harvest(atoms)

    def note_before(self, atoms) -> None:
        """The particles before the next chunk (time, ids, positions, velocities, step): what
        a report of lost particles says of them."""
        self.before = (self.t, atoms.id.copy(), atoms.x.copy(), atoms.v.copy(), self.dem.step)

    def lost(self):
        """A box scene lost particles (through an open face, a soft wall, or blown out)."""
        gone = np.setdiff1d(self.before[1], self.dem.atoms(False).id)
        raise particles_lost(self.scene, gone, self.before[:4], self.dem.step * self.dem.dt, self.keep_all)

    def resync(self) -> None:
        """Before each run: heat content that the script's own commands changed since the last
        run (e.g. ``set ... property/atom Temp``) enters the balance as set by the script (at
        the masses of the last sample: a mass change is ``track_particles``' term)."""
        atoms = self.dem.atoms(True)
        known = np.zeros(len(atoms.id), bool)
        inside = atoms.id < len(self.seen)
        known[inside] = self.seen[atoms.id[inside]]
        if known.any():
            ids = atoms.id[known]
            m = np.where(self.M_by_id[ids] > 0, self.M_by_id[ids], atoms.mass[known])
            C = m * self.capacity[self.materials_of(atoms.type[known])]
            # atom by atom: an unchanged atom adds exactly 0, whatever the order LIGGGHTS holds them in
            self.totals["energy_set_by_script"] += float(np.sum(C * atoms.T[known] - self.CT_by_id[ids]))
        self.track_particles(atoms)

    # -- checkpoint (pyhost.checkpoint writes and reads the files) ---------------------------
    def state(self) -> tuple[dict, dict]:
        """The host's state at the end of a step: (JSON values, arrays)."""
        for series in (self.frames, self.fluid_frames):    # every frame it names on disk
            if series is not None:
                series.flush()
        logs = dict(collisions=self.collisions.mark(), history=self.history.mark(),
                    particles=self.frames.frames if self.frames is not None else None,
                    fluid=self.fluid_frames.frames if self.fluid_frames is not None else None)
        values = dict(t0_step=self.t0_step, steps=self.steps, t=self.t, totals=self.totals, CT0=self.CT0,
                      gas_energy0=getattr(self, "gas_energy0", 0.0), warned=sorted(self.warned), logs=logs,
                      command=self.command, run_left=self.run_left, mesh_motion=self.dem.mesh_motion_times(),
                      randoms=self.dem.random_states())
        atoms = self.dem.atoms(self.heat)
        arrays = dict(open_keys=self.tracker.open_keys, contact_info=self.info, CT_by_id=self.CT_by_id,
                      seen=self.seen, M_by_id=self.M_by_id, T_first_by_id=self.T_first_by_id, fluid_ids=self.fluid_force[0],
                      fluid_force=self.fluid_force[1], T_ids=atoms.id,
                      T=atoms.T if self.heat else np.zeros(0),
                      target_keys=np.array(list(self.targets), np.int64),
                      target_speed=np.array([v[0] for v in self.targets.values()]),
                      target_normal=np.array([v[1] for v in self.targets.values()]).reshape(-1, 3))
        return values, arrays

    def restore(self, state: dict) -> None:
        """Continue from ``state`` (values and arrays of :meth:`state` in one dict)."""
        for name in ("t0_step", "steps", "t", "CT0", "gas_energy0"):
            setattr(self, name, state[name])
        self.totals, self.warned = state["totals"], set(state["warned"])
        self.tracker.update(state["open_keys"])
        self.info = np.asarray(state["contact_info"], float).reshape(-1, len(OPEN_COLUMNS))
        self.CT_by_id, self.seen = state["CT_by_id"], state["seen"]
        self.M_by_id = state.get("M_by_id", np.zeros(len(self.seen)))
        self.T_first_by_id = state.get("T_first_by_id", np.full(len(self.seen), np.nan))
        self.totals.setdefault("energy_mass_change", 0.0)
        self.totals.setdefault("outside_model_range", 0)
        checkpoint.restore_forces(self.dem, state)
        self.dem.set_mesh_motion_times(state.get("mesh_motion", {}))
        self.dem.set_random_states(state.get("randoms", {}))
        if self.restitution and len(state.get("target_keys", ())):   # separation speeds of contacts still open
            self.dem.events.restitution(state["target_keys"], state["target_speed"], state["target_normal"])
            self.targets = dict(zip(state["target_keys"].tolist(),
                                    zip(state["target_speed"].tolist(), state["target_normal"].tolist())))
        if self.heat and "T" in state:       # Temp as it was (a script's fix may not keep it in the restart)
            atoms = self.dem.atoms(True)
            atoms.T[:] = _by_id(state["T_ids"], state["T"], atoms.id)
        if self.fluid is not None:          # the fluid force of the last coupling, until the next
            ids, force = state["fluid_ids"], state["fluid_force"]
            self.dem.set_force(_by_id(ids, force, self.dem.atoms(False).id))
            self.fluid_force = (ids, force)

    # -- particles ----------------------------------------------------------------------
    def materials_of(self, types) -> np.ndarray:
        types = np.asarray(types)
        mat = np.where(types < len(self.type_material), self.type_material[np.minimum(types, len(self.type_material) - 1)], -1)
        if (mat < 0).any():
            bad = sorted(set(types[mat < 0].tolist()))
            raise ScriptError(f"{self.scene.path}: atom type(s) {bad} have no material: name them in a "
                              "[materials.NAME] types = [...] list")
        return mat

    def track_particles(self, atoms, departures: bool = True) -> None:
        """Inserted particles: their material's temperature (if the scene gives one) and their
        heat content enters the balance; departed ones (deleted, lost) leave it with the heat
        content of their last sample; particles whose mass changed since their last sample
        (a script's fix adapt, set ... density) change their heat content by c dm T, the
        balance's ``energy_mass_change`` (at the current T: the heat the host moved in between
        went in at the old mass's capacity, so the two add up to the change of m c T exactly).
        ``departures=False``: ``atoms`` are some of the particles (``harvest_partly``), the
        absent ones have not departed."""
        if not self.heat:
            return
        ids = atoms.id
        top = int(ids.max(initial=0)) + 1
        if top > len(self.seen):
            grow = max(top, 2 * len(self.seen)) - len(self.seen)
            self.seen = np.r_[self.seen, np.zeros(grow, bool)]
            self.CT_by_id = np.r_[self.CT_by_id, np.zeros(grow)]
            self.M_by_id = np.r_[self.M_by_id, np.zeros(grow)]
            self.T_first_by_id = np.r_[self.T_first_by_id, np.full(grow, np.nan)]
        mat = self.materials_of(atoms.type)
        C = atoms.mass * self.capacity[mat]
        new = ~self.seen[ids]
        T_entry = atoms.T[new]                 # the heat content each new atom came in with
        if self.dem.events is not None and self.dem.events.window:
            # under heat/gran an atom seen some steps after its insertion may have been conducted
            # to since: the recorder noted its Temp at its first step, which is what came in
            came, T_came, _ = self.dem.events.appeared()
            if len(came) and new.any():
                first = _by_id(came, T_came, ids[new], missing=np.nan)
                T_entry = np.where(np.isnan(first), T_entry, first)
        if new.any():
            T_set = self.initial_T(atoms, new)
            atoms.T[new] += np.where(np.isnan(T_set), 0.0, T_set - T_entry)    # what it was conducted kept
            T_entry = np.where(np.isnan(T_set), T_entry, T_set)
            cold = new & ~(atoms.T > 0)
            if cold.any():
                k = np.flatnonzero(cold)[0]
                name = list(self.scene.materials)[mat[k]]
                raise ScriptError(f"{self.scene.path}: particle {atoms.id[k]} (type {atoms.type[k]}, materials.{name}) "
                                  f"starts at {atoms.T[k]:g} K: temperatures must be above 0 K; give "
                                  f"materials.{name}.temperature, or the script's fix heat/gran initial_temperature")
            if self.scene.scripted:
                self.check_densities(atoms, new, mat)
            self.totals["inserted"] += int(new.sum())
            self.totals["energy_in"] += float(np.sum(C[new] * T_entry))
            self.T_first_by_id[ids[new]] = T_entry
        old = ~new & (self.M_by_id[ids] > 0)
        dm = atoms.mass[old] - self.M_by_id[ids[old]]
        if dm.any():
            self.totals["energy_mass_change"] += float(np.sum(self.capacity[mat[old]] * dm * atoms.T[old]))
        present = np.zeros(len(self.seen), bool)
        present[ids] = True
        gone = self.seen & ~present if departures else present[:0]
        if gone.any():
            self.totals["departed"] += int(gone.sum())
            self.totals["energy_out"] += float(self.CT_by_id[gone].sum())
            self.seen[gone] = False
            self.M_by_id[gone] = 0.0
        self.seen[ids] = True
        self.CT_by_id[ids] = C * atoms.T
        self.M_by_id[ids] = atoms.mass
        self.C = C

    # -- contacts -----------------------------------------------------------------------
    def sample_contacts(self, atoms) -> None:
        c = self.dem.contacts(atoms, self.wall_index)
        keys = contact_keys(c.i, c.j)
        last_keys, last = self.tracker.open_keys, self.info
        opened, closed, prev = self.tracker.match(keys)
        self.info = np.empty((len(keys), len(OPEN_COLUMNS)))
        kept = prev >= 0
        self.info[kept] = last[prev[kept]]
        if len(opened):
            self.start_collisions(atoms, c, keys, opened)
        if len(closed):
            self.end_collisions(atoms, last_keys[closed], last[closed])
        if self.heat and self.dem.info.heat_gran and len(c):
            self.undo_heat_gran(atoms, c)

    def open_present(self) -> None:
        """The contacts present now count as open, enduring (t_coll 0: no collision time to
        account for), with no restitution to impose at their end (e NaN)."""
        c = self.dem.contacts(self.dem.atoms(self.heat), self.wall_index)
        keys = contact_keys(c.i, c.j)
        self.tracker.update(keys)
        n = len(keys)
        self.info = np.column_stack([np.full(n, self.t), np.zeros(n), np.full(n, math.nan), np.full(n, math.nan),
                                     np.asarray(c.normal, float).reshape(n, 3)])

    def dem_law(self, a: int, b: int) -> DemHertz:
        """The DEM's Hertz law between atom types a and b, from the script's own values
        (LIGGGHTS' effective modulus and per-pair restitution); read once per pair."""
        if (a, b) not in self.laws:
            E = self.dem.type_values("youngsModulus", (a, b))
            nu = self.dem.type_values("poissonsRatio", (a, b))
            e = self.dem.type_pair_value("coefficientRestitution", a, b)
            self.laws[a, b] = DemHertz(effective_modulus(E[0], nu[0], E[1], nu[1]), e)
        return self.laws[a, b]

    def flag_outside_range(self, flagged, v0) -> None:
        """Collisions the contact models do not cover (plugins.heat.validity, as ``collide`` flags
        them): counted in summary.json (outside_model_range), said once; their heat is moved."""
        self.totals["outside_model_range"] += int(flagged.sum())
        if "outside_model_range" not in self.warned:
            self.warned.add("outside_model_range")
            print(f"warning: a collision at v0 = {float(np.max(v0[flagged])):.4g} m/s is outside the contact models' "
                  "range (indentation beyond the smaller radius, or an output overflows): its heat is the models' "
                  "extrapolation; such collisions are counted in summary.json as outside_model_range")

    def check_densities(self, atoms, new, mat) -> None:
        """A script gives its particles their density (templates, set ... density); the contact
        models and the heat capacity use the material's: the two must agree (to 1e-6)."""
        rho = atoms.mass[new] / (4.0 / 3.0 * np.pi * atoms.radius[new] ** 3)
        want = np.array([m.density for m in self.materials])[mat[new]]
        bad = np.flatnonzero(np.abs(rho / want - 1.0) > 1e-6)
        if len(bad):
            k = np.flatnonzero(new)[bad[0]]
            name = list(self.scene.materials)[mat[k]]
            raise ScriptError(f"{self.scene.path}: particle {atoms.id[k]} (type {atoms.type[k]}) has the script's "
                              f"density {rho[bad[0]]:.6g} kg/m^3, materials.{name}.density is {want[bad[0]]:g}: "
                              "give both the same value")

    def check_heat_gran(self) -> None:
        """At each of a script's runs: a fix heat/gran that appeared has its capacities checked
        (``check_capacities``). One defined after the first run came too late for the contact
        compute's heatFlux column (LIGGGHTS refuses the column without the fix), so its
        conduction during collisions cannot be taken back: said once, with what it means."""
        if not (self.heat and self.dem.info.heat_gran):
            return
        self.check_capacities()
        if not self.dem.has_heat_flux() and "heat_gran_late" not in self.warned:
            self.warned.add("heat_gran_late")
            print(f"warning: fix heat/gran {self.dem.info.heat_gran!r} comes after the script's first run: its "
                  "conduction through a contact during the collision's model time is not taken back, so that "
                  "stretch is counted by both (see heat_gran_undone: 0); define it before the first run to avoid it")

    def check_capacities(self) -> None:
        """A script's fix heat/gran integrates Temp with its own thermalCapacity: it must be the
        scene's heat capacity of each type's material, else the two would disagree on energy."""
        types = np.flatnonzero(self.type_material >= 0)
        script = self.dem.type_values("thermalCapacity", types)
        scene = self.capacity[self.type_material[types]]
        bad = np.flatnonzero(np.abs(script / scene - 1) > 1e-12)
        if len(bad):
            t = types[bad[0]]
            raise ScriptError(f"{self.scene.path}: atom type {t}: the script's thermalCapacity {script[bad[0]]:g} "
                              f"differs from materials.{list(self.scene.materials)[self.type_material[t]]}"
                              f".heat_capacity {scene[bad[0]]:g} J/(kg K): give both the same value")

    def partners(self, atoms, i, j):
        """For contacts between local atoms i and partners j (atom ids, or WALL_BASE + wall):
        whether j is a wall, j as a local index or wall code, its material, atom type (walls:
        their LIGGGHTS type), radius [m] and mass [kg] (inf for walls)."""
        wall = j >= WALL_BASE
        jl = np.where(wall, j, atoms.index(np.where(wall, 0, j)))
        w = np.where(wall, j - WALL_BASE, 0)
        jj = np.where(wall, 0, jl)
        mat_i = self.materials_of(atoms.type[i])
        wall_mat = np.where(self.wall_material[w] >= 0, self.wall_material[w], mat_i) if len(self.walls) else mat_i
        mat = np.where(wall, wall_mat, self.materials_of(atoms.type[jj]))
        wall_type = np.array([self.dem.info.wall_type(wl.fix, wl.mesh) or 1 for wl in self.walls] or [1])
        typ = np.where(wall, wall_type[w], atoms.type[jj])
        return (wall, jl, mat, typ, np.where(wall, np.inf, atoms.radius[jj]),
                np.where(wall, np.inf, atoms.mass[jj]))

    def harvest_alone(self, due) -> bool:
        """Whether this chunk's end asks only for a harvest, under MPI with no fix heat/gran:
        then only the colliding atoms are gathered to rank 0 (``harvest_partly``). Nothing but
        the host changes a temperature then, and each atom's heat content in the balance is
        brought up to date when it is next seen."""
        return (self.dem.link is not None and not self.dem.events.window and self.keep_all is None
                and due["harvest"] and not any(v for k, v in due.items() if k != "harvest"))

    def harvest_partly(self) -> None:
        """A harvest under MPI for which rank 0 gathers only the atoms of the events (the
        others stay on their ranks): ``harvest`` on them."""
        ev = self.dem.events.take()
        if not len(ev):
            return
        ids = np.unique(np.r_[ev["i"], ev["j"][~ev["wall"]]])
        atoms = self.dem.atoms_of(ids, self.heat)
        self.track_particles(atoms, departures=False)
        self.harvest(atoms, ev=ev)

    def harvest(self, atoms, final: bool = False, ev=None) -> None:
        """The contact events recorded inside LIGGGHTS since the last harvest: each begun
        contact is a collision, at its impact speed as recorded at first touch, its heat moved
        now in the order the collisions happened. Without a fix heat/gran nothing else changes
        a temperature between two harvests (they come at every fluid exchange, frame and
        sample), so the heat is what it would be if moved at each collision's own step; with
        one, each collision takes the temperature difference it began with (the recorder notes
        the two temperatures at its first step), and what heat/gran conducted through each new
        contact during the collision's model time is taken back (``take_back_heat_gran``;
        ``final``: also for contacts younger than its window, at a checkpoint or the end). A
        collision whose particle left the simulation before the harvest (deleted, out of the
        box) is counted apart (collisions_of_departed) and moves no heat: its heat content left
        at its last sample; so is one that began with no approach speed
        (contacts_without_impact)."""
        ev = self.dem.events.take() if ev is None else ev
        begin, ends = ev[ev["kind"] == BEGIN], ev[ev["kind"] == END]
        if self.dem.events.joined:               # open contacts that moved between ranks (MPI)
            self.totals["contacts_changed_rank"] = self.totals.get("contacts_changed_rank", 0) + len(self.dem.events.joined)
        if self.targets and len(ends):
            self.ended_with_targets(atoms, ends)
        if len(begin):
            self.collide_begun(atoms, begin, ends)
        if self.dem.events.window:
            dt = self.dem.dt
            for key, began, moved in self.dem.events.joined:   # a flux history goes on on another rank
                if (key, began) in self.t_coll_of:
                    self.t_coll_of[key, moved] = self.t_coll_of[key, began] - (moved - began) * dt
            self.take_back_heat_gran(atoms, final)

    def ended_with_targets(self, atoms, ends) -> None:
        """Contacts given a separation speed that ended since the last harvest: the recorder
        imposed it at the end, unless the pair's atoms were on two ranks (MPI: the recorder
        changes only its own rank's atoms) or one was gone. Those get it now, from the
        velocities now (restitution_late), as a contact shorter than the harvest interval does.
        Under MPI every rank forgets these contacts' speeds (each keeps all, as a contact may
        move between ranks)."""
        keys = contact_keys(ends["i"], ends["j"])
        late = []
        for r, (key, imposed) in enumerate(zip(keys.tolist(), ends["imposed"].tolist())):
            target = self.targets.pop(key, None)
            if target is not None and not imposed:
                late.append((r,) + target)
        if self.dem.link is not None:
            self.dem.events.forget(keys)
        if late:
            rows = np.array([r for r, _, _ in late])
            present = (atoms.index(ends["i"][rows]) >= 0) & (ends["wall"][rows] | (atoms.index(ends["j"][rows]) >= 0))
            self.totals["restitution_not_imposed"] = self.totals.get("restitution_not_imposed", 0) + int((~present).sum())
            self.totals["restitution_late"] = self.totals.get("restitution_late", 0) + int(present.sum())
            self.impose_separation(atoms, ends["i"][rows], ends["j"][rows], np.array([n for _, _, n in late]),
                                   np.ones(len(rows)), np.array([v for _, v, _ in late]))

    def collide_begun(self, atoms, begin, ends) -> None:
        i = atoms.index(begin["i"])
        j_here = np.where(begin["wall"], 0, atoms.index(np.where(begin["wall"], begin["i"], begin["j"])))
        here = (i >= 0) & (j_here >= 0)
        if not here.all():
            self.totals["collisions_of_departed"] = self.totals.get("collisions_of_departed", 0) + int((~here).sum())
        # a contact that begins without closing in (particles grown into each other by a fix
        # adapt, or placed touching) is no impact: open, with no collision heat
        still = here & ~(begin["vn"] > 0)
        if still.any():
            self.totals["contacts_without_impact"] = self.totals.get("contacts_without_impact", 0) + int(still.sum())
        begin = begin[here & ~still]
        # in the order of step, then ids: not of the recorder's lists, which follow the atoms'
        # order in memory (a restart or another number of ranks changes it)
        begin = begin[np.lexsort((begin["j"], begin["i"], begin["wall"], begin["step"]))]
        if len(begin):
            at = self.collide(atoms, begin["i"], begin["j"], begin["vn"], begin["n"], begin["step"] * self.dem.dt,
                              T_begin=begin["T"])
            if self.dem.events.window:          # each pair collision's model time, until its flux history comes
                pair = ~begin["wall"]
                keys = contact_keys(begin["i"][pair], begin["j"][pair]).tolist()
                self.t_coll_of.update(zip(zip(keys, begin["step"][pair].tolist()), at[pair, 1].tolist()))
            if self.restitution:
                self.ask_restitution(atoms, begin, at, ends)

    def ask_restitution(self, atoms, begin, at, ends) -> None:
        """Restitution feedback on contact events: each collision's separation speed e v0 (e
        above 1 clipped, counted) handed to the recorder, which imposes it at the step the
        contact ends. A contact that ended before this harvest (shorter than the harvest
        interval, time.sample_every steps) gets it now, from the velocities now, as the samples
        did (counted as restitution_late)."""
        e, v0 = at[:, 2], at[:, 3]
        self.totals["clipped"] += int(np.sum(e > 1.0))
        speed = np.minimum(e, 1.0) * v0
        keys = contact_keys(begin["i"], begin["j"])
        ended = {}
        for key, step in zip(contact_keys(ends["i"], ends["j"]).tolist(), ends["step"].tolist()):
            ended.setdefault(key, []).append(step)
        late = np.array([any(s > b for s in ended.get(k, ())) for k, b in zip(keys.tolist(), begin["step"].tolist())],
                        bool)
        ask = ~late & ~np.isnan(speed)
        if ask.any():
            self.dem.events.restitution(keys[ask], speed[ask], begin["n"][ask])
            self.targets.update(zip(keys[ask].tolist(), zip(speed[ask].tolist(), begin["n"][ask].tolist())))
        if late.any():
            self.totals["restitution_late"] = self.totals.get("restitution_late", 0) + int(late.sum())
            self.impose_separation(atoms, begin["i"][late], begin["j"][late], begin["n"][late],
                                   np.minimum(e[late], 1.0), v0[late])

    def take_back_heat_gran(self, atoms, final: bool) -> None:
        """What the script's fix heat/gran conducted through each new pair contact during the
        collision's model duration t_coll, taken back (the collision heat stands for that time):
        from the recorder's flux history of the contact, step m from the begin carrying flux f_m
        [W] over dt, Q = dt sum_m f_m clip(t_coll / dt - m, 0, 1) [J] into the smaller id. Exact
        per step, where the samples took the flux at each sample over the sample interval."""
        i, j, start, filled, flux = self.dem.events.histories(all=final)
        if not len(i):
            return
        keys = contact_keys(i, j).tolist()
        t_coll = np.array([self.t_coll_of.pop(k, np.nan) for k in zip(keys, start.tolist())])
        if final:                                           # every history is in: what is left has none
            self.t_coll_of = {}
        if final:
            self.t_coll_of = {}
        dt, window = self.dem.dt, flux.shape[1]
        steps = t_coll / dt
        cut = np.isfinite(steps) & (steps > window) & (filled == window)
        if cut.any():
            self.totals["heat_gran_undo_cut"] = self.totals.get("heat_gran_undo_cut", 0) + int(cut.sum())
        share = np.clip(np.nan_to_num(steps)[:, None] - np.arange(window), 0.0, 1.0)
        share[np.arange(window) >= filled[:, None]] = 0.0
        q = dt * np.sum(flux * share, axis=1)              # heat heat/gran moved into i [J]
        a, b = atoms.index(i), atoms.index(j)
        ok = np.isfinite(t_coll) & (a >= 0) & (b >= 0) & (q != 0)
        a, b, q = a[ok], b[ok], q[ok]
        np.subtract.at(atoms.T, a, q / self.C[a])
        np.add.at(atoms.T, b, q / self.C[b])
        self.totals["heat_gran_undone"] += float(np.abs(q).sum())

    def start_collisions(self, atoms, c, keys, rows) -> None:
        i = atoms.index(c.i[rows])
        wall, jl, mj, tj, R_j, m_j = self.partners(atoms, i, c.j[rows])
        ti, R_i, m_i = atoms.type[i], atoms.radius[i], atoms.mass[i]
        R_eff = np.where(wall, R_i, R_i * R_j / np.where(wall, 1.0, R_i + R_j))
        m_eff = np.where(wall, m_i, m_i * m_j / np.where(wall, 1.0, m_i + m_j))
        delta, approach = c.delta[rows], c.approach[rows]
        v0 = np.abs(approach)
        if self.dem.info.pair_model == "hertz":
            for (a, b) in set(zip(ti.tolist(), tj.tolist())):
                s = (ti == a) & (tj == b)
                v0[s] = self.dem_law(a, b).impact_speed(delta[s], approach[s], R_eff[s], m_eff[s],
                                                     window=self.every["sample"] * self.dem.dt)
        elif "model" not in self.warned:
            self.warned.add("model")
            print(f"warning: the DEM's normal model is '{self.dem.info.pair_model}', not hertz: impact speeds "
                  "are the approach speeds at the first sample in contact, not integrated back to touch")
        at = self.collide(atoms, c.i[rows], c.j[rows], v0, c.normal[rows], np.full(len(rows), self.t))
        self.info[rows] = at

    def collide(self, atoms, ids_i, j, v0, normal, time, T_begin=None) -> np.ndarray:
        """Collisions of particles ``ids_i`` with partners ``j`` (ids, or WALL_BASE + wall) at
        impact speeds v0 [m/s] with unit normals (j to i), begun at ``time`` [s]: the plugin's
        heat moved in this order, the totals and the collision log. Returns their OPEN_COLUMNS
        rows. ``T_begin`` (n, 2) [K]: the two temperatures when each began (NaN: as now), where
        something else (a fix heat/gran) changed them since: each collision's temperature
        difference is the one it began with, plus what earlier collisions of this batch moved."""
        i = atoms.index(ids_i)
        wall, jl, mj, _, R_j, _ = self.partners(atoms, i, j)
        mi, R_i = self.materials_of(atoms.type[i]), atoms.radius[i]
        rows = np.arange(len(i))
        models = self.scene.effects.heat_models
        model = models[0] if models else "none"
        moved = e = t_coll = np.zeros(len(rows))
        side = {}
        if self.heat:
            shift = None
            if T_begin is not None:         # (T_i - T_j) then minus now, before this batch
                drift = T_begin - np.column_stack([atoms.T[i], np.where(wall, np.nan, atoms.T[np.where(wall, i, jl)])])
                shift = np.nan_to_num(drift[:, 0]) - np.where(wall, 0.0, np.nan_to_num(drift[:, 1]))
            args = (self.scene.effects.heat_path, self.materials, mi, mj, R_i, R_j, v0, np.ones(len(rows)))
            G, e, t_coll, flagged = evaluate_flagged(model, *args)              # Q per kelvin [J/K]
            if flagged.any():
                self.flag_outside_range(flagged, v0)
            if len(models) > 1:         # side columns: the same collisions at the same dT, nothing moved
                dT = temperature_difference(atoms.T, i, jl, self.T_wall) + (0.0 if shift is None else shift)
                side = {f"Q_{m}": g * dT for m, g in side_heat(models[1:], *args).items()}
            moved, capped, from_walls = exchange_heat(atoms.T, self.C, i, jl, G, self.T_wall, shift)
            self.totals["capped"] += capped
            self.totals["heat_from_walls"] += from_walls
            self.totals["heat_moved"] += float(np.abs(moved[~wall]).sum())
            by_model = self.heat_by_model()
            for m, q in zip(models, [moved] + list(side.values())):
                by_model[m] += float(np.abs(q[~wall]).sum())
        self.totals["collisions"] += len(rows)
        self.totals["particle_wall"] += int(wall.sum())
        self.totals["particle_particle"] += int((~wall).sum())
        self.collisions.write_columns(time=time, i=ids_i, j=np.where(wall, 0, j),
                                      wall=np.where(wall, j - WALL_BASE + 1, 0), v0=v0, Q=moved, e=e,
                                      t_coll=t_coll, model=np.full(len(rows), model), **side)
        return np.column_stack([time, t_coll, e, v0, normal])

    def heat_by_model(self) -> dict:
        """Heat between particles [J], sum of |Q| over collisions, of each heat model: the one
        that moved it and the side models on the same collisions."""
        return self.totals.setdefault("heat_by_model", dict.fromkeys(self.scene.effects.heat_models, 0.0))

    def end_collisions(self, atoms, closed, info) -> None:
        """Contacts gone since the last sample (their keys and OPEN_COLUMNS rows): with
        restitution feedback, the model's e imposed on the pair's normal velocity."""
        if not self.scene.effects.restitution_feedback or not self.heat:
            return
        ids_i = (closed >> 31).astype(np.int64)
        ids_j = (closed & ((1 << 31) - 1)).astype(np.int64)
        self.totals["clipped"] += self.impose_separation(atoms, ids_i, ids_j, info[:, 4:7], info[:, 2], info[:, 3])

    def impose_separation(self, atoms, ids_i, ids_j, normal, e, v0) -> int:
        """The model's separation speed e v0 [m/s] imposed now on each pair's normal velocity
        (particles ``ids_i`` and ``ids_j``, or WALL_BASE + wall: the line of centres, nearest
        image; a wall's ``normal`` as given), momentum conserved; skipped where a particle is
        gone or e is NaN (contacts there at a restart: no collision). Returns how many e above
        1 were clipped."""
        i = atoms.index(ids_i)
        here = (i >= 0) & ~np.isnan(e)
        wall, jl, _, _, _, m_j = self.partners(atoms, np.maximum(i, 0), ids_j)
        here &= wall | (jl >= 0)
        normal = np.array(normal, float)
        jj = np.where(wall, 0, np.maximum(jl, 0))
        d = atoms.x[np.maximum(i, 0)] - atoms.x[jj]
        lo, hi, periodic = self.dem.box()
        d = np.where(periodic, d - (hi - lo) * np.round(d / (hi - lo)), d)
        normal[~wall] = d[~wall] / np.linalg.norm(d[~wall], axis=1)[:, None]
        v_j = np.where(wall[:, None], 0.0, atoms.v[jj])
        dv_i, dv_j, clipped = restitution_impulse(atoms.v[np.maximum(i, 0)], v_j, atoms.mass[np.maximum(i, 0)],
                                                  m_j, normal, e, v0)
        self.dem.add_velocity(i[here], dv_i[here])
        pair = here & ~wall
        if pair.any():
            self.dem.add_velocity(jl[pair], dv_j[pair])
        return clipped

    def undo_heat_gran(self, atoms, c) -> None:
        """The script's fix heat/gran conducts through every contact; during a collision's
        model duration t_coll the collision heat already stands for that time, so what heat/gran
        moved then is taken back: flux at this sample [W] times the part of the sample interval
        inside [start, start + t_coll] (exact when sampling every step)."""
        dt_s = self.every["sample"] * self.dem.dt
        start, t_coll = self.info[:, 0], self.info[:, 1]
        tau = np.clip(start + t_coll - (self.t - dt_s), 0.0, dt_s)
        rows = np.flatnonzero((tau > 0) & (c.j < WALL_BASE))
        if not len(rows):
            return
        i, j = atoms.index(c.i[rows]), atoms.index(c.j[rows])
        q = c.heat_flux[rows] * tau[rows]                   # heat heat/gran moved into i [J]
        np.subtract.at(atoms.T, i, q / self.C[i])
        np.add.at(atoms.T, j, q / self.C[j])
        self.totals["heat_gran_undone"] += float(np.abs(q).sum())

    # -- fluid --------------------------------------------------------------------------
    def couple_fluid(self) -> None:
        """The fluid's force on each particle from the current fluid, then the fluid advanced
        over the next coupling interval with these particles' fraction and drag."""
        atoms = self.dem.atoms(temperature=self.convection)
        lo, hi, periodic = self.dem.box()
        x = np.where(periodic, lo + np.mod(atoms.x - lo, hi - lo), atoms.x)   # the DEM wraps only at re-neighbouring
        interval = self.every["couple"] * self.dem.dt
        forces = self.fluid.particle_forces(x, atoms.v, 2.0 * atoms.radius)
        self.fluid.advance(interval, heat=self.convect(atoms, interval) if self.convection else None)
        self.dem.set_force(forces)
        self.fluid_force = (atoms.id.copy(), forces)

    def convect(self, atoms, interval: float) -> np.ndarray:
        """Gas-particle heat over the coming interval [s] (plugins.convection): each particle's
        Temp takes its share now; returns the heat rate of each cell's gas [W], the opposite,
        for the fluid's advance over the interval."""
        f, name = self.fluid, self.scene.effects.convection
        self.track_particles(atoms)
        d = 2.0 * atoms.radius
        alpha = f.alpha[f.cell]
        re = convection.particle_reynolds(alpha, f.slip, d, f.nu)
        pr = convection.prandtl(f.nu, f.rho, f.cp, f.kappa)
        for key, share in convection.outside(name, re, pr, alpha).items():
            if key not in self.warned:
                self.warned.add(key)
                lo, hi = convection.CORRELATIONS.lookup(name).validity[key]
                print(f"warning: convection '{name}' extrapolated: {share:.1%} of the particles have {key} outside "
                      f"[{lo:g}, {hi:g}] at t = {self.t:g} s")
        G = convection.conductance(name, re, pr, alpha, f.kappa, d)
        q, _ = convection.exchange(atoms.T, self.C, G, f.cell, f.temperature(), f.heat_capacity(), interval)
        atoms.T[:] += q / self.C
        self.totals["heat_convected"] += float(q.sum())
        self.totals["heat_convected_gross"] += float(np.abs(q).sum())
        self.track_particles(atoms)
        return -np.bincount(f.cell, q, len(f.cell_volumes)) / interval

    def bed_state(self, atoms) -> tuple:
        """The fluid columns of history.csv: the superficial inlet velocity [m/s]; the pressure
        drop the particles cause [Pa], mean p of the lowest cell layer less that of the highest,
        less the fluid's own hydrostatic head between them; the bed height [m], twice the mean
        particle centre height above the box floor (exact for a uniform bed)."""
        z = self.fluid.cell_centres[:, 2]
        head = self.fluid.rho * self.fluid.gravity()[2] * (z.max() - z.min())
        floor = self.dem.box()[0][2]
        inlet = math.nan if self.scene.fluid.case else float(self.scene.fluid.inlet_at(self.t))
        return (inlet, layer_pressure_drop(self.fluid) + head,
                2.0 * float(np.mean(atoms.x[:, 2] - floor)) if len(atoms.x) else math.nan)

    def gas_state(self) -> tuple:
        """The gas columns of history.csv: the heat-capacity weighted mean gas temperature [K],
        the gas's heat content rho c alpha V T summed over cells [J]; since the start [J]: the
        heat convected into the particles (net, and the sum of its magnitudes), the heat into
        the gas through the fluid's boundaries, and beside them the heat moved by collisions
        between particles (sum of magnitudes)."""
        C = self.fluid.heat_capacity()
        E = float(np.sum(C * self.fluid.temperature()))
        t = self.totals
        return (E / C.sum(), E, t["heat_convected"], t["heat_convected_gross"], self.fluid.boundary_heat,
                t["heat_moved"])

    # -- output -------------------------------------------------------------------------
    def write_frame(self) -> None:
        tot = self.totals
        atoms = self.dem.atoms(self.heat)
        T = atoms.T if self.heat else np.full(len(atoms.id), np.nan)
        if self.heat:
            self.track_particles(atoms)
        C = self.C if self.heat else np.ones(len(atoms.id))
        group = self.group_of(atoms)
        means = tuple(float(np.sum(C[group == k] * T[group == k]) / max(np.sum(C[group == k]), 1e-300))
                      if np.any(group == k) else math.nan for k in range(len(self.group_names)))
        stats = (float(T.mean()), float(T.min()), float(T.max())) if len(T) else (math.nan,) * 3
        self.history.write([(self.t, len(atoms.id)) + stats + means
                            + (float(np.sum(C * T)), tot["heat_from_walls"], tot["energy_in"], tot["energy_out"],
                               tot["collisions"], tot["capped"], tot["clipped"])
                            + (self.bed_state(atoms) if self.fluid is not None else ())
                            + (self.gas_state() if self.convection else ())])
        if self.frames is not None:
            change = T - self.T_first_by_id[atoms.id] if self.heat else T
            self.frames.write(self.t, atoms.x, id=atoms.id, type=atoms.type, radius=atoms.radius,
                              velocity=atoms.v, temperature=T, temperature_change=change)
        if self.fluid_frames is not None:
            p, u = self.fluid.fields()
            self.fluid_frames.write(self.t, self.fluid.cell_centres, alpha=self.fluid.alpha, velocity=u, pressure=p)

    def flush_events(self) -> None:
        """The contact events recorded since the last harvest, taken now (a run stopped
        between harvests: its checkpoint and summary hold every collision)."""
        if self.events and self.ready and (self.dem.events.waiting or self.dem.events.window):
            atoms = self.dem.atoms(self.heat)
            self.track_particles(atoms)
            self.harvest(atoms, final=True)

    def finish(self, status: str = "completed") -> dict:
        try:                                  # (completed: heat/gran's flux histories still filling)
            self.flush_events()
        except Exception as err:              # the error that stopped the run is the one to report
            if status == "completed":
                raise
            print(f"warning: the collisions since the last harvest are not in the log ({type(err).__name__}: {err})")
        for series in (self.frames, self.fluid_frames):
            if series is not None:
                series.flush()
        self.progress.update(self.t, f", {self.totals['collisions']} collisions", force=True)
        self.heat_by_model()
        summary = dict(self.totals, status=status, time=self.t, steps=self.steps, groups=self.group_names)
        if self.heat:
            atoms = self.dem.atoms(True)
            try:
                self.track_particles(atoms)
            except ScriptError as exc:    # what stopped the run (a type without material): still a summary
                if status == "completed":
                    raise
                summary["energy_balance"] = f"not computed: {exc}"
                return self.write_summary(summary)
            CT = float(np.sum(self.C * atoms.T))
            t = self.totals
            came_in = self.CT0 + t["energy_in"] + abs(t["energy_set_by_script"]) + abs(t["energy_mass_change"])
            residual = (CT - self.CT0 - t["heat_from_walls"] - t["energy_in"] + t["energy_out"]
                        - t["energy_set_by_script"] - t["energy_mass_change"] - t["heat_convected"])   # J
            summary.update(sum_mcT_start=self.CT0, sum_mcT_end=CT,
                           energy_balance_error=residual / max(came_in, 1e-300))             # relative to all that came in
            if self.convection and status == "completed":   # particles and gas; the gas gains through its boundaries
                _, gas, _, _, through, _ = self.gas_state()
                residual += t["heat_convected"] + gas - self.gas_energy0 - through
                summary.update(gas_energy_start=self.gas_energy0, gas_energy_end=gas,
                               heat_through_fluid_boundaries=through,
                               total_energy_balance_error=residual / max(came_in + self.gas_energy0 + abs(through), 1e-300))
        return self.write_summary(summary)

    def write_summary(self, summary: dict) -> dict:
        write_atomic(self.out / "summary.json", json.dumps(summary, indent=1))
        self.collisions.close()
        self.history.close()
        return summary


def run_scene(scene, dem: Dem, commands, out: Path, *, walls_of, fluid=None, end: float | None = None,
              max_time: float | None = None, driven: float | None = None, progress_every: float = 5.0,
              log=print, **particles) -> dict:
    """Run a script's commands on ``dem``; each ``run N`` is N coupled steps (steps beyond
    ``max_time`` [s] of coupled time, for smoke runs, are cut). ``driven`` [s]: how long the
    script's last ``run`` lasts when it asks for 0 steps (a CFD-DEM script whose coupling
    drives the run, as CFDEM's end in ``run 0``). ``walls_of(dem)`` gives the HostWalls once
    the script's walls exist; ``particles``: type_material, groups and initial_T of
    ``Coupling``. Returns the summary, also written when a step fails; a script whose runs
    simulate no step at all is refused (ScriptError) rather than ending as done."""
    coupling = None
    effects = scene.effects_summary()
    resume = particles.get("resume")
    # a script restarted: its set-up replayed up to the run the checkpoint interrupted, that run's
    # steps to go, then the rest as written (a box scene's generated script reads the restart itself)
    restarting = resume is not None and scene.scripted
    restart_from = int(resume["command"]) if restarting else 0
    replayed = 0                        # the replayed set-up's length: commands[replayed] is the run
    if restarting:
        if not 0 <= restart_from < len(commands) or commands[restart_from].name != "run":
            raise ScriptError(f"--restart: the checkpoint's run is command {restart_from} of {scene.path}'s "
                              "script, which is not a run there (the script was changed?)")
        setup = replay(commands, restart_from, resume["restart"])
        commands, replayed = setup + commands[restart_from:], len(setup)
    last_run = max((k for k, c in enumerate(commands) if c.name == "run"), default=-1)
    prepared = None

    def prepare(cmd):
        try:
            added = dem.prepare(heat=effects["particle_temperatures"], contacts=effects["contact_extraction"],
                                fluid_force=fluid is not None,
                                events=scene.time.contacts == "events")
        except LiggghtsError as exc:
            raise LiggghtsError(f"{cmd.where()} (the first run): {exc}") from None
        log("host adds to the script: " + ("; ".join(added) if added else "nothing"))
        return added

    try:
        for k, cmd in enumerate(commands):
            dem.context(cmd)
            if cmd.name != "run":
                dem.command(cmd)
                continue
            run = parse_run(cmd)
            if not dem.dt > 0:
                raise ScriptError(f"{cmd.where()}: the time step is {dem.dt:g} s: give the script a positive "
                                  "'timestep' before its runs")
            if k < replayed:                # a run before the restart's: the host's fixes come at the first
                if prepared is None:
                    prepared = prepare(cmd)
                continue
            if coupling is None:
                if prepared is None:
                    prepared = prepare(cmd)
                elif k == replayed:         # the replayed commands since the host's fixes: set up, then
                    dem.run(0)              # the checkpoint's forces go back (Coupling's restore)
                coupling = Coupling(scene, dem, out, walls=walls_of(dem), fluid=fluid, end=end,
                                    progress_every=progress_every, **particles)
                if scene.scripted:           # a restart replays them: checked unchanged
                    coupling.inputs = tuple(sorted({c.file for c in commands if c.file != "(host)"}))
                coupling.start()
            else:
                coupling.update_walls(walls_of(dem))
                coupling.check_heat_gran()
            coupling.command = k - replayed + restart_from
            if restarting and k == replayed:
                n = int(resume["run_left"])
                log(f"{cmd.where()}: restarted in this run, {n} steps to go")
            else:
                try:
                    n = dem.steps(run.steps, run.upto)
                except ScriptError as exc:
                    raise ScriptError(f"{cmd.where()}: {exc}") from None
            if n == 0 and k == last_run and driven is not None and not (restarting and k == replayed):
                n = round(driven / dem.dt)
                log(f"{cmd.where()}: the script ends in a run of 0 steps, which the coupling drives: "
                    f"{driven:g} s ({n} steps; [time] end, else the fluid case's controlDict endTime)")
            if max_time is not None:
                n = min(n, round(max_time / dem.dt) - coupling.steps)
            if n > 0:
                try:
                    coupling.advance(n)
                except LiggghtsError as exc:      # e.g. "Lost atoms" in a chunk not tried first
                    raise type(exc)(f"{cmd.where()}: {exc}") from None
            dem.report_warnings(cmd)
        if coupling is not None and coupling.steps == 0:
            raise ScriptError(f"{scene.path}: the script's runs simulate no step (its last is "
                              f"{commands[last_run].where()}: '{commands[last_run].text}'); give the steps in "
                              f"the script" + (", or the coupled time as [time] end" if fluid is not None else ""))
    except BaseException as exc:          # keep what was computed: summary of the run so far
        if isinstance(exc, signals.Interrupted) and coupling is not None and coupling.ready \
                and coupling.checkpoint_step != dem.step:   # (not twice at one step)
            try:
                coupling.flush_events()
                checkpoint.write(coupling)
            except Exception as err:      # the stop goes on: summary, engines closed, exit 128 + n
                log(f"warning: no checkpoint at the stop ({type(err).__name__}: {err}); the last one stays")
        if coupling is not None:
            try:
                coupling.finish(status=f"stopped at t = {coupling.t:g} s by {type(exc).__name__}: {exc}")
            except Exception as err:      # the error that stopped the run is the one to report
                log(f"warning: no summary.json ({type(err).__name__}: {err}); collisions.csv and history.csv "
                    "hold the run so far")
        raise
    if coupling is None:
        raise ScriptError(f"{scene.path}: the script has no 'run' command: nothing to simulate")
    return coupling.finish()


def _by_id(ids, values, wanted, missing=None):
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
