"""What the loop, its effects and the checkpoints ask of a DEM engine: the whole interface a
second engine's bridge implements (as ``pyhost.engines.dem.Dem`` does for LIGGGHTS 3.8, with
the package ``pyhost.engines.liggghts``; LAMMPS' GRANULAR package, LIGGGHTS' maintained
successor, is the likely next one).

The engine runs a script command by command (the host's commands among them), advances in
chunks of steps, and hands out the particles (``Atoms``) with writable temperatures. Contacts
come as events recorded inside the engine at every step (``events``: the recorder of
``pyhost.engines.events``; ``ContactEvents``) and what the script declared so far is its
``info`` (``ScriptInfo``). SI units throughout. ``tests/unit/test_structure.py`` checks that the
loop and the effects use nothing of the engine, its events or its info outside this interface,
and that LIGGGHTS' bridge has all of it.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np


class ContactEvents(Protocol):
    """The contact events recorded inside the engine at every step (``pyhost.engines.events``:
    ``ContactEvents``, under MPI ``RankEvents``): each contact's begin (with its impact speed)
    and end, taken at the host's harvests."""

    window: int                  # steps of a fix heat/gran's flux kept per new contact (0: none)
    joined: list                 # contacts that moved between MPI ranks, at the last take

    @property
    def waiting(self) -> int:
        """Events recorded and not yet taken."""

    def take(self) -> np.ndarray:
        """The events waiting, oldest first (``pyhost.engines.events.EVENT``); forgotten then."""

    def sync(self) -> None:
        """Record the contacts now, between runs (after a set-up)."""

    def appeared(self) -> tuple:
        """Atoms inserted since the last call: ids, temperature [K] at their first step, that step."""

    def histories(self, all: bool = False) -> tuple:
        """The flux histories of new contacts handed over: i, j, begin step, steps kept, fluxes [W]."""

    def restitution(self, keys, speed, normal) -> None:
        """Separation speeds [m/s] along ``normal`` to impose when these open contacts end."""

    def forget(self, keys) -> None:
        """Drop the separation speeds of these contacts."""


class ScriptInfo(Protocol):
    """What the script declared so far, as the host reads it (``pyhost.engines.liggghts.script.ScriptInfo``)."""

    heat_gran: str | None        # id of the script's conduction fix (heat/gran), None: none
    globals: dict                # name of a per-type material property -> the id of the command that sets it
    fixes: dict                  # id -> the command that defined it (defined now)
    streams: list                # ids of the insertions that stream particles in, defined now

    def fix_named(self, message: str):
        """The script's command that an engine error message names, or None."""


