"""The particles as the host sees them (``Atoms``), and one rank's own as views of LIGGGHTS'
memory (``local_view``). SI units."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Atoms:
    """The particles now, local order (SI): ids, x (n, 3) [m], v (n, 3) [m/s], radius [m],
    mass [kg], type, T (writable view of LIGGGHTS' Temp [K], or None)."""

    id: np.ndarray
    x: np.ndarray
    v: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    type: np.ndarray
    T: np.ndarray | None

    def index(self, ids) -> np.ndarray:
        """Local index of each atom id (-1 for ids not here)."""
        ids = np.asarray(ids, np.int64)
        lookup = np.full(int(max(self.id.max(initial=0), ids.max(initial=0))) + 1, -1, np.int64)
        lookup[self.id] = np.arange(len(self.id))
        return lookup[ids]


def local_view(lmp, temperature: bool = True) -> Atoms:
    """This rank's own atoms as views of LIGGGHTS' memory (T: Temp, writable; None if not
    ``temperature``), valid until the next run."""
    T = (lmp.temperature() if lmp.nlocal else np.zeros(0)) if temperature else None
    return Atoms(lmp.atom("id").astype(np.int64), lmp.atom("x"), lmp.atom("v"), lmp.atom("radius"),
                 lmp.atom("rmass"), lmp.atom("type"), T)
