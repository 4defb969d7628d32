"""The coupling loop: read this file first.

A scene's DEM is a LIGGGHTS script (the user's, or the box world generated from case.toml),
run command by command by ``run_scene``; each ``run N`` becomes ``Coupling.advance(N)``,
which runs the DEM in chunks and hands the particles to the effects the scene asks for
(``Scene.effects_summary``; one module each in ``pyhost.effects``):

    EnergyBalance   particle temperatures: inserted particles get their material's
                    temperature, departed ones leave the energy balance (when they have one)
    CollisionHeat   every contact that begins is a collision: impact speed, plugin heat,
                    exchange in Temp; the model's restitution at its end if asked; a script's
                    fix heat/gran undone during t_coll (when collisions matter)
    LastingConduction  every conduction.every steps: heat through lasting contacts (after
                    each collision's t_coll) and gas gaps between particles (when asked for)
    FluidExchange   every coupling: fluid force on particles, particles' fraction to the fluid;
                    with convection, gas-particle heat over the interval (with a fluid)
    Frames          every frame: history.csv (each effect adds its columns), VTK

Temperatures live in LIGGGHTS' per-atom ``Temp``: the host reads and writes them there and
keeps no copy. A dry, isothermal scene runs the DEM and the frames only. How a contact is
classified (collision, then enduring) is told in ``pyhost.effects.collisions``.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pyhost import checkpoint, signals
from pyhost.dem_input import script_dem_contacts
from pyhost.effects.balance import EnergyBalance
from pyhost.effects.case_commands import CaseCommands, case_commands
from pyhost.effects.collisions import CollisionHeat
from pyhost.effects.conduction import LastingConduction
from pyhost.effects.fluid import FluidExchange
from pyhost.effects.frames import Frames
from pyhost.effects.probes import Probes
from pyhost.engines.dem import Dem
from pyhost.engines.liggghts import LiggghtsError
from pyhost.failures import InvariantBroken, particles_lost
from pyhost.outdir import write_atomic
from pyhost.output import Progress
from pyhost.script import Program, ScriptError, if_branches, parse_run, replay

HARVEST_EVERY = 1000
"""DEM steps between harvests of the contact events at most (they are also taken at every
frame and checkpoint, and at a fluid exchange that reads temperatures): bounds the
recorder's buffer and the wait of a signal (a stop is taken between two DEM chunks)."""


FRAME_EVERY = 1e-3
"""s between frames where output.every is 0 and the script has no dump (box scenes: always)."""


def totals() -> dict:
    """The run's totals at its start (summary.json): the ``TOTALS`` of every effect that adds
    to them, present in the scene or not (a summary has the same keys whatever the scene)."""
    return {key: value for effect in (CollisionHeat, EnergyBalance, LastingConduction, CaseCommands, FluidExchange)
            for key, value in effect.TOTALS.items()}


@dataclass(frozen=True)
class HostWall:
    """A LIGGGHTS wall as the host sees it: its fix id (and the index of the mesh within a
    mesh wall fix: each mesh is a wall of its own), its real material (index into the
    scene's materials) and its fixed temperature [K] (NaN: adiabatic)."""

    fix: str
    material: int
    temperature: float
    mesh: int = 0


@dataclass(frozen=True)
class Known:
    """What the host knows of each particle before LIGGGHTS holds it, by atom id (a box scene:
    the host placed every particle) or by atom type (a user's script): the group of the
    history's T_group columns (index into ``names``; -1: none; a script's groups are its
    materials, a material with a temperature per type one group per type) and the starting
    temperature [K] (NaN: keep the value LIGGGHTS holds). Tables are indexed by the key; a key
    beyond a table takes its last entry."""

    by: str                 # "id" or "type"
    group: np.ndarray
    T: np.ndarray
    names: tuple

    def of(self, table: np.ndarray, atoms, mask=slice(None)) -> np.ndarray:
        """``table``'s entry (``group`` or ``T``) for each atom (of ``mask``)."""
        return table[np.minimum(getattr(atoms, self.by)[mask], len(table) - 1)]


