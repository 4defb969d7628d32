"""The scene's schema: the frozen dataclasses a ``case.toml`` is built into (``pyhost.scene``
reads and checks it), each field's rule, default and meaning (``spec``), ``SceneError``, and
``build``, which fills a dataclass from one TOML table. SI units. It imports no other part
of the host but the walls, so that everything that takes a scene (the checks, the LIGGGHTS
input) can import it without going round in a circle through the loader.
"""
from __future__ import annotations

import dataclasses
import math
import typing
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from plugins.conduction import CONTACT, GAP
from plugins.convection import CORRELATIONS
from plugins.drag import LAWS as DRAG_LAWS
from plugins.heat import MODEL_NAMES
from pyhost.engines.liggghts.names import CONDUCTION, CONDUCTION_FIX, COUPLING_FIX, MATERIAL_VALUES, WALL_FIX
from pyhost.walls import FACES


class SceneError(ValueError):
    """A problem in a scene file, naming the file and the key."""


def _check(value, rule: str) -> str | None:
    """None if value satisfies rule, else the complaint."""
    if rule == ">0" and not value > 0:
        return f"must be > 0, got {value!r}"
    if rule == ">=0" and not value >= 0:
        return f"must be >= 0, got {value!r}"
    if rule == "0<e<=1" and not 0 < value <= 1:
        return f"must be in (0, 1], got {value!r}"
    if rule == "poisson" and not -1 < value < 0.5:
        return f"must be in (-1, 0.5), got {value!r}"
    if rule == "models":
        names = [value] if isinstance(value, str) else value
        choices = ("none",) + MODEL_NAMES if isinstance(value, str) else MODEL_NAMES
        if not names or not all(isinstance(n, str) and n in choices for n in names):
            return f"must be one of {', '.join(choices)}, or a list of models, got {value!r}"
        if len(set(names)) != len(names):
            return f"names a model twice: {value!r}"
    if rule == "temperatures":
        values = value if isinstance(value, list) else [value]
        if not values or not all(isinstance(T, (int, float)) and not isinstance(T, bool) and math.isfinite(T)
                                 and T >= 0 for T in values):
            return f"must be a temperature >= 0 [K], or a list of them (one per type), got {value!r}"
    if rule.startswith("in:") and value not in rule[3:].split(","):
        return f"must be one of {rule[3:].replace(',', ', ')}, got {value!r}"
    return None


def spec(rule: str = "", default=dataclasses.MISSING, doc: str = ""):
    """A scene field with a validity rule (see ``_check``) and its documentation with units."""
    kw = {} if default is dataclasses.MISSING else (
        {"default_factory": lambda: default} if isinstance(default, (list, dict)) else {"default": default})
    return field(metadata={"rule": rule, "doc": doc}, **kw)


@dataclass(frozen=True)
class Effects:
    fluid: bool = spec(default=False, doc="run the OpenFOAM fluid solver")
    contact_heat: str | list = spec("models", "none", "collision heat model, or a list of models: the first "
                                    "moves the temperatures (and gives e), the others are side columns")
    heat_path: str = spec("in:exact,fast", "fast", "plugin evaluation path")
    restitution_feedback: bool = spec(default=False, doc="apply the model's e(v0) at contact end")
    enduring_conduction: bool = spec(default=False, doc=f"box scenes: LIGGGHTS' {CONDUCTION_FIX} conducts through "
                                                         "particle contacts that outlast a collision, and those "
                                                         "with walls at a temperature")
    wall_heat: bool = spec(default=True, doc="collisions with walls at a fixed temperature exchange heat")
    contact_conduction: str = spec("in:none," + ",".join(CONTACT), "none",
                                   "lasting conduction through particle-particle contacts, every "
                                   "conduction.every DEM steps (plugins/conduction/contact; settings in [conduction]); a collision's "
                                   "contact conducts only after its model duration t_coll, through its "
                                   "collision heat before. Not with enduring_conduction or a script's "
                                   f"{CONDUCTION_FIX}, which conduct through the same contacts")
    gap_conduction: str = spec("in:none," + ",".join(GAP), "none",
                               "conduction through the gas between particles near each other or touching "
                               "(particle-fluid-particle), every conduction.every DEM steps (plugins/conduction/gap; the gas "
                               "conductivity and cut-offs in [conduction])")
    convection: str = spec("in:none," + ",".join(sorted(CORRELATIONS)), "none",
                           "gas-particle convection: Nusselt correlation (plugins.convection); turns on the "
                           "gas energy equation of the fluid; a CFDEM case's couplingProperties gives it when "
                           "this key is absent (LaEuScalarTemp's NuCorrelation, scalarGeneralExchange)")

    @property
    def heat_models(self) -> tuple:
        """The collision heat models, the one that moves heat first; () for none."""
        if isinstance(self.contact_heat, str):
            return () if self.contact_heat == "none" else (self.contact_heat,)
        return tuple(self.contact_heat)


