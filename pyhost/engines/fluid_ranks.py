"""The fluid exchange under mpirun without gathering the particles on rank 0 (issue 47).

The gather path (``FluidExchange.couple``, ``FluidSolver.particle_forces``) sends every
particle to rank 0 and from there to every fluid rank: O(N) memory and time on rank 0. For a
fluid mesh that is a grid of axis-aligned boxes (the box case the host writes from the scene's
``[fluid] cells``: one uniform blockMesh block), the ``cell`` interpolation (the solver's
default) and the ``centre`` void fraction, each LIGGGHTS rank does the particles' part on its
own atoms instead, with O(cells) on rank 0:

1. Rank 0 asks the fluid for every cell's velocity and pressure gradient
   (``FluidSolver.cell_fluid``: a LOCATE of the cell centres; ``cell`` interpolation gives a
   particle its cell's values wherever in the cell it is).
2. Every rank gets them with the mesh's planes (``BoxGrid``: the points' coordinates per axis,
   read once from constant/polyMesh/points, which the solver reads too) in one
   ``Dem.each_rank`` call (``exchange_on_rank``). Each rank finds its particles' cells
   (``np.searchsorted``), sums their volume per cell; the ranks add their sums (MPI Reduce and
   Bcast, so every rank has the same fluid fraction); each rank then computes its particles'
   drag (the same drag law, ``plugins.drag.fluid_fraction`` and ``fluid_force`` as the
   gather path), writes their force into its own LIGGGHTS (``fix collheat_fluid``) and its
   per-cell sums of K and K v go to rank 0 (Reduce), which hands them to the next ADVANCE.
3. A particle outside the mesh stops every rank before any force is set; one whose drag the
   coupling interval does not resolve stops the run after (its forces set, never used). The
   ranks send rank 0 those particles only, and the failure names the same particle as the
   gather path (the first in rank order), with the same count.

Cells are matched as OpenFOAM's LOCATE matches them (a point on a face belongs to both cells
there, and either may be taken: the solver's own choice depends on its hints). The per-cell sums
are added rank by rank instead of particle by particle: the fraction, K and K v differ from the
gather path's in their rounding only, and so do the forces (measured on hot-cold-bed cut through
its cells: 2.2e-15 of the largest; bit for bit where the ranks' cut runs along cell faces, and on
one rank: tests/cases/test_fluid_ranks.py). SI units.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plugins import drag as drag_laws
from plugins.drag import fluid_force, fluid_fraction
from pyhost.engines.ranks import ENGINE


@dataclass(frozen=True)
class BoxGrid:
    """A mesh whose cells are the boxes between planes normal to x, y and z. ``faces``: the
    planes' coordinates [m] per axis, increasing; ``order``: the solver's index (the order of
    ``FluidSolver.cell_centres``) of each grid cell, grid cell ``i + nx (j + ny k)``."""

    faces: tuple
    order: np.ndarray

    @property
    def shape(self) -> tuple:
        return tuple(len(f) - 1 for f in self.faces)

    @classmethod
    def of(cls, points: np.ndarray, centres: np.ndarray) -> "BoxGrid | None":
        """The grid of a mesh of these ``points`` [m] (n, 3) whose cells have these ``centres``
        (the solver's order), or None if it is not one: each point on one of the planes,
        one cell centre between each pair of neighbouring planes on every axis (within 1e-9 of
        the cell's size of the midpoint), every cell of the grid once."""
        points, centres = np.asarray(points, float), np.asarray(centres, float)
        faces = tuple(_planes(points[:, a]) for a in range(3))
        shape = tuple(len(f) - 1 for f in faces)
        if min(shape) < 1 or int(np.prod(shape)) != len(centres):
            return None
        flat = np.zeros(len(centres), np.int64)
        for a in (2, 1, 0):
            f = faces[a]
            i = np.searchsorted(f, centres[:, a]) - 1
            if np.any(i < 0) or np.any(i >= shape[a]):
                return None
            mid, size = 0.5 * (f[i] + f[i + 1]), f[i + 1] - f[i]
            if np.any(np.abs(centres[:, a] - mid) > 1e-9 * size):
                return None
            flat = flat * shape[a] + i
        order = np.full(len(centres), -1, np.int64)
        order[flat] = np.arange(len(centres))
        if np.any(order < 0):
            return None
        return cls(faces, order)

    def cells(self, x: np.ndarray) -> np.ndarray:
        """The grid cell of each position [m] (n, 3); -1 outside the mesh (a point on its
        boundary is inside, as for OpenFOAM)."""
        flat = np.zeros(len(x), np.int64)
        outside = np.zeros(len(x), bool)
        for a in (2, 1, 0):
            f = self.faces[a]
            n = len(f) - 1
            i = np.minimum(np.searchsorted(f, x[:, a], side="right") - 1, n - 1)
            outside |= (x[:, a] < f[0]) | (x[:, a] > f[-1])
            flat = flat * n + i
        return np.where(outside, -1, flat)

    def to_grid(self, values: np.ndarray) -> np.ndarray:
        """Per-cell values in the solver's order, in the grid's."""
        return values[self.order]

    def to_solver(self, values: np.ndarray) -> np.ndarray:
        """Per-cell values in the grid's order, in the solver's."""
        out = np.empty_like(values)
        out[self.order] = values
        return out


def _planes(coordinates: np.ndarray) -> np.ndarray:
    """The planes [m] the points' ``coordinates`` along one axis lie on, increasing: values
    apart by less than 1e-9 of the mesh's extent are one plane, at their mean (blockMesh's
    interpolation leaves some points of the plane z = 0 at -6e-19 m)."""
    c = np.sort(coordinates)
    if not len(c):
        return c
    tol = 1e-9 * (c[-1] - c[0])
    start = np.flatnonzero(np.r_[True, np.diff(c) > tol])
    return np.add.reduceat(c, start) / np.diff(np.r_[start, len(c)])


@dataclass(frozen=True)
class Job:
    """What each rank needs for one exchange, per cell in the grid's order: ``u`` the fluid
    velocity [m/s] and ``gradp`` the kinematic pressure gradient [m/s^2] (n, 3), ``volumes``
    [m^3]; the box (``lo``, ``hi`` [m], ``periodic``: the DEM wraps its atoms only at
    re-neighbouring), the gas (``rho`` [kg/m^3], ``nu`` [m^2/s]), the drag law's name,
    ``alpha_min``, the coupling ``interval`` [s] and the LIGGGHTS ``fix`` the forces go to
    (``dem.FLUID_FIX``)."""

    faces: tuple
    u: np.ndarray
    gradp: np.ndarray
    volumes: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    periodic: np.ndarray
    rho: float
    nu: float
    drag: str
    alpha_min: float
    interval: float
    fix: str


def wrapped(x, lo, hi, periodic) -> np.ndarray:
    """Positions [m] folded into the box along its periodic axes (as ``FluidExchange.couple``)."""
    return np.where(periodic, lo + np.mod(x - lo, hi - lo), x)


def exchange_on_rank(atoms, events, comm, job: Job) -> dict:
    """``Dem.each_rank``'s part of one exchange on this rank's atoms (module doc): their forces
    into this rank's LIGGGHTS; returns on rank 0 the summed per-cell particle volume ``solid``
    [m^3], K ``ksum`` [kg/s] and K v ``kv`` [kg m/s^2] in the grid's order; on every rank
    ``unresolved``, the ids, K [kg/s], mass [kg] and d [m] of its particles whose drag the
    interval does not resolve (K interval / m > 1: the run fails, ``drag_unresolved``). If a
    particle of any rank is outside the mesh, no rank sets a force and each returns only its
    own outside (``outside``: ids, positions [m], velocities [m/s])."""
    grid = BoxGrid(job.faces, np.zeros(0, np.int64))
    ncells = len(job.volumes)
    x = wrapped(atoms.x, job.lo, job.hi, job.periodic)
    cell = grid.cells(x)
    lost = cell < 0
    d = 2.0 * atoms.radius
    vp = np.pi * d**3 / 6.0
    solid = np.zeros(ncells) if lost.any() else np.bincount(cell, vp, ncells)
    solid, n_lost = _everywhere(comm, np.r_[solid, float(lost.sum())])
    if n_lost:
        return dict(outside=(atoms.id[lost].copy(), x[lost], atoms.v[lost].copy()))
    alpha = fluid_fraction(solid, job.volumes, job.alpha_min)
    u, gradp = job.u[cell], job.gradp[cell]
    slip = u - atoms.v
    k = drag_laws.LAWS.lookup(job.drag)(alpha[cell], np.linalg.norm(slip, axis=1), d, job.rho, job.nu)
    over = k * job.interval / atoms.mass > 1.0
    if len(k):
        ENGINE[0].external_force(job.fix)[:] = fluid_force(k, slip, vp, job.rho, gradp)
    sums = np.stack([np.bincount(cell, k, ncells)] + [np.bincount(cell, k * atoms.v[:, i], ncells) for i in range(3)],
                    axis=1)
    sums = _summed(comm, sums)
    mine = dict(unresolved=(atoms.id[over].copy(), k[over], atoms.mass[over].copy(), d[over]))
    return mine if sums is None else dict(mine, solid=solid, ksum=sums[:, 0], kv=sums[:, 1:])


def _everywhere(comm, values: np.ndarray) -> tuple[np.ndarray, float]:
    """``values`` (per-cell sums, then a count) summed over the ranks, the same on every rank
    (Reduce to rank 0, then Bcast: every rank computes the same fluid fraction from them)."""
    if comm is not None:
        from mpi4py import MPI
        total = np.empty_like(values)
        comm.Reduce(values, total, op=MPI.SUM, root=0)
        comm.Bcast(total, root=0)
        values = total
    return values[:-1], float(values[-1])


def _summed(comm, values: np.ndarray) -> np.ndarray | None:
    """The ranks' ``values`` summed, on rank 0 (None elsewhere)."""
    if comm is None:
        return values
    from mpi4py import MPI
    total = np.empty_like(values) if comm.Get_rank() == 0 else None
    comm.Reduce(np.ascontiguousarray(values), total, op=MPI.SUM, root=0)
    return total


def force_on_rank(atoms, events, comm, fix: str) -> tuple[np.ndarray, np.ndarray]:
    """``Dem.each_rank``: this rank's atom ids and the fluid's force on them [N] (LIGGGHTS' ``fix``
    external's array: a checkpoint)."""
    force = ENGINE[0].external_force(fix) if len(atoms.id) else np.zeros((0, 3))
    return atoms.id.copy(), np.array(force)
