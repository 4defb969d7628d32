"""The loop's effects: each thing the coupled run does for a scene, with what it owns.

``pyhost.loop.Coupling`` runs the DEM in chunks and calls the hooks of a list of effects,
built from ``REGISTRY`` by what the scene asks for (``Scene.effects_summary``): no fluid
exchange for a dry scene, no collision heat for an isothermal one. The loop names no effect.
An effect owns its history.csv columns (``columns`` and ``row``), the run's totals it adds to
(``TOTALS``, their starting values; every effect's in one dict, ``Context.totals``, written to
summary.json), its part of a checkpoint (``state`` and ``restore``), its intervals (``every``)
and its files. It reads of the run only its ``Context`` (``Effect.loop``), and finds another
effect's service by name (``Context.find``). A new output column is one line of one effect's
``columns`` and ``row``, a new total one entry of its ``TOTALS``; a new effect is one module
here and one line of ``REGISTRY``.

Hooks, called by the loop on every effect in the registry's order (the defaults do nothing):

    build(ctx)     (class method) the effect for this run, or None: nothing to do
    at_run(walls)  at each of a script's runs, the first included, before its steps: the
                   LIGGGHTS walls as the host sees them now (``HostWall``), checks of the script
    begin(resumed) once, after every effect is built and checked (``resumed``: from a checkpoint)
    start()        once, before the first frame (not on a restart)
    before_run(resumed)  at the start of each run's steps (``resumed``: the run a restart continues)
    after_chunk(due)  after each DEM chunk; ``due``: which intervals end at this step
                   (harvest, conduct, couple, frame, checkpoint: ``every`` of each effect and
                   the loop's own; one that no effect has is False)
    couple()       every coupling interval (an effect's ``every["couple"]`` DEM steps)
    row(atoms)     its history values at a frame, in the order of ``columns``
    frame()        its files at a frame
    join()         at the end of each run's steps: what it runs beside the DEM finished (a
                   failure there stops the run before any effect's end_run)
    end_run()      at the end of each run's steps, after every effect's join
    settle()       work owed since the last chunk (contact events not yet harvested): before
                   a checkpoint and at the end
    state()        (JSON values, arrays) for a checkpoint; restore(state) takes them back
    flush()        its files whole on disk and its totals up to date (a checkpoint, the end)
    end_totals(totals, scene)  (class method) its totals completed for the summary, present or not
    finish(summary, status)   its part of summary.json; an invariant found broken at the end
                   of a completed run goes in ``failure`` (the run then fails, exit 3, after
                   its summary is written and its files closed)
    close()        its files closed (after the summary)
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field

import numpy as np

REGISTRY = (
    # (name another effect finds it by, what Scene.effects_summary() asks for it (None: always),
    #  module:class); the order they act in
    ("balance", "particle_temperatures", "balance:EnergyBalance"),
    ("collisions", "contact_extraction", "collisions:CollisionHeat"),
    ("conduction", "conduction", "conduction:LastingConduction"),
    ("case_commands", "fluid_solver", "case_commands:CaseCommands"),   # after the DEM's steps, before the fluid's exchange
    ("fluid", "fluid_solver", "fluid:FluidExchange"),
    ("frames", None, "frames:Frames"),                                 # every other effect's columns
    ("probes", None, "probes:Probes"),                                 # (when the scene names probes)
)

SUMMARY_ORDER = ("collisions", "balance", "conduction", "case_commands", "fluid")
"""The order of the effects' totals in summary.json (the order they had when the loop named the
effects); an effect not here comes after them, in the registry's order."""


def effect_class(name: str):
    """The class of the registry's effect ``name``."""
    module, cls = dict((n, where) for n, _, where in REGISTRY)[name].split(":")
    return getattr(importlib.import_module(f"pyhost.effects.{module}"), cls)


def totals() -> dict:
    """The run's totals at its start (summary.json): the ``TOTALS`` of every effect that adds
    to them, present in the scene or not (a summary has the same keys whatever the scene)."""
    names = sorted((n for n, _, _ in REGISTRY), key=lambda n: SUMMARY_ORDER.index(n) if n in SUMMARY_ORDER
                   else len(SUMMARY_ORDER) + [r[0] for r in REGISTRY].index(n))
    return {key: value for n in names for key, value in effect_class(n).TOTALS.items()}


def end_totals(totals: dict, scene) -> None:
    """Every registered effect's totals completed for the summary, whether the scene has it or not."""
    for name, _, _ in REGISTRY:
        effect_class(name).end_totals(totals, scene)


