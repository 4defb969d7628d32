"""Contacts as keys: one int64 per particle pair or particle-wall contact, the same on every
rank and after a restart (the collision log, the recorder's restitution speeds and the
joining of contacts that change rank use them). No engine calls.
"""
from __future__ import annotations

import numpy as np

from plugins.heat.exchange import WALL_BASE


def contact_keys(i, j):
    """One int64 key per contact: i and j are particle ids (j may be WALL_BASE + wall)."""
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    if np.any(np.minimum(i, j) < 0) or np.any(np.minimum(i, j) >= WALL_BASE):
        raise ValueError(f"particle ids must lie in [0, {WALL_BASE})")
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    return (lo << 31) | hi
