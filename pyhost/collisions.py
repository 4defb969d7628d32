"""The collision pipeline, one for a run (``pyhost.effects.collisions``), each MPI rank
(``pyhost.effects.rank_heat``) and post (``pyhost.post``): a batch of begun contacts and their
bodies in, each collision's heat Q [J], restitution e [-], duration t_coll [s] and whether it
is outside the contact models' range out (the plugin's ``plugins.heat.batch``). No engine calls.

- Partners. A contact is particle i with partner j: a particle id, or a wall's code
  ``WALL_BASE + w``, w the flat index of the host's walls, one per LIGGGHTS wall fix and mesh
  (a primitive wall is one, a fix wall/gran of n meshes n: a particle touching two meshes of
  one fix at once has two collisions, as it has two contacts). ``wall_code``, ``wall_of``.
- Keys. One int64 per contact, the same on every rank and after a restart (``contact_keys``:
  the collision log, the recorder's restitution speeds, the joining of contacts that change
  rank, post's first appearances).
- Bodies. The material (index into the scene's materials, DEM contact resolved), radius [m]
  and mass [kg] of both partners (``Bodies.partners``): an atom type's material from the
  scene's ``types`` (``material_of``), a wall's its own or the particle's, a wall's radius and
  mass infinite; a sphere's mass 4/3 pi R^3 rho (``sphere_mass``) where the engine gives none.
- Geometry. The minimum image of a separation in a periodic box (``minimum_image``).
- Begun contacts. The run's recorder sees each begin inside LIGGGHTS; post sees a contact
  begun where it first appears in a list of contacts (``FirstAppearances``); ``ended_later``:
  which contacts ended before the host looked.
- Impact speeds. The run's recorder takes each at first touch; from dumps, a contact's
  approach speed at its first appearance is carried back to touch with the DEM's own contact
  law (``carried_back``), whose shortest collision bounds what dumps can resolve
  (``shortest_collision``).
- Heat. ``collide``: the batch's heat moved in its order between the bodies' temperatures
  (``plugins.heat.batch.move_heat``); ``conductances``: one model's heat per kelvin over a
  batch, for post, which moves it while it replays the dumps.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plugins.dem.hertz import DemHertz, hertz_collision_time, impact_speeds, reduced
from plugins.heat.batch import dem_pair, evaluate_flagged, move_heat
from plugins.heat.exchange import WALL_BASE


def contact_keys(i, j):
    """One int64 key per contact: i and j are particle ids (j may be a wall code)."""
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    if np.any(np.minimum(i, j) < 0) or np.any(np.minimum(i, j) >= WALL_BASE):
        raise ValueError(f"particle ids must lie in [0, {WALL_BASE})")
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    return (lo << 31) | hi


def wall_code(w):
    """The partner code of the host's wall number ``w`` (flat index: one per wall fix and mesh)."""
    return WALL_BASE + np.asarray(w, np.int64)


def wall_of(j):
    """For partners ``j`` (particle ids or wall codes): whether each is a wall, and its wall
    number (0 for a particle)."""
    j = np.asarray(j, np.int64)
    wall = j >= WALL_BASE
    return wall, np.where(wall, j - WALL_BASE, 0)


def log_wall(j, number=None):
    """The collision log's ``wall`` column: 0 for a particle partner, else 1 + the wall's number
    (``number[w]`` where the log numbers walls otherwise: post's [[walls]] entries)."""
    wall, w = wall_of(j)
    if number is not None:
        w = np.r_[np.asarray(number, np.int64), 0][w]       # (0 where j is a particle, with no walls)
    return np.where(wall, w + 1, 0)


def sphere_mass(radius, density):
    """Mass [kg] of spheres of radius [m] and density [kg/m^3]."""
    return 4.0 / 3.0 * np.pi * radius**3 * density


def minimum_image(d, size, periodic):
    """Separations ``d`` (n, 3) [m] brought to their nearest periodic image in a box of edge
    lengths ``size`` (3,) [m], along the periodic axes only."""
    return d - np.where(periodic, size * np.round(d / size), 0.0)