class DemEngine(Protocol):
    """A DEM engine as the host drives it."""

    # -- state -------------------------------------------------------------------------
    info: ScriptInfo             # what the script declared so far: walls, heat/gran, computes
    events: ContactEvents | None  # the contact event recorder, None: no contacts asked for
    link: object | None          # the other MPI ranks (pyhost.engines.ranks.Link), None when serial

    @property
    def dt(self) -> float:
        """The time step [s]."""

    @property
    def step(self) -> int:
        """The current step."""

    # -- the script --------------------------------------------------------------------
    def context(self, cmd) -> None:
        """The script command about to run (named in the engine's errors)."""

    def command(self, cmd) -> None:
        """Run one script command (not a ``run``)."""

    def commands(self, cmds) -> None:
        """Run the script's commands up to its next ``run`` (none of them a run), in order,
        each named in the engine's errors (an engine that checks each command before running
        it may check them together first)."""

    def drop_lost(self) -> None:
        """A set-up now, after which the particles past a fixed face of the box are gone (a
        checkpoint's restart file then holds what the host's state does)."""

    def write_restart(self, path) -> None:
        """Write the engine's restart file at ``path`` (a checkpoint's)."""

    def check_restart(self, path) -> None:
        """The engine's restart file just written at ``path`` is whole (read back): OSError
        naming it if not (a full disk the engine did not report)."""

    def prepare(self, heat: bool, contacts: bool | None = None, fluid_force: bool = False,
                then=()) -> list[str]:
        """Before the first run: add what the host needs (temperatures, the contact event
        recorder, the external force), run the script's commands ``then`` (held back to come
        after them) and set up; returns the commands added, for the log."""

    def steps(self, steps: str, upto: bool) -> int:
        """The number of steps of a script's ``run N [upto]``."""

    def value(self, text: str) -> float:
        """A number of the script as the engine evaluates it (a plain number or a $variable)."""

    def branch(self, conditions: list[str]) -> int:
        """Which branch of a script's ``if`` the engine takes now: the index of the first of its
        conditions (as written) that holds, ``len(conditions)`` for the else."""

    def jump_skipped(self) -> bool:
        """Whether a script's ``next`` since the last call exhausted its variable, so that the
        engine's input loop would skip the next ``jump``."""

    def set_up_next(self) -> None:
        """The next run starts with a full set-up, as a script's ``run`` (``pre yes``) does."""

    def run(self, steps: int) -> None:
        """Advance ``steps`` steps (0: set up only)."""

    def report_warnings(self, cmd=None) -> None:
        """Say the engine's new warnings once."""

    def dump_every(self) -> int:
        """The steps between the script's most frequent dump's outputs, as defined now (one with
        a fixed interval); 0 if none. Frames follow it where output.every is 0."""

    def close(self) -> None:
        """End the engine."""

    # -- particles ---------------------------------------------------------------------
    def count(self) -> int:
        """Particles in the simulation, on every rank."""

    def box(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lo [m], hi [m], periodic flags) of the domain."""

    def atoms(self, temperature: bool = True):
        """Every particle now (``pyhost.engines.atoms.Atoms``), with a writable T [K] if asked;
        writes into T and v reach the engine before its next step."""

    def atoms_of(self, ids, temperature: bool = True):
        """The particles with these ids only (MPI: only they are gathered)."""

    def add_velocity(self, local_index, dv) -> None:
        """Add dv [m/s] to the velocities of these atoms (indices into the last ``atoms``)."""

    def set_force(self, force) -> None:
        """The external force [N] on each atom (the fluid's), kept until set again."""

    def keep_snapshot(self) -> int:
        """Keep a copy of every particle's id, position [m] and velocity [m/s] where it lives
        (each MPI rank its own); returns the number of particles."""

    def snapshot(self) -> tuple:
        """The copies of ``keep_snapshot``: (ids, x, v) of all particles (a report of lost ones)."""

    def each_rank(self, func, *args, temperature: bool | None = None) -> list:
        """``func(atoms, events, comm, *args)`` run where the particles live: each MPI rank on its
        own atoms (``Atoms`` with T writable into the engine; without T where ``temperature`` is
        False or, by default, the run has no heat) and contact events, serially once with comm
        None; the results in rank order."""

    def per_atom(self, names) -> tuple:
        """Per-atom arrays by name ("id", "f", "torque"), for a checkpoint."""

    def put_per_atom(self, ids, **arrays) -> None:
        """Per-atom arrays back by id (a restart's forces and torques)."""

    # -- material values of the script ---------------------------------------------------
    def type_values(self, prop: str, types) -> np.ndarray:
        """A per-type property of the script (youngsModulus, poissonsRatio, thermalCapacity)."""

    def type_pair_value(self, prop: str, a: int, b: int) -> float:
        """A per-type-pair property of the script (coefficientRestitution) of types a, b."""

    def has_heat_flux(self) -> bool:
        """Whether the script's fix heat/gran's conduction per contact can be read."""

    # -- contacts ----------------------------------------------------------------------
    def event_walls(self, wall_index: dict, heated=()) -> set:
        """Hand the recorder the walls it records contacts with, by their host codes; of the
        ``heated`` ones ((fix, mesh) whose collisions the host gives heat), those through which
        the script's heat/gran conducts keep its flux through each new contact as pairs do.
        Returns those walls' codes."""

    # -- what a checkpoint keeps that the engine's restart does not ------------------------
    def mesh_motion_times(self) -> dict:
        """Each moving mesh's phase [s]."""

    def set_mesh_motion_times(self, times: dict) -> None:
        """Set each moving mesh's phase [s]."""

    def random_states(self) -> dict:
        """The insertion generators' states."""

    def set_random_states(self, states: dict) -> None:
        """Set the insertion generators' states."""

    def insertion_progress(self) -> dict:
        """Each insertion's progress (next insertion step, particles and mass inserted so far)."""

    def set_insertion_progress(self, progress: dict) -> None:
        """Set each insertion's progress."""


def members(protocol) -> tuple:
    """Every name a protocol declares."""
    return tuple(sorted({n for n in vars(protocol) if not n.startswith("_")} | set(protocol.__annotations__)))


MEMBERS = members(DemEngine)
"""Every name of the interface."""
EVENT_MEMBERS = members(ContactEvents)
INFO_MEMBERS = members(ScriptInfo)
