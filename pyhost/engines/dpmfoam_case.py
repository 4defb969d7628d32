"""A case of OpenFOAM's own CFD-DEM solver DPMFoam (Debian's openfoam-examples:
lagrangian/DPMFoam/Goldschmidt) as a case of this host, so that ``python -m pyhost run``
runs it with collision heat: its gas becomes a collheatFoam case (``CFD/``), its kinematic
cloud a LIGGGHTS script (``DEM/in.liggghts`` reading ``DEM/particles.data``), and a
``case.toml`` ties them (``python -m pyhost dpmfoam CASE OUT``).

What is translated, and how (SI units throughout):

- the gas: every file of 0/, constant/ and system/ but the cloud's own, with the phase's
  suffix dropped from file names and names (``U.air`` -> ``U``, ``alphaPhi.air`` ->
  ``alphaPhi``, ``rho.air`` -> ``rho``: collheatFoam's names); a blockMesh patch of type
  ``wall`` that is an inlet or an outlet of the gas (its velocity neither noSlip nor slip)
  becomes a ``patch``: DPMFoam types it a wall for its particles, whose walls are
  LIGGGHTS' here;
- the particles: ``manualInjection`` of one particle per parcel at the start (positions
  file, fixed diameter, ``U0``), density ``rho0``;
- their contacts: ``pairSpringSliderDashpot`` and ``wallSpringSliderDashpot`` (Hertz, b =
  1.5) as LIGGGHTS' ``hertz tangential history`` with the same Young's moduli and Poisson
  ratios, the friction ``mu``, and the restitution whose damping is the same law
  (``plugins.dem.hertz.restitution_of_tsuji_alpha``); a patch that is not a wall
  (symmetry, an inlet) stops particles by its ``rebound`` rule of the patch interaction
  model (its e and mu, the particles' own modulus);
- the walls: each face of the box the mesh is (one axis-aligned hex block) a LIGGGHTS
  primitive wall (``fix wall/gran ... primitive``) named after its patch and face;
- the forces on the particles: ``ErgunWenYuDrag`` as ``gidaspow`` (Ergun below a fluid
  fraction of 0.8, Wen & Yu above), ``WenYuDrag`` as ``wenyu``; gravity from constant/g.
  DPMFoam gives its particles the drag K/alpha (its Ergun: (150 (1 - alpha)/alpha + 1.75 Re)
  mu V/(alpha d^2), Re on the slip) and a gravity m g (1 - rho_gas/rho_p), nothing of the
  pressure gradient; the host (model A) the drag K of the same law and -V grad p. Where the gas
  gradient is the drag's, alpha grad p = -n K (u - v), the two sums are one force;
- the continuity equation without d(alpha)/dt (``fluid.ddt_alpha = false``, CFDEM's default;
  DPMFoam has it): the host's ``centre`` rule gives each particle's volume to one cell, and
  with beads on cell faces (Goldschmidt's lattice puts a fifth of them on x = 0) a bead that
  moves by a hair flips its volume between two cells within one gas step; d(alpha)/dt turns
  that into gas speeds of +-17 m/s (500 beads, 6 ms; the inlet gives 1.875 m/s) that kick the
  beads upward (shifted 0.1 mm off the face, the lattice runs clean with it); in a bubbling
  bed every bead crossing a face does the same. ``void_fraction = "divided"`` with
  ``ddt_alpha = true`` keeps both, at about 4 times the cost on the whole tutorial;
- the DEM step: the Hertz collision time of two particles at ``impact_speed`` over the
  pair model's ``collisionResolutionSteps`` (DPMFoam sub-cycles to that many steps per
  collision at the cloud's fastest speed), shortened to divide the gas's deltaT.

What is refused, naming the file and the entry: anything else (another injection, parcels
of several particles, cohesion, another force or sub-model, a mesh that is not one box).
"""
from __future__ import annotations

