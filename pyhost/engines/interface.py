"""What the loop, its effects and the checkpoints ask of a DEM engine: the whole interface a
second engine implements in one file (as ``pyhost.engines.dem.Dem`` does for LIGGGHTS 3.8;
LAMMPS' GRANULAR package, LIGGGHTS' maintained successor, is the likely next one).

The engine runs a script command by command (the host's commands among them), advances in
chunks of steps, and hands out the particles (``Atoms``) with writable temperatures. Contacts
come as events recorded inside the engine at every step (``events``: the recorder of
``pyhost.engines.events``). SI units throughout. ``tests/unit/test_structure.py`` checks that the loop and
the effects use nothing of the engine outside this interface, and that ``Dem`` has all of it.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np


class DemEngine(Protocol):
    """A DEM engine as the host drives it."""

    # -- state -------------------------------------------------------------------------
    info: object                 # what the script declared so far (pyhost.script.ScriptInfo): walls, heat/gran, computes
    events: object | None        # the contact event recorder (pyhost.engines.events), None: no contacts asked for
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

    def engine_command(self, line: str) -> None:
        """Run a command of the host's own (write_restart, ...)."""

    def write_restart(self, path) -> None:
        """The engine's restart file of the state now at ``path``, checked whole (``check_restart``)."""

    def drop_outside(self) -> None:
        """A set-up without steps that drops the particles past a fixed face of the box."""

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

    def each_rank(self, func, *args) -> list:
        """``func(atoms, events, comm, *args)`` run where the particles live: each MPI rank on its
        own atoms (``Atoms`` with T writable into the engine) and contact events, serially once
        with comm None; the results in rank order."""

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


MEMBERS = tuple(sorted({n for n in vars(DemEngine) if not n.startswith("_")} | set(DemEngine.__annotations__)))
"""Every name of the interface."""