class Coupling:
    """The coupled run of a scene on a prepared ``Dem``; ``advance(n)`` runs n DEM steps,
    ``finish()`` writes and returns the summary.

    ``type_material``: material index of each atom type (index = type; -1: none);
    ``known``: each particle's group and starting temperature (``Known``);
    ``walls``: the HostWall of every LIGGGHTS wall, in the order of their contact codes.
    The contacts present at the start (overlaps as placed, a script's read_restart of a
    settled bed) are not collisions: open and enduring.
    ``resume``: a checkpoint's state (pyhost.checkpoint) to continue from, its logs appended to.
    ``driven`` [s]: the coupled time of a CFD-DEM script's last run (its case's last coupling step).
    """

    def __init__(self, scene, dem: Dem, out: Path, *, type_material, known: Known, walls, fluid=None,
                 end: float | None = None, progress_every: float = 5.0, resume: dict | None = None,
                 driven: float | None = None):
        self.scene, self.dem, self.out, self.fluid = scene, dem, Path(out), fluid
        self.effects = scene.effects_summary()
        self.materials = script_dem_contacts(scene, dem) if scene.scripted else list(scene.materials.values())
        self.type_material = np.asarray(type_material, int)
        self.known = known
        self.keep_all = known.group if known.by == "id" else None   # box scenes: losing any particle fails
        self.before = None               # box scenes: (time, step, particles) before the chunk under way
        self.capacity = np.array([m.heat_capacity for m in self.materials])
        self.clock = (0.0, 0, dem.dt)      # (t, step, dt): the time of LIGGGHTS' step s is t + (s - step) dt
        self.t = self.time_of(dem.step)     # the simulated time [s]: each step's time step summed
        self.t_step = dem.step              # the step LIGGGHTS numbers at time t
        self.t_begin = self.t               # the time at the start of the coupled run
        self.steps = 0                      # the coupled steps so far (whatever LIGGGHTS numbers them)
        self.totals = totals()            # summary.json's, every effect's whether the scene has it or not
        self.warned = set()
        self.heat = self.effects["particle_temperatures"]
        logs = resume["logs"] if resume else {}
        # the effects the scene asks for, in the order they act
        self.balance = EnergyBalance(self) if self.heat else None
        self.collisions = CollisionHeat(self, walls, logs) if self.effects["contact_extraction"] else None
        self.conduction = LastingConduction(self, walls) if self.effects["conduction"] else None
        self.check_heat_gran()
        if resume is None and self.balance is not None:
            self.balance.begin(dem.atoms(True))
        self.fluid_exchange = FluidExchange(self, fluid, logs) if fluid is not None else None
        self.frames = Frames(self, [self.fluid_exchange] if fluid is not None else [], logs)
        self.probes = Probes(self, logs) if scene.output.probes else None
        self.progress = Progress(end or math.inf, progress_every)
        events = self.collisions is not None
        self.every = dict(harvest=(scene.time.sample_every if self.collisions.restitution else HARVEST_EVERY)
                          if events else 0,
                          frame=0,                    # (set just below, and at each run of a script)
                          couple=scene.time.couple_every if fluid is not None else 0,
                          conduct=scene.conduction.every if self.conduction is not None else 0,
                          checkpoint=round(scene.output.checkpoint / dem.dt) if scene.output.checkpoint else 0)
        self.every["frame"] = self.frame_every()
        self.case_commands = (case_commands(self, driven) if fluid is not None and scene.fluid.case  # a user's case's:
                              else None)                  # after the DEM's steps, before the fluid's exchange
        self.effect_list = [e for e in (self.balance, self.collisions, self.conduction, self.case_commands,
                                        self.fluid_exchange, self.frames, self.probes) if e is not None]
        if events:                           # the walls' contacts now are open ones: one that begins at
            dem.events.sync()                # the next step is a collision (prepare's set-up left the lists)
        self.program, self.run_left = None, 0  # the script's input loop (Program: where it stands at the run
                                               # under way, kept by a checkpoint), the run's steps to go
        self.inputs = {}                     # SHA-256 of each file the run read, at its start (a restart checks them)
        self.extend = 0.0                    # run --extend [s] (a checkpoint keeps it)
        self.ready = resume is not None      # a consistent state to checkpoint (after start())
        self.resumed = resume is not None    # the next advance continues the checkpoint's run
        self.checkpoint_step = -1            # the coupled steps (``steps``) at the last checkpoint written
        if resume is not None:
            self.restore(resume)

    # -- what the effects share ---------------------------------------------------------
    @property
    def C(self) -> np.ndarray:
        """m c [J/K] of the atoms last tracked, in their order (particle temperatures only)."""
        return self.balance.C

    def track_particles(self, atoms, departures: bool = True) -> None:
        """The energy balance brought up to date with these atoms (``EnergyBalance.track``)."""
        if self.balance is not None:
            self.balance.track(atoms, departures)

    def materials_of(self, types) -> np.ndarray:
        types = np.asarray(types)
        mat = np.where(types < len(self.type_material), self.type_material[np.minimum(types, len(self.type_material) - 1)], -1)
        if (mat < 0).any():
            bad = sorted(set(types[mat < 0].tolist()))
            raise ScriptError(f"{self.scene.path}: atom type(s) {bad} have no material: name them in a "
                              "[materials.NAME] types = [...] list")
        return mat

    def update_walls(self, walls) -> None:
        """The LIGGGHTS walls as the host sees them (a script may add walls between runs)."""
        if self.collisions is not None:
            self.collisions.update_walls(walls)
        if self.conduction is not None:
            self.conduction.update_walls(walls)

    def check_heat_gran(self) -> None:
        """At each of a script's runs: its fix heat/gran checked against the scene."""
        if self.balance is not None:
            self.balance.check_heat_gran()

    # -- the loop -----------------------------------------------------------------------
    def start(self) -> None:
        """The effects' start (the first fluid exchange) and the first frame (after
        construction, so that an interrupt from here on finds a coupling to write its summary)."""
        if self.ready:                    # resumed: the checkpoint's state is all there is
            return
        for effect in self.effect_list:
            effect.start()
        self.write_frame()
        self.ready = True

    def advance(self, n: int) -> None:
        """n coupled DEM steps: the loop of the module doc. With checkpoints, a signal stops it
        only at the end of a step, where the state is whole (``signals.deferred``), and a
        checkpoint is written there (``run_scene``), periodic checkpoints asked for or not."""
        with signals.deferred():
            self._advance(n)

    def time_of(self, step) -> float:
        """The simulated time [s] of LIGGGHTS' step number ``step`` of the run under way."""
        t, at, dt = self.clock
        return t + (step - at) * dt

    def _advance(self, n: int) -> None:
        if self.heat and not self.resumed:  # (a restart continues a run: no script command came in between)
            self.balance.resync()
        self.resumed = False
        self.run_left = n
        if (self.dem.dt, self.dem.step) != (self.clock[2], self.t_step):
            # a 'timestep' or 'reset_timestep' since the last run: time goes on from where it was,
            # at the new step size, whatever LIGGGHTS numbers the steps (its own time, update's
            # atime, goes back at a reset_timestep and ignores a timestep change)
            self.clock = (self.t, self.dem.step, self.dem.dt)
            self.t_step = self.dem.step
        self.every["frame"] = self.frame_every()   # (a script's dumps and time step as they are now)
        if self.scene.output.checkpoint:
            self.every["checkpoint"] = round(self.scene.output.checkpoint / self.dem.dt)
        while n > 0:
            step = self.steps
            chunk = min([n] + [k - step % k for k in self.every.values() if k])
            if self.keep_all is not None and (self.before is None or self.before[1] != self.dem.step):
                self.before = (self.t, self.dem.step, self.dem.keep_snapshot())
            self.dem.run(chunk)
            if self.keep_all is not None and self.dem.count() < self.before[2]:
                self.lost()
            n -= chunk
            self.run_left = n
            self.steps += chunk
            step += chunk
            self.t, self.t_step = self.time_of(self.dem.step), self.dem.step
            due = {name: k and step % k == 0 for name, k in self.every.items()}
            if self.collisions is not None:
                self.collisions.after_chunk(due)
            if due["conduct"]:
                self.conduction.conduct()
            if due["couple"]:
                for effect in self.effect_list:
                    effect.couple()
            if due["frame"]:
                self.write_frame()
            if due["checkpoint"]:
                checkpoint.write(self)
            self.progress.update(self.t, f", {self.totals['collisions']} collisions")
            signals.check()
        if self.fluid_exchange is not None:     # the last advance, if it ran beside the DEM: a failure
            self.fluid_exchange.fluid.wait()    # in it stops this run like any other (summary, exit 3)
        if self.heat or self.collisions is not None:
            atoms = self.dem.atoms(self.heat)
            self.track_particles(atoms)
            if self.collisions is not None:
                self.collisions.end_of_run(atoms)
        if self.conduction is not None:       # the run's steps since the last update
            self.conduction.conduct()

    def frame_every(self) -> int:
        """DEM steps between frames: output.every, or where it is 0 the interval of the
        script's most frequent dump as defined now (frames at the steps of its dumps), else
        FRAME_EVERY seconds. A script's run says it when it differs from ``every["frame"]``."""
        every = self.scene.output.every
        dumps = self.dem.dump_every() if every == 0 and self.scene.scripted else 0
        n = dumps or max(1, round((every or FRAME_EVERY) / self.dem.dt))
        if self.scene.scripted and n != self.every["frame"]:
            source = ("output.every" if every else "the script's most frequent dump" if dumps
                      else "the default: no dump in the script")
            print(f"frames and history rows every {n} steps ({n * self.dem.dt:.4g} s; {source})")
        return n

    def lost(self):
        """A box scene lost particles (through an open face, a soft wall, or blown out): a
        report from each rank's copy of its particles before the chunk (``Dem.keep_snapshot``)."""
        ids, x, v = self.dem.snapshot()
        gone = np.setdiff1d(ids, self.dem.atoms(False).id)
        raise particles_lost(self.scene, gone, (self.before[0], ids, x, v), self.time_of(self.dem.step), self.keep_all)

    def write_frame(self) -> None:
        for effect in self.effect_list:
            effect.frame()

    def flush_events(self) -> None:
        """The contact events recorded since the last harvest, taken now (a run stopped
        between harvests: its checkpoint and summary hold every collision)."""
        if self.collisions is not None:
            self.collisions.flush_events()

    # -- checkpoint (pyhost.checkpoint writes and reads the files) ---------------------------
    def state(self) -> tuple[dict, dict]:
        """The host's state at the end of a step: (JSON values, arrays), the loop's and each
        effect's."""
        for effect in self.effect_list:    # every frame a log names on disk
            effect.flush()
        values = dict(clock=self.clock, t_step=self.t_step, t_begin=self.t_begin, steps=self.steps, t=self.t,
                      totals=self.totals, warned=sorted(self.warned), run_left=self.run_left,
                      program=self.program.state() if self.program else {},
                      mesh_motion=self.dem.mesh_motion_times(), randoms=self.dem.random_states(),
                      insertions=self.dem.insertion_progress())
        arrays, logs = {}, {}
        for effect in self.effect_list:
            v, a = effect.state()
            logs.update(v.pop("logs", {}))
            values.update(v)
            arrays.update(a)
        values["logs"] = logs
        return values, arrays

    def restore(self, state: dict) -> None:
        """Continue from ``state`` (values and arrays of :meth:`state` in one dict)."""
        self.steps, self.t = state["steps"], state["t"]
        self.clock = tuple(state["clock"])
        self.t_step, self.t_begin = state["t_step"], state["t_begin"]
        self.totals = dict(totals(), **state["totals"])    # (a total newer than the checkpoint starts at 0)
        self.warned = set(state["warned"])
        checkpoint.restore_forces(self.dem, state)
        self.dem.set_mesh_motion_times(state.get("mesh_motion", {}))
        self.dem.set_random_states(state.get("randoms", {}))
        self.dem.set_insertion_progress(state.get("insertions", {}))
        for effect in self.effect_list:
            effect.restore(state)

    # -- the end ------------------------------------------------------------------------
    def finish(self, status: str = "completed") -> dict:
        try:                                  # (completed: heat/gran's flux histories still filling)
            self.flush_events()
        except Exception as err:              # the error that stopped the run is the one to report
            if status == "completed":
                raise
            print(f"warning: the collisions since the last harvest are not in the log ({type(err).__name__}: {err})")
        if status == "completed" and self.frames.last_step != self.steps:
            self.write_frame()                # the end's state in history.csv and the VTK series
        for effect in self.effect_list:      # (the fluid: its last advance, if it runs beside the DEM)
            try:
                effect.flush()
            except Exception as err:
                if status == "completed":
                    raise
                print(f"warning: {type(err).__name__} at the end of a run that stopped: {err}")
        self.progress.update(self.t, f", {self.totals['collisions']} collisions", force=True)
        if self.totals["heat_by_model"] is None:      # (a scene without collisions: each model's 0 J)
            self.totals["heat_by_model"] = dict.fromkeys(self.scene.effects.heat_models, 0.0)
        summary = dict(self.totals, status=status, time=self.t, steps=self.steps, step=self.dem.step, groups=self.frames.group_names)
        for effect in self.effect_list:
            effect.finish(summary, status)
        write_atomic(self.out / "summary.json", json.dumps(summary, indent=1))
        for effect in self.effect_list:
            effect.close()
        broken = [e.failure for e in self.effect_list if e.failure]
        if broken:                            # (the results are on disk: now exit 3, no exit 0)
            raise InvariantBroken("; ".join(broken))
        return summary