import gzip
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from foamlib import FoamFile

from plugins.dem.hertz import effective_modulus, hertz_collision_time, restitution_of_tsuji_alpha
from pyhost.engines.fluid_case import drop_phase

DRAG = {"ErgunWenYuDrag": "gidaspow", "WenYuDrag": "wenyu"}
"""DPMFoam's drag models the host has, by the host's law names (plugins/drag)."""
GAS_WALLS = ("noSlip", "slip", "partialSlip")
"""Velocity conditions of a patch that is a wall for the gas."""
FACES = ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")


class DpmfoamError(ValueError):
    """A DPMFoam case the importer cannot translate: the message names the file and entry."""


@dataclass
class Contact:
    """One spring-slider-dashpot contact: E [Pa], nu [-], restitution e [-], friction mu [-]."""
    E: float
    nu: float
    e: float
    mu: float


@dataclass
class Cloud:
    """What the importer reads of a DPMFoam case."""
    phase: str                          # the gas phase's name (continuousPhase)
    positions: np.ndarray               # particle centres (n, 3) [m]
    velocity: np.ndarray                # initial velocity U0 (3,) [m/s]
    diameter: float                     # [m]
    density: float                      # rho0 [kg/m^3]
    pair: Contact                       # particle-particle contact
    walls: dict = field(default_factory=dict)    # patch -> Contact of the particles against it
    resolution: int = 12                # collisionResolutionSteps
    drag: str = "gidaspow"              # the host's drag law
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))   # [m/s^2]
    lo: np.ndarray = field(default_factory=lambda: np.zeros(3))        # the box [m]
    hi: np.ndarray = field(default_factory=lambda: np.zeros(3))
    faces: dict = field(default_factory=dict)   # box face (xlo ...) -> patch
    gas_walls: set = field(default_factory=set)  # patches that are walls for the gas too


def _read(path: Path) -> dict:
    if not path.is_file() and Path(f"{path}.gz").is_file():     # as Debian ships some of them
        path = Path(f"{path}.gz")
    if not path.is_file():
        raise DpmfoamError(f"{path}: no such file (a DPMFoam case has constant/kinematicCloudProperties, "
                           "constant/transportProperties, constant/g, 0/, system/blockMeshDict)")
    try:
        return FoamFile(path).as_dict()
    except Exception as exc:            # foamlib's parse errors
        raise DpmfoamError(f"{path}: cannot be parsed: {str(exc).splitlines()[0]}") from None


def _entry(d, key, where, kind=None):
    if key not in d:
        raise DpmfoamError(f"{where}: {key}: missing")
    value = d[key]
    if kind is float:
        value = getattr(value, "value", value)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise DpmfoamError(f"{where}: {key}: must be a number, got {value!r}")
        return float(value)
    return value


def _only(value, allowed: tuple, where: str, why: str):
    if value not in allowed:
        raise DpmfoamError(f"{where}: {value}: not translated ({why}); the importer reads {', '.join(allowed)}")
    return value


