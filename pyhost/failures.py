"""Why a DEM run lost a particle: which one, where and how fast it was last seen, and the
likely cause, told from the scene (exit code 3, docs/exit-codes.md).

Causes, tried in this order for the face the particle was heading to:
- an open face (no wall, not periodic): nothing holds the particle in;
- a DEM step too long for the collision at the particle's speed (fewer than 10 steps per
  DEM collision time, ``pyhost.engines.liggghts.box_input.dem_collision_time``): contacts are missed or blow up;
- tunnelling through a soft wall: the undamped Hertz overlap at that speed (DEM moduli)
  exceeds the radius, so the wall cannot stop it;
- blow-out by the gas: leaving upwards through the top while the inlet blows (tried first
  for an open top).
"""
from __future__ import annotations

import numpy as np

from plugins.dem.hertz import DemHertz
from plugins.heat.batch import dem_pair
from pyhost.engines.liggghts.box_input import dem_collision_time
from pyhost.exitcodes import SimulationFailed
from pyhost.walls import FACES

STEPS_PER_COLLISION = 10        # fewer DEM steps than this per collision: under-resolved


class InvariantBroken(SimulationFailed):
    """A completed run whose own check failed at its end (an effect's ``failure``: the energy
    balance beyond round-off): its files and summary.json are written, then exit code 3."""


class ParticlesLost(SimulationFailed):
    """Particles left the DEM's box. ``ids`` (1-based), ``position`` [m] and ``velocity``
    [m/s] where first lost one was last seen, ``time`` [s] of that sight, ``cause`` in words."""

    def __init__(self, message, ids, position, velocity, time, cause):
        super().__init__(message)
        self.ids, self.position, self.velocity, self.time, self.cause = ids, position, velocity, time, cause


class LeftTheMesh(SimulationFailed):
    """Particles the DEM still holds are outside the fluid's mesh: the DEM's walls and box do
    not keep them where the fluid is."""


def left_the_mesh(ids, x, v, t: float) -> LeftTheMesh:
    """The failure of the particles ``ids`` at positions ``x`` [m], moving at ``v`` [m/s], found
    outside the fluid mesh at time ``t`` [s], naming the first and the likely cause."""
    return LeftTheMesh(
        f"t = {t:.6g} s: {len(ids)} particle(s) are outside the fluid's mesh, e.g. particle {int(ids[0])} at "
        f"{np.round(x[0], 6).tolist()} m moving at {np.round(v[0], 4).tolist()} m/s: the DEM's walls and box do not "
        "keep the particles inside the fluid's mesh (a wall the mesh has and the DEM lacks, such as a hopper's "
        "funnel or a pipe's side given only to the fluid; a DEM box larger than the mesh; a particle through a "
        "soft DEM wall): give the DEM the mesh's walls (fix mesh/surface with the same STL, or a wall/gran)")


class DragUnresolved(SimulationFailed):
    """The gas's drag, held over a coupling interval, would carry particles past the gas speed
    within it: K interval / m > 1."""


def drag_unresolved(ids, k, mass, d, interval: float, dem_step: float, t: float) -> DragUnresolved | None:
    """The failure of particles whose drag relaxes their slip faster than the coupling interval
    [s]: ``k`` the drag coefficient K [kg/s] and ``mass`` [kg], ``d`` the diameter [m] of each
    particle (``ids``); None if K interval / m <= 1 for all. The host's drag force is explicit
    over the interval: the slip changes by the factor 1 - K interval / m, which overshoots
    past 1 and grows past 2."""
    ratio = np.asarray(k) * interval / np.asarray(mass)
    if not len(ratio) or ratio.max() <= 1.0:
        return None
    i = int(np.argmax(ratio))
    tau = mass[i] / k[i]
    return DragUnresolved(
        f"t = {t:.6g} s: the gas's drag relaxes the slip of {int((ratio > 1).sum())} particle(s) faster than the "
        f"coupling interval of {interval:.3g} s (particle {int(ids[i])}, d = {d[i] * 1e3:.3g} mm: m/K = {tau:.3g} s, "
        f"K interval/m = {ratio[i]:.3g}); the host's drag is held over the interval, so it carries them past the gas "
        f"speed and their motion is wrong: couple at most every {max(1, int(tau / dem_step))} DEM steps "
        "(time.couple_every; a CFDEM case: its couplingInterval)")


