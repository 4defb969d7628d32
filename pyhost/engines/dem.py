"""The DEM of a scene on the LIGGGHTS bridge (``pyhost.engines.liggghts``): a LIGGGHTS script run
command by command, either the user's own (``[dem] script``) or the box world the host
generates from the scene (``pyhost.engines.liggghts.box_input``). Both go through the same class.

What the coupling loop gets from it, each in LIGGGHTS' local order and valid until the next
``run``: ``atoms()`` (ids, positions, velocities, radii, masses, types and the writable
``Temp`` of every particle) and ``events`` (the contacts begun and ended at every step,
recorded inside LIGGGHTS: ``pyhost.engines.events``). Temperatures live in LIGGGHTS'
per-atom ``Temp`` (the property ``fix heat/gran`` uses), so a script's dumps, restarts and
fixes see them. What the host adds to a script it prints once, before the first run.

Under mpirun (``link``, :mod:`pyhost.engines.ranks`) LIGGGHTS runs on every rank and this
class on rank 0 orders the other ranks' part of each collective call. ``atoms()`` is then a
gathered copy of all ranks' atoms; what the loop writes into its ``T`` and ``v`` (and
``add_velocity``) goes back to the owning ranks at the next call into LIGGGHTS. Serially
the arrays are LIGGGHTS' own memory and nothing needs to go back.
"""
from __future__ import annotations

import errno
import os
from pathlib import Path

import numpy as np

from pyhost.collisions import wall_code
from pyhost.engines.atoms import Atoms, local_view
from pyhost.engines.liggghts import Liggghts, LiggghtsError
from pyhost.engines.collective import collective
from pyhost.engines.ranks import (ENGINE, gather_arrays, local_atoms, local_atoms_of, local_random_states,
                                  local_snapshot, local_values, put_by_id, set_random_states, write_local)
from pyhost.engines.liggghts.script import Command, ScriptError, ScriptInfo, output_files

FLUID_FIX = "collheat_fluid"
HEAT_GRAN_WINDOW = 200
"""DEM steps of a fix heat/gran's flux the event recorder keeps per new pair contact: what
heat/gran moved during a collision's model duration t_coll is taken back from them, so
t_coll up to this many steps is taken back whole (a longer one: its first 200 steps, counted
as heat_gran_undo_cut)."""


def refusal_hint(cmd: Command, message: str) -> str:
    """What a user of a CFDEM tutorial does about LIGGGHTS' refusal of a ``read_restart`` of
    the file the tutorial's first stage writes (docs/tutorials.md), appended to the refusal."""
    w = cmd.words
    if w[0] == "read_restart" and "Cannot open restart file" in message:
        first = sorted(p.name for p in Path(cmd.file).parent.glob("in.*init*"))
        if first:
            return (f" (a CFDEM tutorial writes it in its first stage, plain LIGGGHTS: run 'liggghts -in {first[0]}' "
                    f"in {Path(cmd.file).parent.resolve()} first)")
    return ""