def read_cloud(case: str | Path) -> Cloud:
    """The particles, their contacts, the drag and the box of a DPMFoam case; DpmfoamError
    for anything the importer would not run as DPMFoam does."""
    case = Path(case)
    props_path = case / "constant" / "kinematicCloudProperties"
    props = _read(props_path)
    where = str(props_path)
    solution = _entry(props, "solution", where)
    if not solution.get("coupled", True):
        raise DpmfoamError(f"{where}: solution.coupled: false (the gas does not feel the particles); the host "
                           "always couples them")
    sub = _entry(props, "subModels", where)
    w = f"{where}: subModels"
    _only(sub.get("collisionModel", "none"), ("pairCollision",), f"{w}: collisionModel",
          "parcels that do not collide (MP-PIC's packing models) are not DEM particles")
    coll = _entry(sub, "pairCollisionCoeffs", w)
    wc = f"{w}: pairCollisionCoeffs"
    _only(coll.get("pairModel"), ("pairSpringSliderDashpot",), f"{wc}: pairModel", "Hertz's spring")
    _only(coll.get("wallModel"), ("wallSpringSliderDashpot",), f"{wc}: wallModel", "Hertz's spring")
    const = _entry(props, "constantProperties", where)
    rho = _entry(const, "rho0", f"{where}: constantProperties", float)
    E = _entry(const, "youngsModulus", f"{where}: constantProperties", float)
    nu = _entry(const, "poissonsRatio", f"{where}: constantProperties", float)

    forces = _entry(sub, "particleForces", w) or {}
    drags = [k for k in forces if k != "gravity"]
    for k in drags:
        _only(k, tuple(DRAG), f"{w}: particleForces", "the host's particles feel drag, gravity and the gas's "
              "pressure gradient only")
    if len(drags) != 1:
        raise DpmfoamError(f"{w}: particleForces: one drag model needed ({', '.join(DRAG)}), got "
                           f"{', '.join(drags) or 'none'}")
    for key, off in (("dispersionModel", "none"), ("heatTransferModel", "none"), ("surfaceFilmModel", "none"),
                     ("stochasticCollisionModel", "none")):
        if sub.get(key, off) != off:
            raise DpmfoamError(f"{w}: {key}: {sub[key]}: not translated (only {off})")

    injections = _entry(sub, "injectionModels", w)
    if not isinstance(injections, dict) or len(injections) != 1:
        raise DpmfoamError(f"{w}: injectionModels: one manualInjection model needed, got "
                           f"{', '.join(injections or ()) or 'none'}")
    (name, inj), = injections.items()
    wi = f"{w}: injectionModels.{name}"
    _only(_entry(inj, "type", wi), ("manualInjection",), f"{wi}: type", "particles that arrive later")
    if inj.get("nParticle", 1) != 1 or inj.get("parcelBasisType", "fixed") != "fixed":
        raise DpmfoamError(f"{wi}: nParticle {inj.get('nParticle')}, parcelBasisType "
                           f"{inj.get('parcelBasisType')}: parcels of several particles (MP-PIC) are not DEM "
                           "particles; the importer needs parcelBasisType fixed, nParticle 1")
    if _entry(inj, "SOI", wi, float) != 0:
        raise DpmfoamError(f"{wi}: SOI: {inj['SOI']}: the importer places the particles at the start (SOI 0)")
    size = _entry(inj, "sizeDistribution", wi)
    _only(size.get("type"), ("fixedValue",), f"{wi}: sizeDistribution.type", "one diameter")
    d = _entry(size.get("fixedValueDistribution", size.get("fixedValueCoeffs", {})), "value",
               f"{wi}: sizeDistribution.fixedValueDistribution", float)
    U0 = np.asarray(inj.get("U0", (0, 0, 0)), float)
    positions_name = str(_entry(inj, "positionsFile", wi)).strip('"')
    pos_path = case / "constant" / positions_name
    positions = np.asarray(_read(pos_path)[None], float)
    if positions.ndim != 2 or positions.shape[1] != 3 or not len(positions):
        raise DpmfoamError(f"{pos_path}: not a list of particle positions (x y z)")

    pair = _entry(coll, "pairSpringSliderDashpotCoeffs", wc)
    wall = _entry(coll, "wallSpringSliderDashpotCoeffs", wc)
    for label, c in (("pairSpringSliderDashpotCoeffs", pair), ("wallSpringSliderDashpotCoeffs", wall)):
        wl = f"{wc}: {label}"
        if _entry(c, "b", wl, float) != 1.5:
            raise DpmfoamError(f"{wl}: b: {c['b']}: the importer translates Hertz's spring (b 1.5) only")
        if float(c.get("cohesionEnergyDensity", 0)) != 0:
            raise DpmfoamError(f"{wl}: cohesionEnergyDensity: {c['cohesionEnergyDensity']}: cohesion is not "
                               "translated (0 only)")
    pw, ww = f"{wc}: pairSpringSliderDashpotCoeffs", f"{wc}: wallSpringSliderDashpotCoeffs"
    pair_contact = Contact(E, nu, restitution_of_tsuji_alpha(_entry(pair, "alpha", pw, float)),
                           _entry(pair, "mu", pw, float))
    wall_contact = Contact(_entry(wall, "youngsModulus", ww, float), _entry(wall, "poissonsRatio", ww, float),
                           restitution_of_tsuji_alpha(_entry(wall, "alpha", ww, float)), _entry(wall, "mu", ww, float))
    resolution = int(_entry(pair, "collisionResolutionSteps", pw, float))

    transport = _read(case / "constant" / "transportProperties")
    phase = str(transport.get("continuousPhase", ""))
    g = np.asarray(_entry(_read(case / "constant" / "g"), "value", str(case / "constant" / "g")), float)
    if "gravity" not in forces:         # DPMFoam's particles feel gravity only with this force
        g = np.zeros(3)
    lo, hi, faces, types = _box(case)
    U = _read(case / "0" / (f"U.{phase}" if phase else "U")).get("boundaryField", {})
    gas_walls = {p for p in types if isinstance(U.get(p), dict) and U[p].get("type") in GAS_WALLS}

    rebound = _rebound(sub, w)
    walls = {}
    for face, patch in faces.items():
        if types[patch] == "wall":
            walls[patch] = wall_contact
        elif rebound(patch) is not None:
            walls[patch] = Contact(E, nu, *rebound(patch))
        else:
            raise DpmfoamError(f"{w}: patchInteractionModel: no rebound rule for the patch {patch!r} ({face} of the "
                               "box), which is not a wall: particles would leave through it; the importer keeps "
                               "every particle (type rebound)")
    return Cloud(phase, positions, U0, d, rho, pair_contact, walls, resolution, DRAG[drags[0]], g, lo, hi, faces,
                 gas_walls)