def heading(scene, x, v) -> str:
    """The face of the box a particle at x moving at v reaches first (periodic axes skipped)."""
    box = np.asarray(scene.domain.box, float)
    best, face = np.inf, FACES[-1]
    for a in range(3):
        if scene.domain.periodic[a] or v[a] == 0:
            continue
        side = 1 if v[a] > 0 else 0
        t = (box[2 * a + side] - x[a]) / v[a]
        if t < best:
            best, face = t, FACES[2 * a + side]
    return face


def likely_cause(scene, group: int, x, v, t: float) -> str:
    speed = float(np.linalg.norm(v))
    face = heading(scene, x, v)
    walls = {w.plane: w for w in scene.walls}
    blowing = scene.fluid is not None and scene.effects.fluid and face == "zhi" and float(scene.fluid.inlet_at(t)) > 0
    gas = f"rising at {v[2]:.3g} m/s with the inlet at {float(scene.fluid.inlet_at(t)):.3g} m/s" if blowing else ""
    if face not in walls and blowing:
        return f"blown out by the gas through the open top (zhi): {gas}"
    if face not in walls:
        return (f"the box is open at {face} (no [[walls]] plane = \"{face}\", axis not periodic): "
                f"a particle reaching it leaves the DEM")
    dt = scene.time.dem_step
    t_c = dem_collision_time(scene, max(speed, 1e-12))
    if dt * STEPS_PER_COLLISION > t_c:
        return (f"time.dem_step = {dt:g} s against a DEM collision time of {t_c:.3g} s at {speed:.3g} m/s "
                f"({t_c / dt:.1f} steps per collision, need >= {STEPS_PER_COLLISION}): "
                f"use dem_step <= {t_c / 20:.2g} s")
    g = scene.particles[group]
    law = DemHertz(dem_pair(scene.materials[g.material], scene.materials[walls[face].material]).Ystar, 1.0)
    mass = 4.0 / 3.0 * np.pi * g.radius**3 * scene.materials[g.material].density
    overlap = float(law.max_overlap(speed, g.radius, mass))
    if overlap > g.radius:
        return (f"tunnelling through the soft wall {face}: at {speed:.3g} m/s the DEM's Hertz overlap would "
                f"reach {overlap:.3g} m, more than the radius {g.radius:g} m: raise materials' dem.youngs_modulus")
    if blowing:
        return f"blown out by the gas, through the top wall: {gas}"
    return f"heading for the wall {face} at {speed:.3g} m/s, cause not recognised"


def particles_lost(scene, lost_ids, before, t_now: float, group) -> ParticlesLost:
    """The error for a box scene whose DEM holds fewer particles than it placed: ``lost_ids``
    (atom ids), ``before`` = (t, ids, x, v) at the last check, ``group`` of each id."""
    ids = np.asarray(lost_ids)
    t, known, x, v = before
    k = int(np.flatnonzero(known == ids[0])[0])
    cause = likely_cause(scene, int(group[ids[0]]), x[k], v[k], t)
    return ParticlesLost(
        f"{len(ids)} particle(s) left the domain between t = {t:g} s and t = {t_now:g} s, "
        f"ids {ids[:10].tolist()}{' ...' if len(ids) > 10 else ''}; particle {ids[0]} last seen at "
        f"x = {np.round(x[k], 9).tolist()} m, v = {np.round(v[k], 6).tolist()} m/s; likely cause: {cause}",
        ids, x[k], v[k], t, cause)