def run_scene(scene, dem: Dem, commands, out: Path, *, walls_of, script: Path, fluid=None, end: float | None = None,
              max_time: float | None = None, driven: float | None = None, extend: float = 0.0,
              progress_every: float = 5.0, log=print, inputs: dict | None = None, **particles) -> dict:
    """Run the script ``script`` on ``dem`` as LIGGGHTS' input loop runs it (``Program``: includes,
    labels and jumps, loops with ``next``, ``if`` branches and ``run ... every``, ``quit``);
    ``commands`` are its commands as read and checked (``read_script``). Each ``run N`` is N
    coupled steps (steps beyond ``max_time`` [s] of coupled time, for smoke runs, are cut).
    ``driven`` [s]: how long the script's last ``run`` lasts when it asks for 0 steps (a CFD-DEM
    script whose coupling drives the run, as CFDEM's end in ``run 0``); in a CFDEM script (``fix
    couple/cfd``) the last run's own steps come first, as CFDEM runs them before its coupling.
    ``extend`` [s]: how much longer than written the script's last run goes on (``run
    --extend``, a restart's; a box scene's end comes extended). The last run is the script's
    last ``run`` command when no ``jump`` follows it. With ``output.checkpoint`` a completed run
    ends in a checkpoint, from which ``--extend`` goes on. ``inputs``: the SHA-256 of each file
    the run reads, taken at its start (``checkpoint.fingerprints``), which its checkpoints keep.
    ``walls_of(dem)`` gives the HostWalls
    once the script's walls exist; ``particles``: type_material, known and resume of
    ``Coupling``. Returns the summary, also written when a step fails; a script whose runs
    simulate no step at all is refused (ScriptError) rather than ending as done."""
    coupling = None
    effects = scene.effects_summary()
    resume = particles.get("resume")
    # a script restarted: the commands it ran replayed up to the run the checkpoint interrupted (its
    # set-up), that run's steps to go, then the script on from where its input loop stood (a box
    # scene's generated script reads the restart itself)
    restarting = resume is not None and scene.scripted
    queue = []                          # (command, "replayed" | "interrupted") before the program's own
    if restarting:
        if "program" not in resume:
            raise ScriptError("--restart: the checkpoint was written by an older version of the host (it does not "
                              "say where the script's input loop stood): start the run anew")
        program = Program.restore(resume["program"], scene.folder)
        trace = program.trace
        if not trace or trace[-1].name != "run":
            raise ScriptError(f"--restart: the checkpoint's last command of {scene.path}'s script is not a run")
        queue = [(c, "replayed") for c in replay(trace, len(trace) - 1, resume["restart"])]
        queue.append((trace[-1], "interrupted"))
    else:
        program = Program(script, scene.folder)
    at = max((k for k, c in enumerate(commands) if c.name == "run"), default=-1)
    last_run = commands[at] if at >= 0 else None
    final_run = last_run if not any(c.name == "jump" for c in commands[at + 1:]) else None
    if extend and final_run is None and scene.scripted:
        raise ScriptError(f"--extend: {scene.path}'s script jumps back after its last run command, so the host "
                          "cannot tell which run is the last to extend")
    # CFDEM runs a script whole (its last run too: often 'run 1'), then its coupling drives the DEM
    cfdem = any(c.name == "fix" and c.words[3:4] == ["couple/cfd"] for c in commands)
    prepared = None
    held = []                           # the reset_timestep commands right before the first run

    def prepare(cmd):
        try:
            added = dem.prepare(heat=effects["particle_temperatures"], contacts=effects["contact_extraction"],
                                fluid_force=fluid is not None, then=held)
        except (LiggghtsError, ScriptError) as exc:
            raise type(exc)(f"{refused_at(cmd, exc)} (the first run): {exc}") from None
        log("host adds to the script: " + ("; ".join(added) if added else "nothing")
            + (f" (before {held[0].where()}'s reset_timestep: LIGGGHTS takes no new fix between a restart's "
               "reset_timestep and its run)" if added and held else ""))
        return added

    def refused_at(cmd, exc, when="set-up") -> str:
        """Where a run's error is: the script's fix that LIGGGHTS' message names, refused in
        this run's set-up or steps (LIGGGHTS checks a fix's values then, not at its line), else
        the run."""
        fix = dem.info.fix_named(str(exc))
        return cmd.where() if fix is None else f"{fix.where()} ('{fix.text[:80]}', refused at {cmd.where()}'s {when})"

    def take():
        """The next command and how it comes: replayed, the interrupted run, or the script's own (None)."""
        if queue:
            return queue.pop(0)
        return program.take(), None

    def plain(cmd, how) -> list:
        """``cmd`` and the plain commands that follow it (taken), up to the next run, if, jump or
        include; the reset_timesteps that end them before the first run held for ``prepare``."""
        if how is None:
            batch = [cmd] + program.plain_ahead()
            for _ in batch[1:]:
                program.take()
            after = program.peek()
        else:
            batch = [cmd]
            while queue and queue[0][0].name != "run":
                batch.append(queue.pop(0)[0])
            after = queue[0][0] if queue else None
        cut = len(batch)
        while prepared is None and after is not None and after.name == "run" and cut > 0 \
                and batch[cut - 1].name == "reset_timestep":
            cut -= 1                    # the host's fixes go in before them (prepare)
        held[:] = batch[cut:]
        return batch[:cut]

    try:
        while True:
            cmd, how = take()
            if cmd is None:
                break
            if cmd.name == "if":        # (the program's own only: a trace holds the branch taken)
                conditions, branches = if_branches(cmd)
                dem.context(cmd)
                try:
                    k = dem.branch(conditions)
                except LiggghtsError as exc:
                    raise LiggghtsError(f"{cmd.where()}: {exc}") from None
                program.push(cmd, branches[k])
                continue
            if cmd.name != "run":
                batch = plain(cmd, how)
                dem.commands(batch)
                if how is None:
                    program.trace += batch + held
                if any(c.name == "next" for c in batch):
                    skip = dem.jump_skipped()
                    if how is None:     # (replayed: the checkpoint says where the loop stood)
                        program.skip_jump = program.skip_jump or skip
                continue
            dem.context(cmd)
            run = parse_run(cmd)
            if not dem.dt > 0:
                raise ScriptError(f"{cmd.where()}: the time step is {dem.dt:g} s: give the script a positive "
                                  "'timestep' before its runs")
            if run.every is not None and how is None:    # chunks of M steps, the commands after each
                try:
                    n, m = dem.steps(run.steps, run.upto), dem.steps(run.every, False)
                except ScriptError as exc:
                    raise ScriptError(f"{cmd.where()}: {exc}") from None
                if m <= 0 or n % m:
                    raise ScriptError(f"{cmd.where()}: run {n} every {m}: {n} steps are not a whole number of "
                                      f"chunks of {m} (LIGGGHTS: 'Invalid run command N value')")
                program.push(cmd, [c for k in range(n // m)        # (pre no: LIGGGHTS sets up the first only)
                                   for c in [f"run {m}" + ("" if run.pre or k == 0 else " pre no"), *run.then]])
                continue
            if how == "replayed":       # a run before the restart's: the host's fixes come at the first
                if prepared is None:
                    prepared = prepare(cmd)
                continue
            if how is None:
                program.trace.append(cmd)
            if coupling is None:
                if prepared is None:
                    prepared = prepare(cmd)
                elif how == "interrupted":  # the replayed commands since the host's fixes: set up, then
                    dem.run(0)              # the checkpoint's forces go back (Coupling's restore)
                coupling = Coupling(scene, dem, out, walls=walls_of(dem), fluid=fluid, end=end,
                                    progress_every=progress_every, driven=driven, **particles)
                coupling.inputs = inputs or {}
                coupling.extend = extend
                coupling.start()
            else:
                coupling.update_walls(walls_of(dem))
                coupling.check_heat_gran()
            coupling.program = program
            if how == "interrupted":
                n = int(resume["run_left"])
                log(f"{cmd.where()}: restarted in this run, {n} steps to go")
            else:
                try:
                    n = dem.steps(run.steps, run.upto)
                except ScriptError as exc:
                    raise ScriptError(f"{cmd.where()}: {exc}") from None
            last = cmd == final_run and run.every is None
            if last and driven is not None and (n == 0 or cfdem) and how != "interrupted":
                more = round(driven / dem.dt)
                log(f"{cmd.where()}: " + ("the script ends in a run of 0 steps, which the coupling drives" if n == 0
                    else f"a CFDEM script (fix couple/cfd): its last run's {n} steps, then the coupling drives")
                    + f": {driven:g} s ({more} steps; [time] end, else the fluid case's controlDict endTime)")
                n += more
            if last and scene.scripted and extend:
                more = round((extend - resume["extend"] if how == "interrupted" else extend) / dem.dt)
                n += more
                if more:
                    log(f"{cmd.where()}: --extend {extend:g}: {more} steps more than the case asks")
            if max_time is not None:
                n = min(n, round((max_time - (coupling.t - coupling.t_begin)) / dem.dt))
            if run.pre and how != "interrupted" and not (resume is not None and not scene.scripted):
                dem.set_up_next()       # (not the run a restart continues: from the checkpoint's forces)
            if n > 0:
                try:
                    coupling.advance(n)
                except LiggghtsError as exc:      # e.g. "Lost atoms" in a chunk not tried first
                    raise type(exc)(f"{refused_at(cmd, exc, 'run')}: {exc}") from None
            dem.report_warnings(cmd)
        if coupling is not None and coupling.steps == 0:
            raise ScriptError(f"{scene.path}: the script's runs simulate no step (its last is "
                              f"{last_run.where()}: '{last_run.text}'); give the steps in "
                              f"the script" + (", or the coupled time as [time] end" if fluid is not None else ""))
        if coupling is not None and scene.output.checkpoint:    # a completed run ends in a checkpoint, marked
            if coupling.checkpoint_step != coupling.steps:       # so: --extend goes on from there
                coupling.flush_events()
                checkpoint.write(coupling)
            checkpoint.mark_complete(out)
    except BaseException as exc:          # keep what was computed: summary of the run so far
        if isinstance(exc, signals.Interrupted) and coupling is not None and coupling.ready \
                and coupling.checkpoint_step != coupling.steps:   # (not twice at one step)
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
    if scene.frozen.end > 0:                  # the bed frozen where the runs left it: heat alone
        from pyhost.frozen import frozen_stage
        frozen_stage(coupling, log=log)
    return coupling.finish()