def _rebound(sub: dict, where: str):
    """patch -> (e, mu) of the patch interaction model's rebound rules (None: no rule)."""
    model = sub.get("patchInteractionModel", "none")
    if model == "localInteraction":
        rules = dict(_entry(sub, "localInteractionCoeffs", where).get("patches", []))
    elif model == "standardWallInteraction":        # one rule for every patch
        rules = {None: _entry(sub, "standardWallInteractionCoeffs", where)}
    else:
        rules = {}
    for patch, rule in rules.items():
        if rule.get("type") != "rebound":
            raise DpmfoamError(f"{where}: {model}: {patch or 'every patch'}: type {rule.get('type')}: the importer "
                               "translates rebound only (every particle stays)")

    def of(patch):
        rule = rules.get(patch, rules.get(None))
        return None if rule is None else (float(rule.get("e", 1.0)), float(rule.get("mu", 0.0)))
    return of


def _box(case: Path):
    """(lo, hi, {face: patch}, {patch: type}) of a mesh that is one axis-aligned box (one hex
    block of system/blockMeshDict, each boundary face on one face of the box)."""
    path = case / "system" / "blockMeshDict"
    mesh = _read(path)
    scale = float(mesh.get("scale", mesh.get("convertToMeters", 1.0)))
    vertices = np.asarray(mesh.get("vertices", []), float) * scale
    blocks = mesh.get("blocks", [])
    hexes = [blocks[k + 1] for k in range(len(blocks) - 1) if blocks[k] == "hex"]
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    corners = np.all((np.isclose(vertices, lo) | np.isclose(vertices, hi)), axis=1)
    if len(hexes) != 1 or len(vertices) != 8 or not corners.all() or mesh.get("edges"):
        raise DpmfoamError(f"{path}: the importer translates a mesh that is one axis-aligned box (one hex block, "
                           "8 corner vertices, no curved edges): the walls of its particles are the box's faces")
    faces, types = {}, {}
    for name, entry in mesh.get("boundary", []):
        types[name] = entry.get("type", "patch")
        for quad in entry.get("faces", []):
            pts = vertices[list(quad)]
            for axis in range(3):
                for side, value in (("lo", lo[axis]), ("hi", hi[axis])):
                    if np.allclose(pts[:, axis], value):
                        faces["xyz"[axis] + side] = name
    missing = [f for f in FACES if f not in faces]
    if missing:
        raise DpmfoamError(f"{path}: boundary: no patch on the box's face {', '.join(missing)} (every face needs "
                           "its patch: the particles' walls)")
    return lo, hi, faces, types


