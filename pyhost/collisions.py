"""Collisions out of the DEM's contact lists: impact speed, start and end, heat exchange.

Pure functions and one small state holder, no engine calls, so that the coupling loop can
be tested without engines. SI units.

How a contact is classified. A contact opens when a pair (or a particle and a wall) shows
up in the contact list and closes when it leaves it. At the first sample in contact the
impact speed is recovered from the DEM's own contact law (``DemHertz.impact_speed``), and
the collision's heat Q is computed by the plugin and exchanged at once, with the
temperatures of that moment. That heat accounts for the first t_coll of the contact, the
collision's duration under the real material's model. A contact that is still open after
t_coll is *enduring*. From then on it conducts only through the enduring-contact effect, if
the scene enables it, and only for the time beyond t_coll. So no stretch of a contact's
time is counted twice.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plugins.dem.hertz import DemHertz, restitution_beta  # noqa: F401  (re-exported for the host)

WALL_BASE = 1 << 30
"""Partner ids at or above this are walls (WALL_BASE + wall index); particle ids stay below."""


def contact_keys(i, j):
    """One int64 key per contact: i and j are particle ids (j may be WALL_BASE + wall)."""
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    if np.any(np.minimum(i, j) < 0) or np.any(np.minimum(i, j) >= WALL_BASE):
        raise ValueError(f"particle ids must lie in [0, {WALL_BASE})")
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    return (lo << 31) | hi


@dataclass
class ContactTracker:
    """The open contacts between two samples of the contact list.

    ``update(keys)`` returns the indices (into keys) of contacts that opened since the last
    sample and the keys of those that closed; the host stores per-contact data alongside.
    """

    open_keys: np.ndarray = None

    def __post_init__(self):
        self.open_keys = np.empty(0, np.int64) if self.open_keys is None else self.open_keys

    def update(self, keys: np.ndarray):
        keys = np.asarray(keys, np.int64)
        if np.unique(keys).size != keys.size:
            raise ValueError("contact list holds the same contact twice (is newton off?)")
        opened = np.flatnonzero(~np.isin(keys, self.open_keys))
        closed = self.open_keys[~np.isin(self.open_keys, keys)]
        self.open_keys = keys.copy()
        return opened, closed


def temperature_difference(T, i, j, T_wall=None):
    """T_i - T_j [K] of each collision (j >= WALL_BASE: the wall's temperature; 0 for an
    adiabatic wall, None or NaN in T_wall), with the temperatures as they are now."""
    i, j = np.asarray(i), np.asarray(j)
    wall = j >= WALL_BASE
    T_j = T[np.where(wall, i, j)]
    if wall.any():
        tw = np.full(len(j), np.nan) if T_wall is None else np.asarray(T_wall, float)[np.where(wall, j - WALL_BASE, 0)]
        T_j = np.where(wall, np.where(np.isnan(tw), T[i], tw), T_j)
    return T[i] - T_j


def exchange_heat(T, C, i, j, G, T_wall=None):
    """Move heat between bodies, one collision after the other, with the temperatures of that
    moment: q = G (T_i - T_j) [J] from i to j, G [J/K] the collision's conductance-time
    (the plugin's Q per kelvin: Q is linear in dT, eqs. 2-3).

    T [K] and C = m c [J/K] are per particle; j >= WALL_BASE is wall j - WALL_BASE, with
    temperature T_wall[wall] (None or NaN: adiabatic, no exchange). No collision carries more
    heat than would equalise the two temperatures: a G above C_i C_j/(C_i + C_j) (C_i for a
    wall) is capped there. Returns the heat moved per collision [J], the number capped, and
    the heat that entered the particles from walls [J]; sum(C T) changes by exactly that.
    """
    moved = np.zeros(len(G))
    capped, from_walls = 0, 0.0
    for k, (a, b, g) in enumerate(zip(np.asarray(i), np.asarray(j), np.asarray(G, float))):
        if b >= WALL_BASE:
            tw = np.nan if T_wall is None else T_wall[b - WALL_BASE]
            if np.isnan(tw):
                continue
            limit, dT = C[a], T[a] - tw
        else:
            limit, dT = C[a] * C[b] / (C[a] + C[b]), T[a] - T[b]
        if g > limit:
            g, capped = limit, capped + 1
        q = g * dT
        T[a] -= q / C[a]
        if b >= WALL_BASE:
            from_walls -= q
        else:
            T[b] += q / C[b]
        moved[k] = q
    return moved, capped, from_walls