@dataclass(frozen=True)
class DemContact:
    youngs_modulus: float = spec(">0", doc="softened Young's modulus of the DEM [Pa]")
    restitution: float = spec("0<e<=1", doc="DEM coefficient of restitution [-]")
    friction: float = spec(">=0", 0.3, "Coulomb friction coefficient [-]")
    poisson_ratio: float = spec("poisson", 0.3, "DEM Poisson ratio [-]")


@dataclass(frozen=True)
class Material:
    density: float = spec(">0", doc="[kg/m^3]")
    youngs_modulus: float = spec(">0", doc="real Young's modulus [Pa]")
    poisson_ratio: float = spec("poisson", doc="[-]")
    yield_stress: float = spec(">0", doc="[Pa]")
    heat_capacity: float = spec(">0", doc="[J/(kg K)]")
    conductivity: float = spec(">0", doc="[W/(m K)]")
    dem: DemContact | None = spec(default=None, doc="the DEM's softened contact: required for box scenes; a "
                                                  f"script scene reads it from the script's {MATERIAL_VALUES} "
                                                  "(checked against this table if given)")
    b1: float = spec(">0", 1.1, "mean pressure at first yield / Y [-]")
    b2: float = spec(">0", 2.8, "fully plastic mean pressure / Y [-]")
    types: list = spec(default=[], doc="LIGGGHTS atom types made of this material (script scenes)")
    temperature: float | list = spec("temperatures", 0.0, "initial temperature of its particles [K] (script "
                                                          "scenes), or a list, one per entry of types (each "
                                                          "type then a temperature group of its own in "
                                                          "history.csv); 0 keeps the script's own Temp values")
    roughness: float = spec(">=0", 0.0, "RMS surface roughness [m], for contact_conduction = \"lethe_rough\" "
                                        "(0: smooth)")
    surface_slope: float = spec(">=0", 0.0, "RMS surface slope [-], for contact_conduction = \"lethe_rough\"")
    microhardness: float = spec(">=0", 0.0, "microhardness [Pa], for contact_conduction = \"lethe_rough\"")

    def temperature_of(self, atom_type: int) -> float:
        """The initial temperature [K] of this material's atoms of that type (0: the script's)."""
        if isinstance(self.temperature, list):
            return float(self.temperature[self.types.index(atom_type)])
        return float(self.temperature)


def check_types(materials: dict, file: str) -> dict:
    """Script scenes and post: each material names its atom types (integers >= 1, no type
    twice) and, if it gives a list of temperatures, one per type. Returns {type: name}."""
    owner = {}
    for name, m in materials.items():
        for t in m.types:
            if isinstance(t, bool) or not isinstance(t, int) or t < 1:
                raise SceneError(f"{file}: materials.{name}.types: atom types are integers >= 1, got {t!r}")
            if t in owner:
                raise SceneError(f"{file}: materials.{name}.types: type {t} is already made of {owner[t]!r}")
            owner[t] = name
        if isinstance(m.temperature, list) and len(m.temperature) != len(m.types):
            raise SceneError(f"{file}: materials.{name}.temperature: {len(m.temperature)} temperatures for "
                             f"{len(m.types)} types {m.types}: give one per type, or one number")
    return owner


@dataclass(frozen=True)
class Particles:
    material: str = spec(doc="key of [materials]")
    count: int = spec(">0", doc="number of particles")
    radius: float = spec(">0", doc="[m]")
    temperature: float = spec(">0", doc="initial temperature [K]")
    region: list = spec(default=[], doc="xmin xmax ymin ymax zmin zmax where they are placed [m]")
    positions: list = spec(default=[], doc="explicit centres [[x, y, z], ...] [m], instead of region")
    velocity: list = spec(default=[0.0, 0.0, 0.0], doc="initial velocity [m/s]")
    velocity_spread: float = spec(">=0", 0.0, "std. deviation of random velocity components added [m/s]")


@dataclass(frozen=True)
class Wall:
    material: str = spec(doc="key of [materials]")
    plane: str = spec("in:," + ",".join(FACES), "", "which face of the box (box scenes)")
    fix: str = spec(default="", doc=f"id of the script's {WALL_FIX}, primitive or mesh (script scenes)")
    temperature: float = spec(">=0", 0.0, "fixed temperature [K] (for collisions; with effects.convection also "
                                           "the gas at that side of a box scene); 0 means adiabatic; a script's "
                                           f"wall with a temperature for its {CONDUCTION_FIX} needs the same one here "
                                           f"({CONDUCTION}'s share during each collision is then taken back)")


