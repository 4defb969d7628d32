"""The LIGGGHTS input of a scene: every value taken from the scene, none typed twice.

``place_particles(scene)`` puts each [[particles]] group in its region (explicit
``positions`` or a jittered lattice, deterministic), ``write_data`` writes them as a
LIGGGHTS data file, and ``input_lines`` gives the commands that build the DEM: granular SI
setup, one atom type per material, the DEM's softened Hertz contact from each material's
``dem`` table, box walls, gravity, integration. Per-type-pair values (restitution,
friction) follow LIGGGHTS' rule of one value per pair of types: the mean of the two.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plugins.dem.hertz import effective_modulus, hertz_collision_time
from pyhost.collisions import sphere_mass
from pyhost.schema import Scene, SceneError
from pyhost.walls import face_primitive



@dataclass(frozen=True)
class Particles:
    """Per-particle arrays (SI), ids 1..N in this order."""

    position: np.ndarray        # (N, 3) [m]
    velocity: np.ndarray        # (N, 3) [m/s]
    radius: np.ndarray          # [m]
    density: np.ndarray         # [kg/m^3]
    temperature: np.ndarray     # [K]
    material: np.ndarray        # index into scene.materials (atom type - 1)
    group: np.ndarray           # index of the scene's [[particles]] group

    @property
    def mass(self):
        return sphere_mass(self.radius, self.density)


NUM = "%.17g"
"""A number as LIGGGHTS reads it, with every digit of the double."""


def num(x) -> str:
    return NUM % float(x)


def material_index(scene: Scene) -> dict:
    return {name: k for k, name in enumerate(scene.materials)}


def place_particles(scene: Scene, seed: int = 12345) -> Particles:
    """Positions of every group: its explicit positions, else a jittered simple-cubic lattice
    filling its region with spacing 2.1 radii (no initial overlaps)."""
    rng = np.random.default_rng(seed)
    index = material_index(scene)
    parts = []
    for k, g in enumerate(scene.particles):
        if g.positions:
            pos = np.asarray(g.positions, float)
        else:
            lo, hi = np.array(g.region[0::2], float), np.array(g.region[1::2], float)
            spacing = 2.1 * g.radius                     # half a spacing from each face: the
            n = np.floor((hi - lo - spacing) / spacing).astype(int) + 1   # jitter never reaches a wall
            if np.any(n < 1) or n.prod() < g.count:
                raise SceneError(f"{scene.path}: particles[{k}].region: holds {max(int(n.prod()), 0)} "
                                 f"particles of radius {g.radius} m, not {g.count}")
            cells = np.stack(np.meshgrid(*(np.arange(m) for m in n), indexing="ij"), -1).reshape(-1, 3)
            cells = cells[np.argsort(cells[:, 2], kind="stable")][: g.count]   # fill from the bottom
            jitter = rng.uniform(-0.04, 0.04, cells.shape) * g.radius
            pos = lo + 0.5 * spacing + cells * spacing + jitter
        vel = np.asarray(g.velocity, float) + rng.normal(0.0, 1.0, pos.shape) * g.velocity_spread
        parts.append((pos, vel, g))
    mats = scene.materials
    return Particles(
        position=np.concatenate([p for p, _, _ in parts]),
        velocity=np.concatenate([v for _, v, _ in parts]),
        radius=np.concatenate([np.full(len(p), g.radius) for p, _, g in parts]),
        density=np.concatenate([np.full(len(p), mats[g.material].density) for p, _, g in parts]),
        temperature=np.concatenate([np.full(len(p), g.temperature) for p, _, g in parts]),
        material=np.concatenate([np.full(len(p), index[g.material]) for p, _, g in parts]),
        group=np.concatenate([np.full(len(p), k) for k, (p, _, _) in enumerate(parts)]),
    )


def write_data(path: Path, scene: Scene, particles: Particles) -> Path:
    """A LIGGGHTS data file (atom_style granular: id type diameter density x y z), written
    DATA_CHUNK atoms at a time: the lines of 1,000,000 atoms held at once as Python strings,
    joined, took some 500 MB (rank 0's peak under MPI)."""
    box = scene.domain.box
    head = ["LIGGGHTS data file written by pyhost", "", f"{len(particles.radius)} atoms",
            f"{len(scene.materials)} atom types", "",
            f"{num(box[0])} {num(box[1])} xlo xhi", f"{num(box[2])} {num(box[3])} ylo yhi",
            f"{num(box[4])} {num(box[5])} zlo zhi",
            "", "Atoms", ""]
    n = len(particles.radius)
    atom = " ".join(["%d", "%d"] + [NUM] * 5)       # (one % per line: 27,000 atoms in 0.1 s, not 0.2)
    speed = " ".join(["%d"] + [NUM] * 3) + " 0 0 0"
    material, diameter = np.asarray(particles.material) + 1, 2 * np.asarray(particles.radius, float)
    density = np.broadcast_to(np.asarray(particles.density, float), (n,))
    position, velocity = np.asarray(particles.position, float), np.asarray(particles.velocity, float)

    def atoms(a, b):
        return [atom % row for row in zip(range(a + 1, b + 1), material[a:b].tolist(), diameter[a:b].tolist(),
                                          density[a:b].tolist(), *position[a:b].T.tolist())]

    def velocities(a, b):
        return [speed % row for row in zip(range(a + 1, b + 1), *velocity[a:b].T.tolist())]

    from pyhost.output import naming
    with naming(path), open(path, "w") as f:
        f.write("\n".join(head) + "\n")
        for lines, middle in ((atoms, ["", "Velocities", ""]), (velocities, [])):
            for a in range(0, n, DATA_CHUNK):
                f.write("\n".join(lines(a, min(a + DATA_CHUNK, n))) + "\n")
            if middle:
                f.write("\n".join(middle) + "\n")
    return path


DATA_CHUNK = 50_000
"""Atoms per piece of a data file written at once (``write_data``)."""


def input_lines(scene: Scene, data_file: Path, skin: float | None = None) -> list[str]:
    """LIGGGHTS commands that build the scene's DEM from its data file (nothing is run)."""
    mats = list(scene.materials.values())
    n = len(mats)
    r_max = max(g.radius for g in scene.particles)
    skin = 0.5 * r_max if skin is None else skin
    periodic = " ".join("p" if p else "f" for p in scene.domain.periodic)
    pairwise = lambda f: " ".join(num(0.5 * (f(a) + f(b))) for a in mats for b in mats)
    g = np.asarray(scene.domain.gravity, float)
    g_mag = float(np.linalg.norm(g))
    lines = [
        "atom_style granular", "atom_modify map array", f"boundary {periodic}", "newton off",
        "communicate single vel yes", "units si",
    ]
    if any(m.dem.youngs_modulus > 1e9 for m in mats):
        lines.append("hard_particles yes")
    if g_mag > 0:
        # Under mpirun: cut the domain across the widest horizontal axis, not along gravity
        # (LIGGGHTS' default for a tall box), where the settled bed would sit on one rank.
        up = int(np.argmax(np.abs(g)))
        extent = np.subtract(scene.domain.box[1::2], scene.domain.box[0::2])
        across = max((a for a in range(3) if a != up), key=lambda a: extent[a])
        lines.append("processors " + " ".join("*" if a == across else "1" for a in range(3)))
    lines += [
        f"read_data {data_file}",
        f"neighbor {num(skin)} bin", "neigh_modify delay 0",
        "fix m1 all property/global youngsModulus peratomtype " + " ".join(num(m.dem.youngs_modulus) for m in mats),
        "fix m2 all property/global poissonsRatio peratomtype " + " ".join(num(m.dem.poisson_ratio) for m in mats),
        f"fix m3 all property/global coefficientRestitution peratomtypepair {n} " + pairwise(lambda m: m.dem.restitution),
        f"fix m4 all property/global coefficientFriction peratomtypepair {n} " + pairwise(lambda m: m.dem.friction),
        "pair_style gran model hertz tangential history",
        "pair_coeff * *",
        f"timestep {num(scene.time.dem_step)}",
    ]
    if g_mag > 0:
        lines.append(f"fix gravity all gravity {num(g_mag)} vector " + " ".join(num(c / g_mag) for c in g))
    index = material_index(scene)
    for k, w in enumerate(scene.walls):
        kind, (position,) = face_primitive(w.plane, scene.domain.box)
        # with enduring conduction heat/gran conducts from a wall at a temperature too (its share
        # during each collision is taken back, as for pairs)
        hot = f" temperature {num(w.temperature)}" if scene.effects.enduring_conduction and w.temperature > 0 else ""
        lines.append(f"fix wall{k} all wall/gran model hertz tangential history primitive "
                     f"type {index[w.material] + 1} {kind} {num(position)}{hot}")
    if scene.effects.enduring_conduction:       # LIGGGHTS' own conduction through lasting contacts
        lines += ["fix m5 all property/global thermalConductivity peratomtype " + " ".join(num(m.conductivity) for m in mats),
                  "fix m6 all property/global thermalCapacity peratomtype " + " ".join(num(m.heat_capacity) for m in mats),
                  "fix heat all heat/gran initial_temperature 0"]
    lines += ["fix integrate all nve/sphere", "thermo_style custom step atoms ke", "thermo 100000"]
    return lines


def dem_collision_time(scene: Scene, v: float) -> float:
    """Shortest Hertz collision time of the DEM among the scene's particles at impact speed
    v [m/s] (eq. 32 with the DEM's softened modulus) [s]: the DEM step must resolve it."""
    times = []
    for grp in scene.particles:
        m = scene.materials[grp.material]
        E = effective_modulus(m.dem.youngs_modulus, m.dem.poisson_ratio, m.dem.youngs_modulus, m.dem.poisson_ratio)
        mass = sphere_mass(grp.radius, m.density)
        times.append(hertz_collision_time(E, grp.radius / 2.0, mass / 2.0, v))
    return min(times)


SCRIPT_DEM = (("youngs_modulus", "youngsModulus"), ("poisson_ratio", "poissonsRatio"),
              ("restitution", "coefficientRestitution"), ("friction", "coefficientFriction"))
"""DemContact field and the script's property/global that sets it (per type, or per type pair
for restitution and friction, read on the diagonal)."""


def script_dem_contacts(scene, dem) -> list:
    """The scene's materials with the DEM contact the user's script sets (``dem``: the engine
    after the script's set-up): that of the material's first atom type, or for a wall material
    the type of the first [[walls]] fix made of it. A ``[materials.X].dem`` table given as well
    must agree on what it states (youngs_modulus, restitution, and poisson_ratio or friction
    where they differ from their defaults): ScriptError naming both places otherwise. A
    material with neither a type nor a wall keeps its table (None: never needed)."""
    import dataclasses

    from pyhost.schema import DemContact
    from pyhost.engines.liggghts.script import ScriptError

    wall_of = {}
    for w in scene.walls:
        wall_of.setdefault(w.material, w.fix)
    defaults = DemContact(youngs_modulus=1.0, restitution=1.0)
    out = []
    for name, m in scene.materials.items():
        t = m.types[0] if m.types else dem.info.wall_type(wall_of[name]) if name in wall_of else None
        if t is None:
            out.append(m)
            continue
        values = {}
        for key, prop in SCRIPT_DEM:
            if prop not in dem.info.globals:
                continue
            pairwise = key in ("restitution", "friction")
            values[key] = float(dem.type_pair_value(prop, t, t) if pairwise else dem.type_values(prop, [t])[0])
        if m.dem is not None:
            for key, prop in SCRIPT_DEM:
                given = getattr(m.dem, key)
                stated = key in ("youngs_modulus", "restitution") or given != getattr(defaults, key)
                if stated and key in values and not math.isclose(given, values[key], rel_tol=1e-9):
                    raise ScriptError(f"{scene.path}: materials.{name}.dem.{key} = {given:g} differs from the "
                                      f"script's {prop} {values[key]:g} of atom type {t}: the script's value is the "
                                      f"one LIGGGHTS uses; drop the dem table or give the same value")
        missing = [k for k in ("youngs_modulus", "restitution") if k not in values]
        if missing and m.dem is None:
            raise ScriptError(f"{scene.path}: materials.{name}: the script sets no "
                              f"{', '.join(p for k, p in SCRIPT_DEM if k in missing)} for atom type {t}; "
                              f"give materials.{name}.dem")
        base = m.dem or defaults
        out.append(dataclasses.replace(m, dem=dataclasses.replace(base, **values)))
    return out