def dem_step(cloud: Cloud, deltaT: float, impact_speed: float = 1.0) -> tuple[float, int]:
    """(DEM step [s], DEM steps per gas step): the Hertz collision time of two particles at
    ``impact_speed`` [m/s] (eq. 32) over the cloud's collisionResolutionSteps, shortened to
    divide the gas step ``deltaT`` [s] into whole steps."""
    r = cloud.diameter / 2
    m = cloud.density * math.pi * cloud.diameter**3 / 6
    Estar = effective_modulus(cloud.pair.E, cloud.pair.nu, cloud.pair.E, cloud.pair.nu)
    t_c = hertz_collision_time(Estar, r / 2, m / 2, impact_speed)
    n = max(1, math.ceil(deltaT / (t_c / cloud.resolution) - 1e-9))
    return deltaT / n, n


def convert(case: str | Path, out: str | Path, impact_speed: float = 1.0, hot_below: float | None = None,
            temperatures: tuple[float, float] = (400.0, 300.0)) -> dict:
    """Write ``out`` (CFD/, DEM/in.liggghts, DEM/particles.data, case.toml) from the DPMFoam
    ``case``; returns what was chosen (for the command's report). The case is only read.
    DPMFoam's particles have no temperature: all start at ``temperatures[1]`` [K], or with
    ``hot_below`` [m] those whose centre is below that height z at ``temperatures[0]``: atom
    type 1 (hot) and 2 (cold), one material with a temperature per type."""
    case, out = Path(case), Path(out)
    cloud = read_cloud(case)
    control = _read(case / "system" / "controlDict")
    deltaT = _entry(control, "deltaT", str(case / "system" / "controlDict"), float)
    dt, every = dem_step(cloud, deltaT, impact_speed)
    inside = np.all((cloud.positions - cloud.diameter / 2 >= cloud.lo - 1e-12)
                    & (cloud.positions + cloud.diameter / 2 <= cloud.hi + 1e-12), axis=1)
    if not inside.all():
        k = int(np.flatnonzero(~inside)[0])
        raise DpmfoamError(f"{case}/constant: particle {k + 1} at {cloud.positions[k].tolist()} reaches outside the "
                           f"box {cloud.lo.tolist()} - {cloud.hi.tolist()}")

    if hot_below is not None and not cloud.lo[2] < hot_below < cloud.hi[2]:
        raise DpmfoamError(f"hot_below: {hot_below!r} m is not inside the box's z range "
                           f"{cloud.lo[2]!r} - {cloud.hi[2]!r} m")
    if not all(math.isfinite(T) and T > 0 for T in temperatures):
        raise DpmfoamError(f"temperatures: must be positive [K], got {tuple(temperatures)!r}")
    kind = (np.where(cloud.positions[:, 2] < hot_below, 1, 2) if hot_below is not None
            else np.ones(len(cloud.positions), int))

    cfd, dem = out / "CFD", out / "DEM"
    if out.exists():
        raise DpmfoamError(f"{out}: exists; the importer writes a new folder")
    for sub in ("0", "constant", "system"):
        for src in sorted((case / sub).rglob("*")):
            if (src.is_dir() or src.name.startswith("kinematicCloud") or src.name.endswith(("~", ".orig"))
                    or "polyMesh" in src.parts):        # built again from blockMeshDict, its patches retyped
                continue
            rel = str(src.relative_to(case)).removesuffix(".gz")        # OpenFOAM reads either
            dst = cfd / drop_phase(rel, cloud.phase)
            dst.parent.mkdir(parents=True, exist_ok=True)
            try:
                with gzip.open(src, "rt") if src.suffix == ".gz" else open(src) as f:
                    text = f.read()
            except (UnicodeDecodeError, gzip.BadGzipFile):
                raise DpmfoamError(f"{src}: not a text file (the importer reads OpenFOAM's ascii files)") from None
            dst.write_text(drop_phase(text, cloud.phase))
    block = FoamFile(cfd / "system" / "blockMeshDict")
    boundary = block["boundary"]
    retyped = [name for name, entry in boundary if entry.get("type") == "wall" and name not in cloud.gas_walls]
    block["boundary"] = [(name, {**entry, "type": "patch"} if name in retyped else entry) for name, entry in boundary]

    dem.mkdir(parents=True)
    beads = int(kind.max())             # the particles' atom types: 1, or 1 (hot) and 2 (cold)
    _write_data(dem / "particles.data", cloud, kind)
    (dem / "in.liggghts").write_text(_script(cloud, dt, case, beads))
    (out / "case.toml").write_text(_scene(cloud, every, case, beads, temperatures))
    return dict(particles=len(cloud.positions), dt=dt, couple_every=every, deltaT=deltaT,
                e_pair=cloud.pair.e, walls={p: c.e for p, c in cloud.walls.items()}, retyped=retyped,
                drag=cloud.drag, hot=int(np.sum(kind == 1)) if beads == 2 else 0)