@dataclass(frozen=True)
class Domain:
    box: list = spec(doc="xmin xmax ymin ymax zmin zmax [m]")
    gravity: list = spec(default=[0.0, 0.0, -9.81], doc="[m/s^2]")
    periodic: list = spec(default=[False, False, False], doc="periodic in x, y, z")


@dataclass(frozen=True)
class Fluid:
    case: str = spec(default="", doc="the user's OpenFOAM case folder, relative to the case folder ('.': "
                                     "case.toml sits in it, as CFDEM's tutorials keep it), solved by collheatFoam "
                                     "with its own mesh and boundary conditions (supported: docs/fluid-cases.md). "
                                     "Its transportProperties give nu and rho (or a uniform 0/rho), its "
                                     "constant/g the gravity, which acts on the gas: the keys density, "
                                     "viscosity, inlet_*, plenum, cells and sides are then unused. Checked "
                                     "before any engine: each mesh patch has its entry in 0/U and 0/p, "
                                     "decomposeParDict has fluid.ranks subdomains, the mesh files read "
                                     "(docs/exit-codes.md). Copied to OUT/fluid without run outputs, time "
                                     "folders other than 0 and the controlDict's start, and processor folders; "
                                     "a CFDEM case's constant/liggghtsCommands runs as in CFDEM")
    density: float = spec(">0", 1.2, "[kg/m^3]")
    viscosity: float = spec(">0", 1.8e-5, "dynamic viscosity [Pa s]")
    inlet_velocity: float = spec(">=0", 0.0, "superficial velocity at the inlet (fluid z lo) [m/s]")
    inlet_table: list = spec(default=[], doc="[[time s, superficial velocity m/s], ...] instead of "
                                             "inlet_velocity: piecewise linear, held after the last")
    plenum: float = spec(">=0", 0.0, "particle-free fluid layer below the box [m]: the box's z lo "
                                      "wall is then a distributor, and the inlet sees no particles")
    drag: str = spec("in:" + ",".join(sorted(DRAG_LAWS)), "gidaspow",
                     "drag law (plugins.drag); a CFDEM case's couplingProperties forceModels gives it "
                     "when this key is absent (KochHillDrag, DiFeliceDrag, GidaspowDrag)")
    cells: list = spec(default=[10, 1, 30], doc="cells in x, y, z")
    sides: str = spec("in:slip,wall", "slip", "the four side faces of the fluid box")
    alpha_min: float = spec(">0", 0.3, "floor of the fluid fraction given to the solver [-]; a CFDEM case's "
                                       "couplingProperties gives it when this key is absent (its void fraction "
                                       "model's alphaMin, CFDEM's default 0.1)")
    ddt_alpha: bool = spec(default=True, doc="d(alpha)/dt in the gas continuity equation; a CFDEM case's "
                                             "couplingProperties gives it when this key is absent (useDDTvoidfraction: "
                                             "b true, off or absent false, as CFDEM's solvers)")
    void_fraction: str = spec("in:centre,divided", "centre",
                              "how a particle's volume and drag go to the fluid cells: all to the cell of its "
                              "centre, or divided over the cells it overlaps (CFDEM's divided model; for cells "
                              "less than about 3 particle diameters wide); a CFDEM case's couplingProperties "
                              "voidFractionModel gives it when this key is absent")
    conductivity: float = spec(">0", 0.026, "gas thermal conductivity [W/(m K)] (with effects.convection; a CFDEM "
                                            "case's heat transfer model's lambda gives it when this key is absent)")
    heat_capacity: float = spec(">0", 1005.0, "gas specific heat capacity [J/(kg K)] (with effects.convection; a "
                                              "CFDEM case's heat transfer model's Cp gives it when this key is absent)")
    temperature: float = spec(">0", 293.15, "initial gas temperature [K] (with effects.convection)")
    inlet_temperature: float = spec(">=0", 0.0, "gas temperature at the inlet [K]; 0: the initial temperature")
    ranks: int = spec(">0", 1, "MPI ranks of the fluid solver, started as a job of its own (mpirun -np, "
                               "after decomposePar; the box mesh is cut into slabs across x or y, whichever has "
                               "more cells; a user's case needs its own system/decomposeParDict with that many "
                               "subdomains)")
    overlap: str = spec("in:auto,always,never", "auto",
                        "whether the fluid advances while the DEM runs the same coupling interval, in "
                        "parallel (the results are the same): auto does so in a serial run when this "
                        "machine has a core for each fluid rank beside the DEM's, not under mpirun")

    @property
    def prandtl(self) -> float:
        """Gas Prandtl number mu c / k (-)."""
        return self.viscosity * self.heat_capacity / self.conductivity

    def inlet_at(self, t):
        """Superficial inlet velocity [m/s] at time t [s] (scalar or array)."""
        if not self.inlet_table:
            return self.inlet_velocity + 0.0 * np.asarray(t, float)
        times, speeds = np.array(self.inlet_table, float).T
        return np.interp(t, times, speeds)