@dataclass(eq=False)
class Context:
    """What an effect may read of the run (and the totals and warnings it adds to). SI units.

    ``scene``, ``dem`` (pyhost.engines.dem.Dem), ``out`` (the output folder), ``fluid`` (the
    running solver, or None), ``driven`` [s] (a CFD-DEM script's coupled time, or None);
    ``effects``: ``Scene.effects_summary()``; ``heat``: whether particles have temperatures;
    ``materials``: the real materials (their DEM contacts read from a script's);
    ``capacity`` [J/(kg K)] of each; ``types``: the type-to-material table
    (pyhost.particles.TypeMaterials); ``known``: what the host knows of each particle
    (pyhost.particles.Known); ``logs``: a checkpoint's output marks (empty: a new run);
    ``totals`` (summary.json's), ``warned`` (warnings said once). The loop's clock is read
    through ``t``, ``steps``, ``clock``, ``time_of``, ``every`` and ``ready``; the effects
    built before one, ``present``; another effect, ``find``; the balance's ``track_particles``
    and ``C``. ``READS`` is all of it: an effect reads nothing else of the run
    (tests/unit/test_structure.py)."""

    READS = ("scene", "dem", "out", "fluid", "driven", "effects", "heat", "materials", "capacity", "type_material",
             "materials_of", "known", "logs", "totals", "warned", "t", "steps", "clock", "time_of", "every", "ready",
             "present", "find", "track_particles", "C")

    scene: object
    dem: object
    out: object
    fluid: object
    driven: float | None
    materials: list
    types: object
    known: object
    logs: dict
    _clock: object = None               # the loop, whose clock the properties below read
    totals: dict = field(default_factory=totals)
    warned: set = field(default_factory=set)
    present: list = field(default_factory=list)     # the effects built, in the registry's order
    named: dict = field(default_factory=dict)

    def __post_init__(self):
        self.effects = self.scene.effects_summary()
        self.heat = self.effects["particle_temperatures"]
        self.capacity = np.array([m.heat_capacity for m in self.materials])
        self.type_material = self.types.table

    def build(self) -> list:
        """The effects the scene asks for, built in the registry's order (each sees those before it)."""
        for name, wanted, _ in REGISTRY:
            if wanted is None or self.effects[wanted]:
                effect = effect_class(name).build(self)
                if effect is not None:
                    self.present.append(effect)
                    self.named[name] = effect
        return self.present

    def find(self, name: str):
        """The registry's effect ``name`` of this run, or None (the scene does not ask for it)."""
        return self.named.get(name)

    def materials_of(self, types) -> np.ndarray:
        """Material index of each atom type (ScriptError for a type without one)."""
        return self.types.of(types)

    # -- the loop's clock, read-only --
    t = property(lambda self: self._clock.t, doc="the simulated time [s]")
    steps = property(lambda self: self._clock.steps, doc="the coupled DEM steps so far")
    clock = property(lambda self: self._clock.clock, doc="(t [s], step, dt [s]): LIGGGHTS' step s is at t + (s - step) dt")
    every = property(lambda self: self._clock.every, doc="DEM steps between each interval's ends, by name")
    ready = property(lambda self: self._clock.ready, doc="whether the run has a state whole enough to checkpoint")

    def time_of(self, step) -> float:
        """The simulated time [s] of LIGGGHTS' step number ``step`` of the run under way."""
        return self._clock.time_of(step)

    # -- the energy balance's service (pyhost.effects.balance), where particles have temperatures --
    def track_particles(self, atoms, departures: bool = True) -> None:
        """The energy balance brought up to date with these atoms (``EnergyBalance.track``)."""
        balance = self.find("balance")
        if balance is not None:
            balance.track(atoms, departures)

    @property
    def C(self) -> np.ndarray:
        """m c [J/K] of the atoms last tracked, in their order (particle temperatures only)."""
        return self.find("balance").C


class Effect:
    """One thing the loop does; ``loop`` is the run's ``Context`` (what it may read of the loop)."""

    columns: tuple = ()
    TOTALS: dict = {}                 # the summary's totals it adds to, with their values at the start
    failure: str | None = None        # what its finish found broken (a completed run only)
    every: dict = {}                  # DEM steps between the ends of its intervals, by name (0: none)

    def __init__(self, loop: Context):
        self.loop = loop

    @classmethod
    def build(cls, ctx: Context):
        return cls(ctx)

    @classmethod
    def end_totals(cls, totals: dict, scene) -> None:
        pass

    def at_run(self, walls) -> None:
        pass

    def begin(self, resumed: bool) -> None:
        pass

    def start(self) -> None:
        pass

    def before_run(self, resumed: bool) -> None:
        pass

    def after_chunk(self, due: dict) -> None:
        pass

    def couple(self) -> None:
        pass

    def row(self, atoms) -> tuple:
        return ()

    def frame(self) -> None:
        pass

    def join(self) -> None:
        pass

    def end_run(self) -> None:
        pass

    def settle(self) -> None:
        pass

    def state(self) -> tuple[dict, dict]:
        return {}, {}

    def restore(self, state: dict) -> None:
        pass

    def flush(self) -> None:
        pass

    def finish(self, summary: dict, status: str) -> None:
        pass

    def close(self) -> None:
        pass


def by_id(ids, values, wanted, missing=None):
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