def _types(cloud: Cloud, beads: int) -> list[Contact]:
    """LIGGGHTS' atom types: the particles' (``beads`` of them, one contact), then one per
    distinct wall contact."""
    kinds = [cloud.pair] * beads
    for c in cloud.walls.values():
        if c not in kinds[beads:]:
            kinds.append(c)
    return kinds


def _write_data(path: Path, cloud: Cloud, kind: np.ndarray) -> None:
    n = len(cloud.positions)
    lines = ["LIGGGHTS data file: the particles of a DPMFoam case's manualInjection (pyhost dpmfoam)", "",
             f"{n} atoms", f"{len(_types(cloud, int(kind.max())))} atom types", ""]
    lines += [f"{lo!r} {hi!r} {a}lo {a}hi" for lo, hi, a in zip(cloud.lo.tolist(), cloud.hi.tolist(), "xyz")]
    lines += ["", "Atoms", ""]
    lines += [f"{k + 1} {t} {cloud.diameter!r} {cloud.density!r} {x!r} {y!r} {z!r}"
              for k, (t, (x, y, z)) in enumerate(zip(kind.tolist(), cloud.positions.tolist()))]
    if np.any(cloud.velocity):
        u = " ".join(repr(c) for c in cloud.velocity.tolist())
        lines += ["", "Velocities", ""] + [f"{k + 1} {u} 0 0 0" for k in range(n)]
    path.write_text("\n".join(lines) + "\n")