@dataclass(frozen=True)
class Dem:
    script: str = spec(default="", doc="the user's LIGGGHTS input script, relative to the case folder; "
                                       "run as written, each 'run N' becoming N coupled steps; a CFDEM "
                                       "case's fluid.case without [[particles]]: the script its "
                                       "couplingProperties names (liggghtsPath) when not given")
    variables: dict = spec(default={}, doc="LIGGGHTS index variables set as with 'liggghts -var NAME VALUE'")
    test_variables: dict = spec(default={}, doc="variables of the -test smoke run (added to variables)")


@dataclass(frozen=True)
class Time:
    dem_step: float = spec(">=0", 0.0, "DEM time step [s] (box scenes; a script sets its own)")
    end: float = spec(">=0", 0.0, "simulated time [s] (box scenes; a script's runs set it, except a CFD-DEM "
                                  "script's final run of 0 steps, which the coupling drives for this long, else for "
                                  "the fluid case's controlDict endTime)")
    sample_every: int = spec(">0", 1, "DEM steps between harvests of the contact events with restitution "
                                      "feedback: a contact shorter than this gets its separation speed at the "
                                      "harvest, late (restitution_late in summary.json)")
    couple_every: int = spec(">0", 50, "DEM steps between fluid exchanges; a CFDEM case's couplingInterval "
                                       f"(its in-memory exchange, twoWayMPI), else its script's {COUPLING_FIX} "
                                       "couple_every, gives it when this key is absent")
    test_end: float = spec(">=0", 0.0, "simulated time of the -test smoke run [s]; 0 means end/10")


@dataclass(frozen=True)
class Conduction:
    every: int = spec(">0", 1, "DEM steps between two updates of lasting conduction; each update moves the "
                               "heat of the interval exactly for an isolated pair, whatever its length "
                               "(plugins/conduction/exchange.py), first order in it for particles with several "
                               "neighbours; the pairs are those found at the update")
    gas_conductivity: float = spec(">=0", 0.0, "conductivity of the gas in the gaps [W/(m K)], for "
                                               "effects.gap_conduction; 0: fluid.conductivity of the scene's "
                                               "[fluid] (the gas it solves), required without one")
    lens: float = spec(">0", 0.2, "gas lens thickness around the larger particle, in its radii (MFiX's FLPC): "
                                  "rong_horio conducts through gaps below lens * R_max [-]")
    min_distance: float = spec(">0", 1e-6, "closest approach of two surfaces in the gas path [m] "
                                           "(MFiX's DES_MIN_COND_DIST): rong_horio's gap is never below it")
    gas_parameter: float = spec(">=0", 0.0, "Lethe's gas parameter M [m], added to the gap of its macrogap "
                                            "(gap_conduction = \"lethe\"; needs > 0: a point contact's gas "
                                            "resistance vanishes without it)")


@dataclass(frozen=True)
class Output:
    every: float = spec(">=0", 0.0, "interval between VTK frames and history rows [s]; 0: a script's own rhythm, "
                        "its most frequent dump at each run (frames at the steps of its dumps), else 1e-3 s "
                        "(box scenes, scripts without dumps)")
    vtk: bool = spec(default=True, doc="write VTK time series")
    pictures: bool = spec(default=True, doc="write PNG pictures")
    checkpoint: float = spec(">=0", 0.0, "simulated time between periodic checkpoints into OUT/checkpoint [s]; "
                             "0: none. A signal (SIGTERM, SIGINT, SIGHUP) always writes one at the stop; continue "
                             "with 'run CASE --restart' (docs/checkpoint.md)")
    collisions: str = spec("in:csv,binary", "csv", "form of the collision log: 'csv', OUT/collisions.csv; 'binary', "
                           "one raw little-endian file per column in OUT/collisions/ with schema.json (cheaper "
                           "to write; read with pyhost.output.read_collisions, convert with "
                           "'python -m pyhost collisions OUT')")
    probes: dict = spec(default={}, doc="probes: NAME = [xmin, xmax, ymin, ymax, zmin, zmax] [m], a region whose "
                        "particles' mean temperature (by heat capacity) goes to OUT/probes.csv, column NAME [K], at "
                        "every frame and every frozen.every of a frozen stage (NaN: no particle centre in it)")


