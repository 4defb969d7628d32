"""Contacts from particle positions: the overlaps the DEM's contact law acts on.

delta = r_i + r_j - |x_i - x_j| for particle pairs (found with scipy's cKDTree, periodic
where the domain is) and delta = r_i - distance to the plane for the box walls the scene
declares. The normal points from partner j to particle i; the approach speed
-(v_i - v_j) . n is > 0 while they close in. This is the same overlap LIGGGHTS uses, so the
host needs positions and velocities only, from whichever bridge runs the DEM.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from pyhost.collisions import WALL_BASE

AXIS = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Contacts:
    """Current contacts: rows i (particle index), j (particle index or WALL_BASE + wall),
    overlap delta [m], unit normal n (j to i), approach speed [m/s]."""

    i: np.ndarray
    j: np.ndarray
    delta: np.ndarray
    normal: np.ndarray
    approach: np.ndarray

    def __len__(self):
        return len(self.i)


def find_contacts(x, v, r, box, periodic=(False, False, False), walls=()) -> Contacts:
    """Contacts among particles at x [m] with velocities v [m/s] and radii r [m] in
    box = (xmin, xmax, ymin, ymax, zmin, zmax); walls are plane names ("zlo", ...)."""
    x, v, r = np.asarray(x, float), np.asarray(v, float), np.asarray(r, float)
    lo, hi = np.array(box[0::2], float), np.array(box[1::2], float)
    size = hi - lo
    per = np.asarray(periodic, bool)
    if per.any():
        # cKDTree wraps every axis of boxsize: non-periodic axes get a box 4x the domain, with
        # the points shifted into its middle, so that no pair can meet across its wrap
        pts = np.where(per, np.mod(x - lo, size), x - lo + size)
        tree = cKDTree(pts, boxsize=np.where(per, size, 4.0 * size))
    else:
        tree = cKDTree(x)
    pairs = tree.query_pairs(2.0 * r.max(), output_type="ndarray") if len(r) > 1 else np.empty((0, 2), int)
    i, j = pairs[:, 0], pairs[:, 1]
    d = x[i] - x[j]
    d -= np.where(per, size * np.round(d / size), 0.0)            # minimum image
    dist = np.linalg.norm(d, axis=1)
    delta = r[i] + r[j] - dist
    keep = delta > 0
    i, j, d, dist, delta = i[keep], j[keep], d[keep], dist[keep], delta[keep]
    n = d / dist[:, None]
    approach = -np.einsum("ij,ij->i", v[i] - v[j], n)
    rows = [(i, j, delta, n, approach)]
    for w, plane in enumerate(walls):
        axis, side = AXIS[plane[0]], plane[1:]
        gap = x[:, axis] - lo[axis] if side == "lo" else hi[axis] - x[:, axis]
        k = np.flatnonzero(r - gap > 0)
        nw = np.zeros((len(k), 3))
        nw[:, axis] = 1.0 if side == "lo" else -1.0
        rows.append((k, np.full(len(k), WALL_BASE + w), (r - gap)[k], nw, -np.einsum("ij,ij->i", v[k], nw)))
    return Contacts(*(np.concatenate([row[c] for row in rows]) for c in range(5)))
