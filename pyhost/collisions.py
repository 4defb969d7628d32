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


class ContactTracker:
    """The open contacts between two samples of the contact list.

    ``update(keys)`` returns the indices (into keys) of contacts that opened since the last
    sample and the keys of those that closed (both in key order); ``match(keys)``
    also says where each contact was in the last sample, so that the host keeps per-contact
    data in arrays aligned with ``open_keys``. Membership by binary search in sorted copies.
    """

    def __init__(self):
        self.open_keys = np.empty(0, np.int64)
        self._sorted = self.open_keys
        self._order = np.empty(0, np.intp)

    def match(self, keys: np.ndarray):
        """(opened: indices into keys of the new contacts; closed: indices into the last
        ``open_keys`` of those gone; prev: for each key its index in the last ``open_keys``, -1
        for a new one); ``open_keys`` becomes a copy of keys. opened and closed come in the
        order of their keys, not of the engine's list, whose order follows the atoms' order in
        memory (a restart or another number of ranks changes it): the host moves heat and
        restitution impulses in this order, so it must not depend on the engine's."""
        keys = np.asarray(keys, np.int64)
        order = np.argsort(keys, kind="stable")
        ordered = keys[order]
        if np.any(ordered[1:] == ordered[:-1]):
            raise ValueError("contact list holds the same contact twice (is newton off?)")
        prev = np.full(len(keys), -1, np.intp)
        if len(self._sorted):
            at = np.minimum(np.searchsorted(self._sorted, keys), len(self._sorted) - 1)
            hit = self._sorted[at] == keys
            prev[hit] = self._order[at[hit]]
        opened = order[prev[order] < 0]
        closed = self._order[~_member(self._sorted, ordered)]
        self.open_keys, self._sorted, self._order = keys.copy(), ordered, order
        return opened, closed, prev

    def update(self, keys: np.ndarray):
        old = self.open_keys
        opened, closed, _ = self.match(keys)
        return opened, old[closed]


def _member(values, ordered):
    """Whether each value is in the sorted array ``ordered``."""
    at = np.minimum(np.searchsorted(ordered, values), max(len(ordered) - 1, 0))
    return ordered[at] == values if len(ordered) else np.zeros(len(values), bool)


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


def exchange_heat(T, C, i, j, G, T_wall=None, shift=None):
    """Move heat between bodies, one collision after the other, with the temperatures of that
    moment: q = G (T_i - T_j) [J] from i to j, G [J/K] the collision's conductance-time
    (the plugin's Q per kelvin: Q is linear in dT, eqs. 2-3).

    T [K] and C = m c [J/K] are per particle; j >= WALL_BASE is wall j - WALL_BASE, with
    temperature T_wall[wall] (None or NaN: adiabatic, no exchange). ``shift`` [K] per collision,
    if given, is added to its T_i - T_j (temperatures that changed since the collision by what
    it does not stand for: pyhost.loop's contact events). No collision carries more
    heat than would equalise the two temperatures: a G above C_i C_j/(C_i + C_j) (C_i for a
    wall) is capped there. Returns the heat moved per collision [J], the number capped, and
    the heat that entered the particles from walls [J]; sum(C T) changes by exactly that.

    Done in rounds, bit-identical to the loop: a round takes every remaining collision that is
    the first remaining one of both its particles (a wall, of fixed temperature, is nobody's
    state), so no particle appears twice in a round and each meets its partners in order.
    """
    i, j, G = np.asarray(i), np.asarray(j), np.asarray(G, float)
    wall = j >= WALL_BASE
    tw = np.full(len(j), np.nan)
    if wall.any() and T_wall is not None:
        tw[wall] = np.asarray(T_wall, float)[j[wall] - WALL_BASE]
    active = np.flatnonzero(~wall | ~np.isnan(tw))
    limit = np.where(wall, C[i], C[i] * C[np.where(wall, i, j)] / (C[i] + C[np.where(wall, i, j)]))
    capped = int(np.count_nonzero(G[active] > limit[active]))
    g = np.minimum(G, limit)
    moved = np.zeros(len(G))
    # the second body of a wall collision: a code of its own that no particle shares
    other = np.where(wall, -1 - np.arange(len(j)), j)
    left = active
    while len(left):
        ends = np.stack([i[left], other[left]], axis=1).ravel()
        first = np.zeros(len(ends), bool)
        first[np.unique(ends, return_index=True)[1]] = True
        now = first.reshape(-1, 2).all(axis=1)
        k = left[now]
        a, b, pair = i[k], j[k], ~wall[k]
        q = g[k] * (T[a] - np.where(pair, T[np.where(pair, b, a)], tw[k]) + (0.0 if shift is None else shift[k]))
        T[a] -= q / C[a]
        T[b[pair]] += q[pair] / C[b[pair]]
        moved[k] = q
        left = left[~now]
    q_walls = moved[active[wall[active]]]
    from_walls = 0.0 - float(np.cumsum(q_walls)[-1]) if len(q_walls) else 0.0   # summed in order
    return moved, capped, from_walls