@dataclass(frozen=True)
class Frozen:
    end: float = spec(">=0", 0.0, "duration of the frozen-bed thermal stage after the script's last run [s]: the "
                                  "particles stay where the DEM left them and only heat moves, through the "
                                  "conduction models of [effects] and the walls at a temperature (pyhost/frozen.py); "
                                  "0: no frozen stage")
    step: float = spec(">0", 1.0, "thermal time step of the frozen stage [s]")
    every: float = spec(">=0", 0.0, "interval between the frozen stage's probe rows [s]; 0: every 10 steps")
    method: str = spec("in:implicit,explicit", "implicit",
                       "implicit: backward Euler, a sparse solve per step (stable at any step); explicit: forward "
                       "Euler, refused when the step exceeds its stability bound min(C_i / sum_j H_ij)")


@dataclass(frozen=True)
class Scene:
    path: Path
    effects: Effects
    materials: dict
    particles: list
    domain: Domain
    time: Time
    walls: list
    fluid: Fluid | None
    output: Output
    dem: Dem = Dem()
    conduction: Conduction = Conduction()
    frozen: Frozen = Frozen()

    @property
    def folder(self) -> Path:
        """The case folder: a script runs there, its relative paths are read from there."""
        return Path(self.path).resolve().parent

    @property
    def scripted(self) -> bool:
        """The DEM is the user's own LIGGGHTS script (else the box world generated from the scene)."""
        return bool(self.dem.script)

    def effects_summary(self) -> dict:
        """What the host builds for this scene."""
        heat = bool(self.effects.heat_models)
        convection = self.effects.convection != "none"
        conduction = self.effects.contact_conduction != "none" or self.effects.gap_conduction != "none"
        return dict(
            fluid_solver=self.effects.fluid,
            convection=convection,
            conduction=conduction,
            particle_temperatures=heat or convection or conduction,
            contact_extraction=heat or self.effects.restitution_feedback,
            collision_heat=heat,
            restitution_feedback=self.effects.restitution_feedback,
            enduring_conduction=self.effects.enduring_conduction,
            wall_heat=heat and self.effects.wall_heat and any(w.temperature > 0 for w in self.walls),
        )


RETIRED = {
    "time.contacts": "retired: collisions come from contact events recorded inside LIGGGHTS at every step "
                     "(docs/contact-events.md); sampling the contact lists is gone from runs (post still "
                     "reads contact dumps)",
}
"""Keys a scene may still carry from an earlier version, and why they went."""


def build(cls, data, where: str, file: str):
    """The dataclass ``cls`` filled from one TOML table ``data`` (at key ``where`` of ``file``):
    every key known, every value of its type and within its rule; SceneError naming the file
    and the key otherwise. A missing key takes its default (or is an error if it has none)."""
    if not isinstance(data, dict):
        raise SceneError(f"{file}: {where}: must be a table, got {type(data).__name__}")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    hints = typing.get_type_hints(cls)
    for key in data:
        if f"{where}.{key}" in RETIRED:
            raise SceneError(f"{file}: {where}.{key}: {RETIRED[f'{where}.{key}']}; remove the key")
        if key not in fields:
            raise SceneError(f"{file}: {where}.{key}: unknown key; known: {', '.join(fields)}")
    values = {}
    for name, f in fields.items():
        key = f"{where}.{name}"
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise SceneError(f"{file}: {key}: missing ({f.metadata.get('doc', '')})")
            continue
        value, kind = data[name], hints[name]
        if type(None) in typing.get_args(kind):         # an optional table: X | None
            kind = next(k for k in typing.get_args(kind) if k is not type(None))
        if dataclasses.is_dataclass(kind):
            values[name] = build(kind, value, key, file)
            continue
        if float in (kind, *typing.get_args(kind)) and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, kind) or (kind is not bool and isinstance(value, bool)):
            raise SceneError(f"{file}: {key}: must be {getattr(kind, '__name__', str(kind))}, got {value!r}")
        if kind is float and not math.isfinite(value):
            raise SceneError(f"{file}: {key}: must be finite, got {value!r}")
        problem = _check(value, f.metadata.get("rule", "")) if f.metadata.get("rule") else None
        if problem:
            raise SceneError(f"{file}: {key}: {problem}")
        values[name] = value
    return cls(**values)
