"""Contacts from particle positions: the overlaps the DEM's contact law acts on.

delta = r_i + r_j - |x_i - x_j| for particle pairs (found with scipy's cKDTree, periodic
where the domain is) and delta = r_i - distance to the wall for the box faces and primitive
walls given (``pyhost.walls``). The normal points from partner j to particle i; the approach speed
-(v_i - v_j) . n is > 0 while they close in. This is the same overlap LIGGGHTS uses, so the
host needs positions and velocities only, from whichever bridge runs the DEM.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pyhost.collisions import minimum_image, wall_code
from pyhost.walls import face_overlap, primitive_overlap


@dataclass(frozen=True)
class Contacts:
    """Contacts, one row each: ``i`` a particle (index or atom id); ``j`` a particle, or the
    code of the wall of that index among those given (``pyhost.collisions.wall_code``); overlap
    ``delta`` [m]; unit ``normal`` from j to i; ``approach`` = -(v_i - v_j).n [m/s] (> 0 while
    closing in). The form of a contact list that ``pyhost post`` finds in dump frames without
    contact dumps."""

    i: np.ndarray
    j: np.ndarray
    delta: np.ndarray
    normal: np.ndarray
    approach: np.ndarray

    def __len__(self):
        return len(self.i)

    @classmethod
    def concat(cls, parts: list) -> "Contacts":
        """The rows of several lists, in order."""
        if not parts:
            z = np.zeros(0)
            return cls(np.zeros(0, np.int64), np.zeros(0, np.int64), z, np.zeros((0, 3)), z)
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.__dataclass_fields__))


class ContactFinder:
    """Contacts among particles of radii r [m] in box = (xmin, xmax, ..., zmax), periodic where
    asked, with the ``walls``: box faces ("zlo", ...) or primitive walls (kind, numbers), as
    ``pyhost.walls`` places them.

    A Verlet list: candidate pairs within 2 r_max + skin come from scipy's cKDTree and are
    reused until some particle has moved more than skin/2 since they were found, which
    cannot miss a contact (two particles close in by at most skin between rebuilds).
    """

    def __init__(self, r, box, periodic=(False, False, False), walls=(), skin=None):
        self.r, self.box = np.asarray(r, float), tuple(float(b) for b in box)
        self.lo, self.hi = np.array(box[0::2], float), np.array(box[1::2], float)
        self.size = self.hi - self.lo
        self.per = np.asarray(periodic, bool)
        self.walls = tuple(walls)
        self.skin = 0.5 * self.r.max() if skin is None else skin
        self.x_built, self.pairs, self.rebuilds = None, None, 0

    def _wrap(self, d):
        return minimum_image(d, self.size, self.per)

    def _rebuild(self, x) -> None:
        from scipy.spatial import cKDTree   # here: only post's contacts need it (0.1-0.3 s to import)

        cutoff = 2.0 * self.r.max() + self.skin
        if self.per.any():
            # cKDTree wraps every axis of boxsize: non-periodic axes get a box 4x the domain,
            # with the points shifted into its middle, so that no pair meets across its wrap
            pts = np.where(self.per, np.mod(x - self.lo, self.size), x - self.lo + self.size)
            tree = cKDTree(pts, boxsize=np.where(self.per, self.size, 4.0 * self.size))
        else:
            tree = cKDTree(x)
        self.pairs = tree.query_pairs(cutoff, output_type="ndarray") if len(x) > 1 else np.empty((0, 2), int)
        self.x_built = x.copy()
        self.rebuilds += 1

    def __call__(self, x, v) -> Contacts:
        x, v, r = np.asarray(x, float), np.asarray(v, float), self.r
        if self.x_built is None or np.max(np.sum(self._wrap(x - self.x_built) ** 2, axis=1)) > (0.5 * self.skin) ** 2:
            self._rebuild(x)
        i, j = self.pairs[:, 0], self.pairs[:, 1]
        d = self._wrap(x[i] - x[j])
        dist = np.sqrt(np.einsum("ij,ij->i", d, d))
        delta = r[i] + r[j] - dist
        keep = delta > 0
        i, j, d, dist, delta = i[keep], j[keep], d[keep], dist[keep], delta[keep]
        n = d / dist[:, None]
        approach = -np.einsum("ij,ij->i", v[i] - v[j], n)
        rows = [(i, j, delta, n, approach)]
        for w, wall in enumerate(self.walls):
            delta, nw = face_overlap(x, r, wall, self.box) if isinstance(wall, str) else primitive_overlap(x, r, wall)
            k = np.flatnonzero(delta > 0)
            rows.append((k, np.full(len(k), wall_code(w)), delta[k], nw[k], -np.einsum("ij,ij->i", v[k], nw[k])))
        return Contacts.concat([Contacts(*row) for row in rows])


def find_contacts(x, v, r, box, periodic=(False, False, False), walls=()) -> Contacts:
    """Contacts of one configuration (see ContactFinder, which reuses its search)."""
    return ContactFinder(r, box, periodic, walls)(x, v)
