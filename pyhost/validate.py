"""Checks of a whole scene before any engine starts, after ``pyhost.scene`` read the file and
built it key by key: what only the whole scene tells.

``check_scene(scene)``: no wall on a periodic axis, 0 < alpha_min < 1, output.every >=
dem_step, test_end <= end, a particle count LIGGGHTS and this machine can hold, positions
and regions inside the box, no initial overlap between particles (periodic images
considered) or with a wall, and a DEM step that resolves the DEM collision at the scene's
highest expected speed.
Each complaint names the file and the key, with the numbers.
"""
from __future__ import annotations

import math
import os

import numpy as np

from pyhost.schema import SceneError
from pyhost.walls import face_axis, face_gap

MAX_IDS = 2**31 - 1             # LIGGGHTS' atom ids are 32-bit signed integers
BYTES_PER_PARTICLE = 2000       # LIGGGHTS' per-atom arrays, neighbour lists, the host's copies
STEPS_PER_COLLISION = 10        # fewer DEM steps than this per DEM collision: refused
OVERLAP_TOLERANCE = 1e-9        # relative to the sum of radii: touching is not overlapping
AXES = "xyz"


def max_count(memory: int | None = None) -> int:
    """Most particles a run may ask for: LIGGGHTS' 32-bit ids, and this machine's memory."""
    if memory is None:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    return min(MAX_IDS, memory // BYTES_PER_PARTICLE)


def expected_speed(scene) -> tuple[float, str]:
    """Highest impact speed [m/s] the scene should see, and where it comes from: twice the
    fastest of the initial velocities (plus 4 spreads), free fall across the box, and the
    inlet velocity (two particles may meet head-on)."""
    box = scene.domain.box
    candidates = [(float(np.linalg.norm(g.velocity)) + 4.0 * g.velocity_spread,
                   f"particles[{k}].velocity + 4 velocity_spread") for k, g in enumerate(scene.particles)]
    g = float(np.linalg.norm(scene.domain.gravity))
    if g > 0:
        height = max(box[1] - box[0], box[3] - box[2], box[5] - box[4])
        candidates.append((math.sqrt(2.0 * g * height), "free fall across the box"))
    if scene.fluid is not None and scene.effects.fluid:
        inlet = max([scene.fluid.inlet_velocity] + [row[1] for row in scene.fluid.inlet_table])
        candidates.append((inlet, "fluid inlet velocity"))
    v, why = max(candidates)
    return 2.0 * v, f"twice the {why} ({v:.3g} m/s)"


def check_scene(scene) -> None:
    from pyhost.engines.liggghts.box_input import dem_collision_time, place_particles

    file, d, tm = scene.path, scene.domain, scene.time
    if scene.fluid is not None and not scene.fluid.alpha_min < 1:
        raise SceneError(f"{file}: fluid.alpha_min: must be in (0, 1), got {scene.fluid.alpha_min!r}")
    if scene.fluid is not None and scene.effects.fluid:
        ranks = scene.fluid.ranks
        if scene.fluid.case:
            decompose = scene.folder / scene.fluid.case / "system" / "decomposeParDict"
            if ranks > 1 and not decompose.is_file():
                raise SceneError(f"{file}: fluid.ranks = {ranks}: the user's case has no {decompose}, which "
                                 "decomposePar needs")
        elif ranks > max(scene.fluid.cells[:2]):
            raise SceneError(f"{file}: fluid.ranks = {ranks}: the box mesh is cut into one slab per rank across x or y, "
                             f"and fluid.cells has only {max(scene.fluid.cells[:2])} cells there")
    if scene.scripted:          # the script places the particles and sets the box and the step
        return
    for k, w in enumerate(scene.walls):
        if d.periodic[face_axis(w.plane)[0]]:
            raise SceneError(f"{file}: walls[{k}].plane: {w.plane!r} lies on the periodic axis {w.plane[0]} "
                             f"(domain.periodic = {d.periodic})")
    if 0 < scene.output.every < tm.dem_step:
        raise SceneError(f"{file}: output.every: must be at least time.dem_step ({tm.dem_step:g} s), "
                         f"got {scene.output.every:g} s")
    if tm.test_end > tm.end:
        raise SceneError(f"{file}: time.test_end: must not exceed time.end ({tm.end:g} s), got {tm.test_end:g} s")
    total, limit = sum(g.count for g in scene.particles), max_count()
    if total > limit:
        raise SceneError(f"{file}: particles: {total} particles in all, more than {limit} (LIGGGHTS' 32-bit ids "
                         f"and {BYTES_PER_PARTICLE} bytes each in this machine's memory)")
    lo, hi = np.array(d.box[0::2], float), np.array(d.box[1::2], float)
    for k, g in enumerate(scene.particles):
        if g.region:
            rlo, rhi = np.array(g.region[0::2], float), np.array(g.region[1::2], float)
            bad = np.flatnonzero((rlo < lo) | (rhi > hi))
            if len(bad):
                a = bad[0]
                raise SceneError(f"{file}: particles[{k}].region: {AXES[a]} from {rlo[a]:g} to {rhi[a]:g} m is "
                                 f"not inside the box ({lo[a]:g} to {hi[a]:g} m)")
        for n, x in enumerate(g.positions):
            out = np.flatnonzero((np.array(x) < lo) | (np.array(x) >= hi))
            if len(out):
                raise SceneError(f"{file}: particles[{k}].positions[{n}]: {x} m is outside the box "
                                 f"({AXES[out[0]]} from {lo[out[0]]:g} to {hi[out[0]]:g} m)")
    particles = place_particles(scene)
    _walls_clear(scene, particles)
    _no_overlaps(scene, particles, lo, hi)
    v, why = expected_speed(scene)
    if v > 0:
        t_c = dem_collision_time(scene, v)
        if tm.dem_step * STEPS_PER_COLLISION > t_c:
            raise SceneError(f"{file}: time.dem_step: {tm.dem_step:g} s resolves the DEM collision at {v:.3g} m/s "
                             f"({why}), which lasts {t_c:.3g} s, with {t_c / tm.dem_step:.1f} steps; need "
                             f">= {STEPS_PER_COLLISION}: use dem_step <= {t_c / 20:.2g} s (20 steps) or softer "
                             f"materials' dem.youngs_modulus")


def _where(scene, i) -> str:
    """particles[k].positions[n] (or the group and index) of particle i."""
    counts = np.cumsum([g.count for g in scene.particles])
    k = int(np.searchsorted(counts, i, side="right"))
    n = i - (counts[k - 1] if k else 0)
    return f"particles[{k}]" + (f".positions[{n}]" if scene.particles[k].positions else f" (particle {n} of its region)")


def _walls_clear(scene, p) -> None:
    for w in scene.walls:
        gap = face_gap(p.position, w.plane, scene.domain.box)
        i = int(np.argmin(gap - p.radius))
        if gap[i] < p.radius[i] * (1 - OVERLAP_TOLERANCE):
            raise SceneError(f"{scene.path}: {_where(scene, i)}: overlaps the wall {w.plane} by "
                             f"{p.radius[i] - gap[i]:.3g} m at the start (centre {gap[i]:.3g} m from it, "
                             f"radius {p.radius[i]:g} m)")


def _apart_as_placed(scene) -> bool:
    """Whether no two particles can touch as ``place_particles`` places them: every group on
    its lattice (no explicit positions), in regions that share no volume. Within a lattice the
    centres are 2.1 radii apart, each moved by at most 0.04 radii per axis (at least 2.02 radii
    apart); its outermost centres are 1.05 - 0.04 radii inside its region, which lies inside the
    box: each sphere is inside its region, 0.01 radii from its faces (periodic images too)."""
    groups = scene.particles
    if any(g.positions for g in groups):
        return False
    boxes = [np.array(g.region, float).reshape(3, 2) for g in groups]
    return all(np.any((a[:, 1] <= b[:, 0]) | (b[:, 1] <= a[:, 0]))
               for k, a in enumerate(boxes) for b in boxes[k + 1:])


def _no_overlaps(scene, p, lo, hi) -> None:
    """Pairs closer than the sum of their radii, periodic images included (cKDTree on a torus
    for the periodic axes, a torus too large to wrap for the others); none to look for where
    every group is a lattice of its own region (``_apart_as_placed``), which spares a box
    scene's start scipy.spatial's import (0.2-0.5 s)."""
    if _apart_as_placed(scene):
        return
    from scipy.spatial import cKDTree   # here: box scenes only (0.1-0.3 s to import)

    length = hi - lo
    periodic = np.array(scene.domain.periodic)
    x = p.position - lo
    x = np.where(periodic, np.mod(x, length), x + length)
    size = np.where(periodic, length, 3.0 * length + 4.0 * p.radius.max())
    pairs = cKDTree(x, boxsize=size).query_pairs(2.0 * p.radius.max(), output_type="ndarray")
    if not len(pairs):
        return
    i, j = pairs.T
    delta = x[i] - x[j]
    delta -= np.where(periodic, length * np.round(delta / length), 0.0)
    gap = np.linalg.norm(delta, axis=1) - (p.radius[i] + p.radius[j])
    worst = int(np.argmin(gap / (p.radius[i] + p.radius[j])))
    if gap[worst] < -OVERLAP_TOLERANCE * (p.radius[i][worst] + p.radius[j][worst]):
        a, b = int(i[worst]), int(j[worst])
        raise SceneError(f"{scene.path}: {_where(scene, a)} and {_where(scene, b)}: overlap by {-gap[worst]:.3g} m "
                         f"at the start ({int((gap < 0).sum())} overlapping pair(s), periodic images included)")