def material_of(type_material, types, where: str | None = None):
    """Material index of LIGGGHTS atom types (``type_material``: index = type, -1 none); -1
    for a type beyond the table, or with ``where`` (the scene file) an error naming the types."""
    table = np.asarray(type_material)
    types = np.asarray(types)
    mat = np.where(types < len(table), table[np.minimum(types, len(table) - 1)], -1)
    if where is not None and (mat < 0).any():
        from pyhost.engines.liggghts.script import ScriptError
        bad = sorted(set(types[mat < 0].tolist()))
        raise ScriptError(f"{where}: atom type(s) {bad} have no material: name them in a "
                          "[materials.NAME] types = [...] list")
    return mat


@dataclass(frozen=True)
class Partners:
    """Both bodies of each collision: whether j is a wall and its number, materials, radii
    [m] and masses [kg] (inf for a wall)."""

    wall: np.ndarray
    w: np.ndarray
    mat_i: np.ndarray
    mat_j: np.ndarray
    R_i: np.ndarray
    R_j: np.ndarray
    m_i: np.ndarray | None
    m_j: np.ndarray | None

    def __getitem__(self, k) -> "Partners":
        """These collisions' partners at ``k`` (a mask or indices)."""
        return Partners(*(None if a is None else a[k] for a in (self.wall, self.w, self.mat_i, self.mat_j, self.R_i,
                                                                   self.R_j, self.m_i, self.m_j)))


@dataclass(frozen=True)
class Bodies:
    """The one lookup of collision bodies: ``materials`` (pyhost.schema.Material, their DEM
    contact resolved), the material of each atom type (``type_material``, index = type, -1
    none) and of each wall by number (``wall_material``, -1: the particle's own)."""

    materials: list
    type_material: np.ndarray
    wall_material: np.ndarray

    def partners(self, j, mat_i, R_i, mat_j, R_j, m_i=None, m_j=None) -> Partners:
        """The partners of particles of materials ``mat_i`` and radii ``R_i`` [m] with partners
        ``j`` (ids or wall codes), whose particle materials, radii and masses are ``mat_j``,
        ``R_j`` and ``m_j`` where j is a particle (read nowhere else); masses [kg] as the engine
        has them, or None: spheres of the materials' densities."""
        wall, w = wall_of(j)
        wm = (np.asarray(self.wall_material)[w] if len(self.wall_material) else np.full(len(w), -1))
        mj = np.where(wall, np.where(wm >= 0, wm, mat_i), mat_j)
        R_j = np.where(wall, np.inf, R_j)
        if m_i is None:
            density = np.array([m.density for m in self.materials])
            m_i = sphere_mass(R_i, density[mat_i])
            m_j = sphere_mass(R_j, density[mj])
        m_j = np.where(wall, np.inf, m_j)
        return Partners(wall, w, mat_i, mj, R_i, R_j, m_i, m_j)


def collide(models, path, bodies: Bodies, p: Partners, v0, T, C, i, j, T_wall, shift=None):
    """A batch of collisions in their order: the first of ``models`` moves each one's heat
    between T [K] (changed in place; C = m c [J/K]; i, j indices into them, j a wall code for
    a wall) at impact speed v0 [m/s], the others give side columns (``move_heat``; ``path``:
    the plugin's ``fast`` or ``ode``; ``shift`` [K]: a change of each temperature difference).
    Returns the columns (Q [J] moved from i to j, e, t_coll [s], Q_<model>), whether each is
    outside the models' range, and how many were capped."""
    return move_heat(models, path, bodies.materials, p.mat_i, p.mat_j, p.R_i, p.R_j, v0, T, C, i, j, T_wall, shift)


def conductances(model, path, bodies: Bodies, p: Partners, v0):
    """One model's heat per kelvin G [J/K], e [-], t_coll [s] and range flags of a batch of
    collisions (``evaluate_flagged`` at a difference of 1 K)."""
    return evaluate_flagged(model, path, bodies.materials, p.mat_i, p.mat_j, p.R_i, p.R_j, v0, np.ones(len(v0)))


