"""Contacts as keys, and the open contacts between two samples of the DEM's contact lists.

Pure functions and one small state holder, no engine calls, so that the coupling loop can
be tested without engines. The physics they feed lives in plugins/: impact speeds in
``plugins.dem.hertz``, heat in ``plugins.heat.batch``, its exchange in ``plugins.heat.exchange``.

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

from plugins.heat.exchange import WALL_BASE


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