class Dem:
    """LIGGGHTS running a scene's script. ``walls``: the host's walls in order, each
    (fix id, material name or None for adiabatic LIGGGHTS walls the scene does not name)."""

    def __init__(self, workdir: Path, *, variables: dict | None = None, log=print, link=None):
        self.link = link
        if link is not None:
            link.order("open", os.getcwd(), str(Path(workdir).resolve()), variables)
        self.lmp = Liggghts(Path(workdir).resolve(), variables=variables, comm=link and link.comm)
        self.info = ScriptInfo()
        self.log = log
        self.events = None        # the contact event recorder (pyhost.engines.events), if asked for
        self.heat = False         # whether the particles have temperatures (prepare)
        self._warnings = set()    # LIGGGHTS warnings already shown
        self._pending = None      # under MPI: the last gathered atoms, their T and v as gathered
        self._counts = None       # under MPI: atoms per rank in the last gather
        self._rows = None         # under MPI: rank 0's local indices sent in the last gather (None: all)

    def _order(self, name: str, *args) -> None:
        """Under MPI: what the host changed goes back to the ranks, then the followers make
        the same call as rank 0 is about to."""
        if self.link is not None:
            self._commit()
            self.link.order(name, *args)

    @collective
    def _raw(self, line: str) -> None:
        self._order("command", line)
        self.lmp.command(line)
        self._pending = None            # a command may move, add or delete atoms

    def close(self) -> None:
        if self.link is not None:
            self.link.close()
        if self.events is not None:
            self.events.close()
        self.lmp.close()

    # -- the script -----------------------------------------------------------------
    def make_folders(self, cmd: Command) -> None:
        """The folder of each file the command opens, made if missing: LIGGGHTS refuses a fix
        print into a folder nobody made ('Cannot open fix print file'), as CFDEM's
        settlingTestMPI does into DEM/post, which CFDEM's repository does not have."""
        for name in output_files(cmd):
            folder = Path(name).parent
            if "$" not in str(folder) and not folder.is_dir():
                folder.mkdir(parents=True)
                self.log(f"made the folder {folder.resolve()} for {name} ({cmd.where()}): LIGGGHTS does not make it")

    def foreign_grid(self, cmd: Command) -> bool:
        """Whether a command is a ``processors Px Py Pz`` for another number of ranks than this
        run has (CFDEM's tutorials ask for 4 and 2): LIGGGHTS would refuse it ('Specified
        processors != physical processors'), and it only divides the box among the ranks, the
        same physics on any grid, so the host leaves it out and says so."""
        w = cmd.words
        if w[0] != "processors" or len(w) < 4 or not all(x.isdigit() for x in w[1:4]):
            return False
        n, ranks = int(w[1]) * int(w[2]) * int(w[3]), 1 if self.link is None else self.link.size
        if n == ranks:
            return False
        self.log(f"{cmd.where()}: '{cmd.text}' is a grid of {n} ranks and this run has {ranks}: left out (it only "
                 f"divides the box among the ranks, and LIGGGHTS divides it itself); run under 'mpirun -np {n}' to "
                 "keep it")
        return True

    def command(self, cmd: Command) -> None:
        """Run one script command; a refusal names the script's file and line."""
        self.check_temperature_set(cmd)
        try:
            self._raw(cmd.text)
        except LiggghtsError as exc:
            raise LiggghtsError(f"{cmd.where()}: {exc}{refusal_hint(cmd, str(exc))}") from None
        self.info.learn(cmd)
        if cmd.name == "timestep" and not self.dt > 0:     # LIGGGHTS takes it; every run would then stand still
            raise ScriptError(f"{cmd.where()}: '{cmd.text}': the time step is {self.dt:g} s: give the script a "
                              "positive 'timestep'")
        self.report_warnings(cmd)

    def check_temperature_set(self, cmd: Command) -> None:
        """A ``set ... property/atom Temp VALUE`` at or below 0 K is refused before it runs,
        naming the script's line (LIGGGHTS takes it; the heat models, the energy balance and
        a particle's start, refused at 0 K, need kelvins above 0). A per-atom ``v_name`` is
        left to the check of the particles' start."""
        w = cmd.words
        if not (w and w[0] == "set" and "property/atom" in w[:-2] and w[w.index("property/atom") + 1] == "Temp"):
            return
        word = w[w.index("property/atom") + 2]
        if word.startswith("v_"):
            return
        try:
            T = self.value(word)
        except ScriptError:
            return                      # LIGGGHTS' own refusal of the command names it
        if not T > 0:
            raise ScriptError(f"{cmd.where()}: '{cmd.text}': {T:g} K: temperatures must be above 0 K")

    def commands(self, cmds: list[Command]) -> None:
        """The script's commands up to its next ``run`` (none of them a run), in order. A serial
        run tries them together first in one forked copy (each is otherwise tried alone: see
        ``Liggghts.try_ahead``), the folders of the files they open made first; a refusal names
        the script's file and line."""
        cmds = [cmd for cmd in cmds if not self.foreign_grid(cmd)]
        for cmd in cmds:
            self.make_folders(cmd)
        if self.link is None:
            self.lmp.try_ahead([c.text for c in cmds])
        for cmd in cmds:
            self.context(cmd)
            self.command(cmd)

    def context(self, cmd: Command) -> None:
        """The script command under way, on every rank: named if LIGGGHTS ends the process
        (an error of one rank alone under MPI, which cannot return)."""
        text = f"{cmd.where()} ({cmd.text[:200]})"
        if self.link is not None:
            self._order("context", text)
        self.lmp.context(text)

    def report_warnings(self, cmd: Command | None = None) -> None:
        """LIGGGHTS' own warnings since the last report, on screen once each (they used to stay
        in OUT/dem/log.liggghts): after each script command and each script run."""
        for line in self.lmp.new_warnings():
            if line not in self._warnings:
                self._warnings.add(line)
                where = f" (after {cmd.where()})" if cmd is not None else ""
                self.log(f"LIGGGHTS {line}{where}; each warning is shown once, all are in {self.lmp.log}")

    @collective
    def value(self, text: str) -> float:
        """A number of the script as LIGGGHTS evaluates it (a plain number or a $variable);
        ScriptError with LIGGGHTS' message if it cannot."""
        try:
            return float(text)
        except ValueError:
            pass
        try:
            self._raw(f"variable collheat_value equal {text}")
            # evaluated inside a tried command, so that a bad expression (run ${word}) is an
            # error naming the script's line, not the end of the process
            self._raw("variable collheat_checked equal ${collheat_value}")
        except LiggghtsError as exc:
            raise ScriptError(str(exc)) from None
        self._order("variable", "collheat_value")
        return self.lmp.variable("collheat_value")

    @collective
    def branch(self, conditions: list[str]) -> int:
        """Which branch of a script's ``if`` LIGGGHTS takes now: the index of the first of the
        ``conditions`` (as written) that holds, ``len(conditions)`` (the else) if none. LIGGGHTS
        evaluates them itself, in an ``if`` of the same conditions whose branches only say which
        they are; LiggghtsError with its message if it cannot."""
        def quoted(text: str) -> str:
            return f"'{text}'" if '"' in text else f'"{text}"'

        probe = (f"if {quoted(conditions[0])} then \"variable collheat_branch equal 0\""
                 + "".join(f" elif {quoted(c)} \"variable collheat_branch equal {k}\""
                           for k, c in enumerate(conditions[1:], 1))
                 + f" else \"variable collheat_branch equal {len(conditions)}\"")
        self._raw(probe)
        self._order("variable", "collheat_branch")
        return int(self.lmp.variable("collheat_branch"))

    def jump_skipped(self) -> bool:
        """Whether a ``next`` since the last call exhausted its variable: LIGGGHTS would skip the
        script's next ``jump`` (rank 0's LIGGGHTS: every rank ran the same ``next``)."""
        return self.lmp.take_jump_skip()

    @collective
    def steps(self, steps: str, upto: bool) -> int:
        """The number of steps of a ``run`` (a number or a $variable, evaluated by LIGGGHTS)."""
        try:
            value = float(int(steps))
        except ValueError:
            try:
                value = self.value(steps)
            except ScriptError as exc:
                raise ScriptError(f"run {steps}: {exc}") from None
        # LIGGGHTS' own rules for 'run N [upto]' (its run.cpp): a whole N, 0 <= N < 2^31, and an
        # upto step not before the current one
        if value != int(value):
            raise ScriptError(f"run {steps}: {value:g} is not a whole number of steps (LIGGGHTS: 'Expected integer')")
        n = int(value) - (self.lmp.step if upto else 0)
        if not 0 <= n <= 2**31 - 1:
            why = (f"step {int(value)} is before the current step {self.lmp.step}" if upto and n < 0 else
                   f"{n} steps is outside 0 .. 2^31 - 1")
            raise ScriptError(f"run {steps}{' upto' if upto else ''}: {why} (LIGGGHTS: 'Invalid run command')")
        return n

    def prepare(self, heat: bool, contacts: bool | None = None, fluid_force: bool = False,
                then=()) -> list[str]:
        """What the host adds before the first run: the Temp property (if no fix heat/gran or
        property/atom Temp made it), the contact event recorder's fix and the fluid force;
        then the script's commands ``then`` (its reset_timestep right before the first run:
        after a read_restart LIGGGHTS refuses a new fix between the two) and the run's set-up.
        ``contacts``: whether the loop needs the contacts (default: with heat). Returns the
        added commands (printed once)."""
        from pyhost.engines.events import fix_command

        units, style, spheres = self.lmp.styles()
        if units != "si":       # (a read_restart brings its file's units, a script without any LIGGGHTS' lj)
            raise ScriptError(f"the script runs in LIGGGHTS' units {units}: the host's contact models, heat and "
                              "energy balance are in SI; give 'units si' before the box (and the script's values "
                              "in SI)")
        if not spheres:         # (the contact recorder and every effect read each atom's radius and mass)
            raise ScriptError(f"the script's atoms are LIGGGHTS' atom_style {style}, not spheres with a radius and a "
                              "mass each: the host's contact, heat and drag models are for spheres (atom_style "
                              "granular or sphere)")
        contacts = heat if contacts is None else contacts
        added = []
        if heat and not self.info.temp_fix and not self.info.heat_gran:
            added.append("fix Temp all property/atom Temp scalar yes yes no 0.0")
        if contacts:
            added.append(fix_command())
        if fluid_force:
            added.append(f"fix {FLUID_FIX} all external pf/array 1")
        for line in added:
            self.command(Command(line, "(host)", 0))
        if contacts:
            from pyhost.engines.events import ContactEvents, RankEvents
            self.events = ContactEvents(self.lmp) if self.link is None else RankEvents(self.lmp, self.link)
            self.heat = heat
            self.follow_heat_gran()
        if then:
            self.commands(list(then))
        self.run(0)
        if fluid_force:         # the set-up added fix external's array while it was uninitialised
            self.set_force(np.zeros((self.count(), 3)))     # memory: zero it and set up again
            self._raw("run 0")
        return added

    @collective
    def set_up_next(self) -> None:
        """The next run starts with a full set-up, on every rank (``Liggghts.set_up_next``)."""
        self._order("set_up_next")
        self.lmp.set_up_next()

    @collective
    def run(self, steps: int) -> None:
        self._order("run", int(steps))
        self.lmp.run(int(steps))
        self._pending = None            # the gathered atoms are out of date

    @collective
    def count(self) -> int:
        """Number of particles on all ranks now."""
        if self.link is None:
            return self.lmp.nlocal
        self._order("count")
        counts = self.link.gather(self.lmp.nlocal)
        self._counts = np.array(counts)
        return int(sum(counts))

    @property
    def dt(self) -> float:
        return self.lmp.dt

    @property
    def step(self) -> int:
        return self.lmp.step

    def dump_every(self) -> int:
        """The script's most frequent dump with a fixed interval [steps] as defined now; 0 if none
        (the same on every rank)."""
        return self.lmp.dump_every()

    def box(self):
        """(lo, hi, periodic) of the simulation box [m]."""
        lo, hi = self.lmp.box()
        return lo, hi, np.array(self.info.periodic)

    # -- particles --------------------------------------------------------------------
    @collective
    def atoms(self, temperature: bool = True) -> Atoms:
        lmp = self.lmp
        if self.link is None:
            return local_view(lmp, temperature)
        if self._all_current(temperature):
            return self._pending[0]     # no run or command since: as serially, the same arrays
        self._order("atoms", temperature)
        return self._gathered(local_atoms(lmp, temperature), None, temperature)

    @collective
    def atoms_of(self, ids, temperature: bool = True) -> Atoms:
        """Under MPI: only the atoms of these ids (those that exist), gathered from the ranks
        that own them (the ids go to every rank), in no particular order; what the loop
        writes into their T and v goes back as with :meth:`atoms`. Serially, and while the
        atoms gathered last are still current: all atoms, as :meth:`atoms`."""
        if self.link is None or self._all_current(temperature):
            return self.atoms(temperature)
        self._order("atoms_of", np.asarray(ids, np.int64), temperature)
        rows, parts = local_atoms_of(self.lmp, ids, temperature)
        return self._gathered(parts, rows, temperature)

    def _all_current(self, temperature: bool) -> bool:
        """Under MPI: whether the atoms gathered last are all atoms, with T if asked, and no
        run or command came since."""
        return (self._pending is not None and self._rows is None
                and (not temperature or self._pending[0].T is not None))

    def _gathered(self, parts, rows, temperature: bool) -> Atoms:
        """All ranks' ``parts`` (rank 0's own: its local ``rows``, None for all) gathered on rank
        0 as the atoms whose T and v go back at the next call (``_commit``)."""
        cols, counts = gather_arrays(self.link.comm, parts)
        self._counts, self._rows = np.array(counts), rows
        atoms = Atoms(cols[0].astype(np.int64), *cols[1:6], cols[6] if temperature else None)
        self._pending = (atoms, None if atoms.T is None else atoms.T.copy(), atoms.v.copy())
        return atoms

    def _commit(self) -> None:
        """Under MPI: the temperatures and velocities the host changed in the last gathered
        atoms go to the ranks that own them (nothing is sent when nothing changed). They stay
        valid until the next run or command: later changes go at the next call."""
        if self._pending is None:
            return
        atoms, T0, v0 = self._pending
        T = None if T0 is None or np.array_equal(atoms.T, T0) else atoms.T
        v = None if np.array_equal(atoms.v, v0) else atoms.v
        if T is not None or v is not None:
            self._pending = (atoms, None if T0 is None else atoms.T.copy(), atoms.v.copy())
            self._write(T=T, v=v)

    @collective
    def _write(self, **arrays) -> None:
        """Each rank's slice (the local order of the last gather) of per-atom arrays."""
        cut = np.cumsum(self._counts)[:-1]
        names = ("T", "v", "force")
        pieces = [np.split(arrays[k], cut) if arrays.get(k) is not None else [None] * len(self._counts)
                  for k in names]
        self.link.order("write", FLUID_FIX)
        write_local(self.lmp, *self.link.scatter(list(zip(*pieces))), force_fix=FLUID_FIX, rows=self._rows)

    @collective
    def keep_snapshot(self) -> int:
        """Every rank keeps a copy of its atoms' ids, positions [m] and velocities [m/s] (what a
        report of lost particles says of them: ``snapshot``); returns the number of particles.
        Under MPI nothing but the counts goes to rank 0."""
        if self.link is not None:
            self._order("keep_snapshot")
        self._snapshot = local_snapshot(self.lmp)
        n = len(self._snapshot[0])
        return n if self.link is None else int(sum(self.link.gather(n)))

    @collective
    def snapshot(self) -> tuple:
        """The copies of ``keep_snapshot`` (ids, x, v) of all ranks, gathered."""
        if self.link is None:
            return self._snapshot
        self._order("snapshot")
        cols, _ = gather_arrays(self.link.comm, self._snapshot)
        return cols

    @collective
    def each_rank(self, func, *args, temperature: bool | None = None) -> list:
        """``func(atoms, events, comm, *args)`` (a module-level function: the followers import it
        by name) on every rank, on its own atoms (``local_view``: LIGGGHTS' memory, T writable;
        ``temperature`` False or, by default, a run without heat: T None, LIGGGHTS has no Temp
        then) and contact events (None if not recorded); the ranks' results in rank order
        (serially: the one result, in a list, comm None). What the host changed in gathered
        atoms goes back first."""
        ENGINE[0] = self.lmp            # (ranks.ENGINE: for a func that needs more than the atoms)
        temperature = self.heat if temperature is None else temperature
        if self.link is None:
            return [func(local_view(self.lmp, temperature), self.events, None, *args)]
        self._order("each_rank", func, args, temperature)
        events = self.events.local if self.events is not None else None
        mine = func(local_view(self.lmp, temperature), events, self.link.comm, *args)
        self._pending = None            # func may change the atoms' Temp: a gathered copy is out of date
        return self.link.gather(mine)

    @collective
    def per_atom(self, names) -> tuple:
        """Copies of per-atom arrays (``Liggghts.atom`` names, e.g. id, f, torque) of all atoms,
        in the order of ``atoms()``."""
        if self.link is None:
            return local_values(self.lmp, names)
        self._order("per_atom", tuple(names))
        parts = self.link.gather(local_values(self.lmp, names))
        return tuple(np.concatenate([p[k] for p in parts]) for k in range(len(names)))

    @collective
    def put_per_atom(self, ids, **arrays) -> None:
        """Per-atom arrays given for all atoms by id (e.g. f=..., torque=...) into LIGGGHTS, on
        every rank; the next run starts without a set-up, which would compute the forces again."""
        self._order("put", ids, arrays)
        put_by_id(self.lmp, ids, arrays)

    def mesh_motion_times(self) -> dict:
        """The time [s] of each fix move/mesh of the script (its phase: see
        ``Liggghts.move_mesh_time``), by fix id."""
        return {fix: self.lmp.move_mesh_time(fix) for fix in self.info.mesh_motions}

    @collective
    def set_mesh_motion_times(self, times: dict) -> None:
        """Give each fix move/mesh its time back (a restart), on every rank."""
        if not times:
            return
        self._order("mesh_times", times)
        for fix, t in times.items():
            self.lmp.move_mesh_time(fix, t)

    @collective
    def random_states(self) -> dict:
        """The state of each random generator of the script's insertion (its regions, insert,
        distribution and template fixes), by "what id": one per rank."""
        keys = list(self.info.randoms)
        if self.link is not None:
            self._order("random_states", keys)
        mine = local_random_states(self.lmp, keys)
        every = [mine] if self.link is None else self.link.gather(mine)
        return {k: [m[k] for m in every] for k in mine if all(k in m for m in every)}

    @collective
    def set_random_states(self, states: dict) -> None:
        """Put those states back (a restart), each rank its own. On another number of ranks
        than the run that saved them, LIGGGHTS' own reset stays: a restart on other ranks is
        another decomposition anyway."""
        if not states:
            return
        self._order("set_random_states", states)
        set_random_states(self.lmp, states, 0, 1 if self.link is None else self.link.size)

    def insertion_progress(self) -> dict:
        """The progress of each insertion fix of the script (``Liggghts.insert_progress``), by fix
        id: the same on every rank, read on rank 0."""
        found = {fix: self.lmp.insert_progress(fix) for fix in self._insertions()}
        return {fix: p for fix, p in found.items() if p is not None}

    @collective
    def set_insertion_progress(self, progress: dict) -> None:
        """Put that progress back (a restart), on every rank: an insertion that was done stays
        done, on any number of ranks."""
        if not progress:
            return
        self._order("insertion_progress", progress)
        for fix, p in progress.items():
            self.lmp.insert_progress(fix, [float(x) for x in p])

    def _insertions(self) -> list[str]:
        return [key.split(" ", 1)[1] for key in self.info.randoms if key.startswith("insert ")]

    def check_restart(self, path: Path) -> None:
        """LIGGGHTS' restart file just written at ``path``, read back (``Liggghts.check_restart``):
        OSError naming it if it is cut (a full disk)."""
        if self.link is not None:
            return                      # (no forked copy under MPI: LIGGGHTS' own fwrite errors stay unseen)
        try:
            self.lmp.check_restart(path)
        except LiggghtsError as exc:
            raise OSError(errno.EIO, f"LIGGGHTS wrote a restart it cannot read back, a full disk? ({exc})",
                          str(path)) from None

    def drop_lost(self) -> None:
        """A set-up now, on every rank, after which the particles past a fixed face of the box
        are gone (LIGGGHTS drops them at a re-neighbouring: 'thermo_modify lost ignore')."""
        self._raw("run 0 post no")

    def write_restart(self, path) -> None:
        """LIGGGHTS' restart file written at ``path``, on every rank."""
        self._raw(f"write_restart {path}")

    def add_velocity(self, local_index, dv) -> None:
        """Add dv [m/s] to the velocity of these atoms (indices into the last ``atoms()``)."""
        v = self.lmp.atom("v") if self.link is None else self._pending[0].v
        np.add.at(v, np.asarray(local_index), dv)

    @collective
    def set_force(self, force) -> None:
        """Force [N] on each atom (the order of the last ``atoms()``), applied every step
        until changed."""
        if self.link is None:
            self.lmp.external_force(FLUID_FIX)[:] = force
            return
        self._commit()
        if self._rows is not None:
            raise RuntimeError("a force for every atom needs the atoms of atoms(), not of atoms_of()")
        if len(force) != self._counts.sum():
            raise ValueError(f"{len(force)} forces for {self._counts.sum()} particles")
        self._write(force=np.asarray(force, float))

    # -- the DEM's own values -----------------------------------------------------------
    def type_values(self, prop: str, types) -> np.ndarray:
        """A per-type property/global of the script (youngsModulus, poissonsRatio,
        thermalCapacity, ...) for these atom types (from 1)."""
        return np.array([self.lmp.fix_global(self._global_fix(prop), int(t) - 1) for t in types])

    def type_pair_value(self, prop: str, a: int, b: int) -> float:
        """A per-type-pair property/global of the script (coefficientRestitution, ...)."""
        return self.lmp.fix_global(self._global_fix(prop), a - 1, b - 1)

    def _global_fix(self, prop: str) -> str:
        fix = self.info.globals.get(prop)
        if fix is None:
            raise ScriptError(f"the script sets no 'fix ... property/global {prop} ...', which the host needs")
        return fix

    def follow_heat_gran(self) -> None:
        """With particle temperatures, the event recorder follows the script's fix heat/gran
        (``ContactEvents.conduction``): from the first run, or from the run after the script
        defines it later (CFDEM's packedBedTemp does): its walls' conduction is counted in the
        balance from then on, and its share during the collisions that begin from then on is
        taken back."""
        if self.events is not None and self.heat and self.info.heat_gran and not self.has_heat_flux():
            self.events.conduction(self.info.heat_gran, HEAT_GRAN_WINDOW)

    def has_heat_flux(self) -> bool:
        """Whether heat/gran's flux through each contact reaches the host (the event
        recorder's flux histories)."""
        return self.events is not None and self.events.window > 0

    # -- contacts ---------------------------------------------------------------------
    def event_walls(self, wall_index: dict, heated=()) -> set:
        """The primitive and mesh walls, for the event recorder, with their contact codes; of
        the ``heated`` ones ((fix, mesh) whose collisions the host gives heat), those through
        which the script's fix heat/gran conducts (a temperature in the script) keep its flux
        through each new contact (``wall_conduction``). Returns their codes. The recorder's
        fix comes after every wall's (``ContactEvents.keep_last``), and follows a fix heat/gran
        defined since the last run (``follow_heat_gran``)."""
        self.follow_heat_gran()
        if self.events.keep_last():
            self._pending = None
            self.log("the host's contact recorder (fix collheat_events) given anew after the script's walls "
                     "defined since the first run: it sums heat/gran's flux through their contacts after they add it")
        primitive = [(fix, int(wall_code(wall_index[fix, 0]))) for fix, w in self.info.walls.items() if w.primitive is not None]
        if not self.events.primitives(*(zip(*primitive) if primitive else ([], []))):
            raise ScriptError(f"the primitive walls {', '.join(f for f, _ in primitive)}: one is not a fix wall/gran "
                              "with a primitive wall the contact recorder can read: their collisions cannot be seen")
        meshes = [(mesh, int(wall_code(wall_index[fix, k]))) for fix, w in self.info.walls.items()
                  for k, mesh in enumerate(w.meshes or ())]
        if not self.events.meshes(*(zip(*meshes) if meshes else ([], []))):
            names = ", ".join(sorted({m for m, _ in meshes}))
            raise ScriptError(f"the mesh walls {names}: the contact recorder finds no neighbour list of a fix "
                              "wall/gran on them (every fix wall/gran of LIGGGHTS 3.8 makes one): their "
                              "collisions cannot be seen")
        if not self.has_heat_flux():
            return set()
        conducting = set()
        for meshes, walls in ((False, [(fix, 0) for fix, _ in primitive]),
                              (True, [(fix, k) for fix, w in self.info.walls.items() for k in range(len(w.meshes or ()))])):
            params = []
            for fix, k in walls:
                word = self.info.conducting_temperature(fix, k) if (fix, k) in heated else None
                T = None if word is None else self.value(word)
                mode, area = self.info.walls[fix].contact_area
                params.append((-1.0 if T is None else T, self.info.wall_type(fix, k) or 0,
                               ("overlap", "constant", "projection").index(mode) if mode in ("constant", "projection")
                               else 0, self.value(area) if mode == "constant" and T is not None else 0.0))
                if T is not None:
                    conducting.add(int(wall_code(wall_index[fix, k])))
            if not self.events.wall_conduction(meshes, params):
                raise ScriptError(f"walls {', '.join(f for f, _ in walls)}: the contact recorder cannot follow "
                                  "heat/gran's conduction through them (an atom type out of range?)")
        return conducting