def _script(cloud: Cloud, dt: float, case: Path, beads: int) -> str:
    kinds = _types(cloud, beads)
    n = len(kinds)
    E = " ".join(f"{k.E!r}" for k in kinds)
    nu = " ".join(f"{k.nu!r}" for k in kinds)

    def matrix(value):
        rows = []
        for i in range(n):
            rows.append(" ".join(f"{value(i, j)!r}" for j in range(n)))
        return " &\n\t".join(rows)

    def of(i, j, what):             # particle-particle: the pair's; particle-wall: the wall's
        k = max(i, j)
        return getattr(kinds[k] if min(i, j) < beads else cloud.pair, what)

    g = float(np.linalg.norm(cloud.gravity))
    gravity = (f"fix\tgravi all gravity {g!r} vector " + " ".join(f"{c!r}" for c in (cloud.gravity / g).tolist())
               if g else "# no gravity force (DPMFoam's particleForces have none)")
    walls = []
    for face in FACES:
        patch = cloud.faces[face]
        axis, side = face[0], face[1:]
        at = float((cloud.lo if side == "lo" else cloud.hi)["xyz".index(axis)])
        walls.append(f"fix\twall_{patch}_{face} all wall/gran model hertz tangential history primitive type "
                     f"{kinds.index(cloud.walls[patch], beads) + 1} {axis}plane {at!r}")
    walls_said = ", ".join(f"{k + 1} walls of e = {c.e:.4f}, mu = {c.mu:g}" for k, c in enumerate(kinds)
                           if k >= beads)
    return f"""# The particles of the DPMFoam case {case} (constant/kinematicCloudProperties), written by
# 'python -m pyhost dpmfoam' (pyhost/engines/dpmfoam_case.py says what maps to what).
# Atom types: {"1 the particles" if beads == 1 else "1 the hot particles, 2 the cold ones"}; {walls_said}.

atom_style\tgranular
atom_modify\tmap array
boundary\tf f f
newton\t\toff
communicate\tsingle vel yes
units\t\tsi

read_data\tDEM/particles.data        # paths from the case folder, where case.toml is

neighbor\t{cloud.diameter / 4!r} bin
neigh_modify\tdelay 0

fix\tm1 all property/global youngsModulus peratomtype {E}
fix\tm2 all property/global poissonsRatio peratomtype {nu}
# restitution: the damping of DPMFoam's alpha (pair {cloud.pair.e:.6f}), the same law as LIGGGHTS' hertz
fix\tm3 all property/global coefficientRestitution peratomtypepair {n} &
\t{matrix(lambda i, j: of(i, j, 'e'))}
fix\tm4 all property/global coefficientFriction peratomtypepair {n} &
\t{matrix(lambda i, j: of(i, j, 'mu'))}

pair_style\tgran model hertz tangential history
pair_coeff\t* *

timestep\t{dt!r}

{gravity}
{chr(10).join(walls)}

fix\tintegr all nve/sphere

# the gas drives the run: as long as the case's controlDict says (or [time] end)
run\t0
"""


def _scene(cloud: Cloud, every: int, case: Path, beads: int, temperatures) -> str:
    T_hot, T_cold = (float(T) for T in temperatures)
    types, T = ("[1]", f"{T_cold!r}") if beads == 1 else ("[1, 2]", f"[{T_hot!r}, {T_cold!r}]")
    return f"""# The DPMFoam case
#   {case}
# as written by 'python -m pyhost dpmfoam'. DPMFoam's particles have no temperature and no
# real material: give yours below (the host refuses the run until each required key is
# there), then: python -m pyhost run THIS_FOLDER

[dem]
script = "DEM/in.liggghts"

[effects]
fluid = true
contact_heat = "A"

[fluid]
case = "CFD"
drag = "{cloud.drag}"          # DPMFoam's drag model
ddt_alpha = false          # DPMFoam solves d(alpha)/dt: pyhost/engines/dpmfoam_case.py says why not

[time]
couple_every = {every}           # DEM steps per gas step (the case's deltaT)

[materials.particles]
types = {types}
density = {cloud.density!r:<14s} # kg/m^3, the case's rho0
temperature = {T}     # K, per type: DPMFoam's particles have none
# the real material, for the contact heat model (DPMFoam's youngsModulus {cloud.pair.E:g} Pa
# is the DEM's softened one):
# youngs_modulus =         # Pa
# poisson_ratio =
# yield_stress =           # Pa
# heat_capacity =          # J/(kg K)
# conductivity =           # W/(m K)
"""