def ended_later(begin, ends) -> np.ndarray:
    """Whether each begun contact (its ``i``, ``j``, ``step``) has an end among ``ends`` after
    its begin: a contact shorter than the interval between two looks at the events."""
    last = {}
    for k, s in zip(contact_keys(ends["i"], ends["j"]).tolist(), ends["step"].tolist()):
        last[k] = max(s, last.get(k, s))
    return np.array([last.get(k, -1) > s for k, s in zip(contact_keys(begin["i"], begin["j"]).tolist(),
                                                          begin["step"].tolist())], bool)


class FirstAppearances:
    """Contacts begun between two looks at a stream of contact lists (post's dumps): the keys
    of the previous list; ``new(keys)`` gives which of these are new (begun since)."""

    def __init__(self):
        self.previous = np.empty(0, np.int64)

    def new(self, keys):
        fresh = ~np.isin(keys, self.previous)
        self.previous = keys
        return fresh


def dem_laws(bodies: Bodies, p: Partners, names: list, where) -> dict:
    """The DEM's contact law of each pair of materials that collide: (a, b) -> (Y* [Pa],
    ``plugins.dem.hertz.DemHertz``); ValueError naming a material without its DEM values
    (``names``: the materials' names in ``where``, the scene file)."""
    mats, laws = bodies.materials, {}
    for a, b in set(zip(p.mat_i.tolist(), p.mat_j.tolist())):
        for k in (a, b):
            if mats[k].dem is None:
                raise ValueError(f"{where}: materials.{names[k]}.dem: post recovers impact speeds with the DEM's "
                                 "contact law: give the table (youngs_modulus, restitution, poisson_ratio), or "
                                 "--script with the script's values")
        dem = dem_pair(mats[a], mats[b])
        laws[a, b] = (dem.Ystar, DemHertz(dem.Ystar, dem.restitution))
    return laws


def carried_back(bodies: Bodies, p: Partners, approach, delta, window, names: list, where) -> np.ndarray:
    """Impact speeds [m/s] of contacts first seen with overlap ``delta`` [m] at approach speed
    ``approach`` [m/s], up to ``window`` [s] after they began: carried back to touch with the
    DEM's contact law (``plugins.dem.hertz.impact_speeds``)."""
    R, m = reduced(p.R_i, p.R_j, p.m_i, p.m_j)
    laws = dem_laws(bodies, p, names, where)
    return impact_speeds(approach, lambda a, b: laws[a, b][1], p.mat_i, p.mat_j, delta, approach, R, m, window,
                         mask=delta > 0)


def shortest_collision(bodies: Bodies, p: Partners, v0, names: list, where) -> tuple[float, float]:
    """The DEM's shortest Hertz collision time [s] among these collisions at the fastest impact
    seen (1 m/s if none), and that speed [m/s]."""
    R, m = reduced(p.R_i, p.R_j, p.m_i, p.m_j)
    mi, mj = p.mat_i, p.mat_j
    v = float(v0.max()) if np.any(v0 > 0) else 1.0
    return min(hertz_collision_time(Y, R[(mi == a) & (mj == b)].min(), m[(mi == a) & (mj == b)].min(), v)
               for (a, b), (Y, _) in dem_laws(bodies, p, names, where).items()), v


@dataclass
class Found:
    """Collisions found (post: first appearances in dumps): each one's step, particle ``i``,
    partner ``j``, overlap ``delta`` [m] and approach speed [m/s] when first seen, and the
    ``window`` [s] since the look before; lists of arrays until ``array()`` gives them in the
    order of their steps."""

    columns = ("step", "i", "j", "delta", "approach", "window")
    parts: dict = field(default_factory=lambda: {c: [] for c in Found.columns})

    def add(self, **arrays) -> None:
        for c in self.columns:
            self.parts[c].append(np.broadcast_to(arrays[c], np.shape(arrays["i"])).astype(float))

    def count(self) -> int:
        return sum(len(a) for a in self.parts["i"])

    def array(self) -> dict:
        out = {c: np.concatenate(v) if v else np.zeros(0) for c, v in self.parts.items()}
        order = np.argsort(out["step"], kind="stable")
        out = {c: a[order] for c, a in out.items()}
        out["i"], out["j"] = out["i"].astype(np.int64), out["j"].astype(np.int64)
        return out
