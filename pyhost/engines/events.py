"""Contact events recorded inside LIGGGHTS at every DEM step (``plugins/liggghts/contact_events.cpp``).

``ContactEvents(lmp)`` adds ``fix collheat_events all external pf/callback 1 APPLY`` and attaches
the helper's recorder to it: from the next run on, every step (in compiled code, no Python)
notes each particle-particle contact and each contact with a wall (primitive walls by
LIGGGHTS' own geometry, mesh walls) that begins or ends. ``take()`` hands the events over in
a batch, as a numpy structured array of ``EVENT``: kind (``BEGIN`` or ``END``), step, i and
j (atom ids, the smaller first; j is WALL_BASE + wall index for a wall), vn, the approach
speed at the first step in contact [m/s] (the relative normal velocity before any contact
force acted: the impact speed), the unit normal n from j to i, and for an END the contact's
duration in steps. Units SI.

With a script's fix heat/gran, ``conduction(fix, window)`` has the recorder also keep the flux
heat/gran conducts through each new pair contact at each of its first ``window`` steps (its
own formula, in compiled code); ``histories()`` hands them over once full or ended; and each
BEGIN carries T, the two temperatures [K] at its step (NaN without heat/gran; for a wall, the
particle's and NaN). ``restitution(keys, speeds, normals)`` has the recorder impose those
separation speeds at the step each contact ends (restitution feedback); the END says so.

Under MPI (``RankEvents``) each rank records the contacts of its own atoms; rank 0 orders the
others and joins their batches (events only, a few per collision: no atoms, no contacts).
A contact whose atom moves to another rank at a neighbour build ends there and begins on the
new rank at the same step, both rows flagged ``moved``; :func:`join_moved` drops such pairs.
"""
from __future__ import annotations

import ctypes

import numpy as np

from pyhost.engines.collective import collective

FIX = "collheat_events"
APPLY = 1 << 30
"""The fix's napply: LIGGGHTS adds its (zeroed) force array only at steps that are multiples
of it, not at every step (plugins/liggghts/contact_events.cpp keeps the same number)."""


def fix_command(fix: str = FIX) -> str:
    """The LIGGGHTS command that adds the recorder's fix: its callback at every step."""
    return f"fix {fix} all external pf/callback 1 {APPLY}"


ROW = 12
BEGIN, END = 0, 1
EVENT = np.dtype([("kind", np.int8), ("wall", np.bool_), ("step", np.int64), ("i", np.int64), ("j", np.int64),
                  ("vn", float), ("n", float, 3), ("duration", np.int64), ("T", float, 2), ("imposed", np.bool_),
                  ("moved", np.bool_)])

_c = ctypes
_vp, _int, _dp = _c.c_void_p, _c.c_int, _c.POINTER(_c.c_double)
_DECLARATIONS = {
    "collheat_events_attach": (_vp, [_vp, _c.c_char_p]),
    "collheat_events_primitives": (_int, [_vp, _int, _c.POINTER(_c.c_char_p), _dp]),
    "collheat_events_meshes": (_int, [_vp, _int, _c.POINTER(_c.c_char_p), _dp]),
    "collheat_events_prime": (None, [_vp]),
    "collheat_events_sync": (None, [_vp]),
    "collheat_events_waiting": (_int, [_vp]),
    "collheat_events_open": (_int, [_vp]),
    "collheat_events_total": (_c.c_longlong, [_vp, _int]),
    "collheat_events_take": (_int, [_vp, _dp, _int]),
    "collheat_events_free": (None, [_vp]),
    "collheat_events_conduction": (_int, [_vp, _c.c_char_p, _int]),
    "collheat_events_wall_conduction": (_int, [_vp, _int, _int, _dp]),
    "collheat_events_histories": (_int, [_vp, _int]),
    "collheat_events_take_histories": (_int, [_vp, _dp, _int]),
    "collheat_events_appeared": (_int, [_vp, _dp, _int]),
    "collheat_events_restitution": (None, [_vp, _int, _c.POINTER(_c.c_int64), _dp, _dp]),
    "collheat_events_forget": (None, [_vp, _int, _c.POINTER(_c.c_int64)]),
    "collheat_events_meshes_by_history": (_int, [_vp]),
    "collheat_events_heat_gran_heat": (None, [_vp, _dp]),
    "collheat_events_walls_after": (_int, [_vp]),
    "collheat_events_reattach": (_int, [_vp, _c.c_char_p]),
}
IMPOSED, MOVED = 1, 2      # the flags column
HEAD = 4


class ContactEvents:
    """The contact events of one LIGGGHTS instance (``pyhost.engines.liggghts.Liggghts``):
    serially all, under MPI this rank's (see :class:`RankEvents`). Create it before the run whose contacts it should follow: the contacts present at
    that run's set-up are open contacts, not events (see :meth:`prime`)."""

    def __init__(self, lmp, fix: str = FIX):
        self.lmp, self.fix = lmp, fix
        h = lmp.helper
        for name, (restype, argtypes) in _DECLARATIONS.items():
            fn = getattr(h, name)
            fn.restype, fn.argtypes = restype, argtypes
        lmp.command(fix_command(fix))
        self.handle = h.collheat_events_attach(lmp.ptr, fix.encode())
        if not self.handle:
            raise RuntimeError(f"could not attach the contact event recorder to fix {fix}")
        self.window = 0
        self.joined = []        # contacts that moved between ranks, at the last take (RankEvents)

    def conduction(self, fix: str, window: int) -> None:
        """Keep the flux [W] of ``fix <fix> ... heat/gran`` through each new pair contact at
        each of its first ``window`` steps."""
        if self.lmp.helper.collheat_events_conduction(self.handle, fix.encode(), int(window)):
            raise RuntimeError(f"fix {fix} is not a heat/gran conduction: no flux histories")
        self.window = int(window)

    def appeared(self) -> tuple:
        """Atoms that appeared (inserted) since the last call, with heat/gran: ids, Temp [K]
        at their first step, before heat/gran conducted any heat to them, and that step."""
        h = self.lmp.helper
        n = h.collheat_events_appeared(self.handle, None, 0) if self.window else 0
        raw = np.empty((n, 3))
        if n:
            raw = raw[:h.collheat_events_appeared(self.handle, raw.ctypes.data_as(_dp), n)]
        return raw[:, 0].astype(np.int64), raw[:, 1], raw[:, 2].astype(np.int64)

    def heat_gran_heat(self) -> tuple[float, float]:
        """What the script's fix heat/gran added to the particles' m c T since the last call,
        summed at every step as it integrates [J]: (from its sources, per-atom heatSource [W];
        from its conduction, whose pair terms cancel: what its walls with a temperature
        conducted in). (0, 0) without heat/gran."""
        out = (_c.c_double * 2)()
        self.lmp.helper.collheat_events_heat_gran_heat(self.handle, out)
        return out[0], out[1]

    def keep_last(self) -> bool:
        """The recorder's fix given anew after every fix wall/gran, if a script defined one after
        it (after the first run): LIGGGHTS calls the fixes' post_force in their order, and a
        wall's adds heat/gran's flux through its contacts after the recorder summed the flux of
        the step (the walls' heat went uncounted: an energy balance broken at the end). The
        recorder adds no force, so the trajectory is the same; its contacts and histories stay.
        Returns whether it moved (the next run sets up anew, as after any command)."""
        h = self.lmp.helper
        if not h.collheat_events_walls_after(self.handle):
            return False
        self.lmp.command(f"unfix {self.fix}")
        self.lmp.command(fix_command(self.fix))
        if h.collheat_events_reattach(self.handle, self.fix.encode()):
            raise RuntimeError(f"could not attach the contact event recorder to fix {self.fix} again")
        return True

    def restitution(self, keys, speed, normal) -> None:
        """Separation speeds [m/s] to impose on open contacts (``pyhost.collisions.contact_keys``)
        at the step each ends; ``normal`` (n, 3): a wall's, from the wall to the particle (a
        pair takes its line of centres then). An END event says whether it was imposed."""
        keys = np.ascontiguousarray(keys, dtype=np.int64)
        speed = np.ascontiguousarray(speed, dtype=float)
        normal = np.ascontiguousarray(np.reshape(normal, (-1, 3)), dtype=float)
        self.lmp.helper.collheat_events_restitution(self.handle, len(keys), keys.ctypes.data_as(_c.POINTER(_c.c_int64)),
                                                    speed.ctypes.data_as(_dp), normal.ctypes.data_as(_dp))

    def forget(self, keys) -> None:
        """Drop the separation speeds of these contacts (they ended: under MPI the ranks where
        they did not end keep theirs until told)."""
        keys = np.ascontiguousarray(keys, dtype=np.int64)
        self.lmp.helper.collheat_events_forget(self.handle, len(keys), keys.ctypes.data_as(_c.POINTER(_c.c_int64)))

    def histories(self, all: bool = False) -> tuple:
        """The flux histories handed over (with ``all``, also those still filling, which the
        recorder then drops): i, j (ids, i < j), the step the contact began, the steps kept,
        and the fluxes [W] into i at each step from the begin, (n, window)."""
        h = self.lmp.helper
        n = h.collheat_events_histories(self.handle, int(all)) if self.window else 0
        raw = np.empty((n, HEAD + self.window))
        if n:
            raw = raw[:h.collheat_events_take_histories(self.handle, raw.ctypes.data_as(_dp), n)]
        ids = raw[:, :3].astype(np.int64)
        return ids[:, 0], ids[:, 1], ids[:, 2], raw[:, 3].astype(np.int64), raw[:, HEAD:]

    def primitives(self, ids, codes) -> bool:
        """Primitive walls (planes, cylinders: any kind LIGGGHTS has): the ``fix wall/gran ...
        primitive`` id and the partner code (WALL_BASE + wall index) of each. The recorder takes
        their geometry, their list of nearby particles and their group from LIGGGHTS' own fix.
        False (nothing changed) if one is not such a fix."""
        arr = (_c.c_char_p * len(ids))(*[i.encode() for i in ids])
        codes = np.ascontiguousarray(codes, dtype=float)
        return self.lmp.helper.collheat_events_primitives(self.handle, len(ids), arr, codes.ctypes.data_as(_dp)) >= 0

    def wall_conduction(self, meshes: bool, params) -> bool:
        """The walls (of the primitives or the meshes, as last given, in their order) through
        which the script's fix heat/gran conducts and whose collisions the host gives heat:
        (temperature [K], < 0: none; atom type; contact area mode 0 overlap, 1 constant, 2
        projection; constant area [m^2]) for each. Their new contacts keep flux histories as
        pairs do (``histories``, the wall's code as j). False if that is not one per wall."""
        params = np.ascontiguousarray(np.reshape(params, (-1, 4)), dtype=float)
        return self.lmp.helper.collheat_events_wall_conduction(self.handle, int(meshes), len(params),
                                                               params.ctypes.data_as(_dp)) == 0

    def meshes(self, ids, codes) -> bool:
        """Mesh walls: the ``fix mesh/surface`` id and the partner code of each. False (and
        none recorded) if one has no neighbour list of a fix wall/gran to take candidates from."""
        arr = (_c.c_char_p * len(ids))(*[i.encode() for i in ids])
        codes = np.ascontiguousarray(codes, dtype=float)
        return self.lmp.helper.collheat_events_meshes(self.handle, len(ids), arr, codes.ctypes.data_as(_dp)) >= 0

    @property
    def meshes_by_history(self) -> int:
        """Mesh walls whose contacts the last step read from LIGGGHTS' own mesh contact history
        (fix wall/gran with tangential history, defined before the recorder's fix); the others
        are found by the recorder's own sphere-triangle test."""
        return self.lmp.helper.collheat_events_meshes_by_history(self.handle)

    def prime(self) -> None:
        """The next step records the contacts there as open, without events (a (re)start)."""
        self.lmp.helper.collheat_events_prime(self.handle)

    def sync(self) -> None:
        """Record the contacts now, between runs: only right after a set-up (``run 0``), whose
        neighbour lists hold; walls given since then take their contacts as open."""
        self.lmp.helper.collheat_events_sync(self.handle)

    @property
    def waiting(self) -> int:
        return self.lmp.helper.collheat_events_waiting(self.handle)

    @property
    def open_count(self) -> int:
        """Contacts open now."""
        return self.lmp.helper.collheat_events_open(self.handle)

    def totals(self) -> tuple[int, int]:
        """(begun, ended): events recorded since the recorder was attached."""
        h = self.lmp.helper
        return h.collheat_events_total(self.handle, 0), h.collheat_events_total(self.handle, 1)

    def take(self) -> np.ndarray:
        """The events waiting, oldest first, as an array of ``EVENT``; the recorder forgets them."""
        n = self.waiting
        raw = np.empty((n, ROW))
        if n:
            got = self.lmp.helper.collheat_events_take(self.handle, raw.ctypes.data_as(_dp), n)
            raw = raw[:got]
        out = np.empty(len(raw), EVENT)
        kind = raw[:, 0].astype(int)
        out["kind"] = kind % 2
        out["wall"] = kind >= 2
        out["step"] = raw[:, 1]
        out["i"], out["j"] = raw[:, 2], raw[:, 3]
        out["vn"] = raw[:, 4]
        out["n"] = raw[:, 5:8]
        out["duration"] = raw[:, 8]
        out["T"] = raw[:, 9:11]
        flags = raw[:, 11].astype(int)
        out["imposed"] = (flags & IMPOSED) > 0
        out["moved"] = (flags & MOVED) > 0
        return out

    def close(self) -> None:
        if self.handle:
            self.lmp.helper.collheat_events_free(self.handle)
            self.handle = None


GATHERED = {"take", "histories", "appeared", "primitives", "meshes", "wall_conduction", "waiting", "open_count", "totals",
            "heat_gran_heat"}
"""What each rank answers to rank 0 (the others' recorders change only their own state)."""


def ask(events, name: str, args=()):
    """One rank's recorder does ``name`` (a method, or a property without ``args``)."""
    value = getattr(events, name)
    return value(*args) if callable(value) else value


def join_moved(ev: np.ndarray) -> np.ndarray:
    """All ranks' events of one harvest, with the contacts that moved between ranks joined: an
    END flagged ``moved`` (its atom left the rank at a neighbour build) and a BEGIN flagged
    ``moved`` (new on a rank at a build) of the same contact at the same step are one open
    contact going on, and both go. What is left of either is a real END (the contact ended as
    its atom left) or BEGIN (it began at the build). Returns the events, oldest first (by
    step; the ranks' order within a step), flags cleared, and the joined ones as ``(key, step
    it began, step it moved)`` rows (the flux histories use them)."""
    from pyhost.collisions import contact_keys
    moved = np.flatnonzero(ev["moved"])
    drop = np.zeros(len(ev), bool)
    joined = []
    if len(moved):
        keys = contact_keys(ev["i"][moved], ev["j"][moved])
        ends = {}
        for r, k in zip(moved.tolist(), keys.tolist()):
            if ev["kind"][r] == END:
                ends[k, int(ev["step"][r])] = r
        for r, k in zip(moved.tolist(), keys.tolist()):
            e = ends.get((k, int(ev["step"][r]))) if ev["kind"][r] == BEGIN else None
            if e is not None:
                drop[[r, e]] = True
                step = int(ev["step"][r])
                joined.append((k, step - int(ev["duration"][e]), step))
    out = ev[~drop]
    out["moved"] = False
    return out[np.argsort(out["step"], kind="stable")], joined


class RankEvents:
    """Rank 0's recorder under MPI: every rank's own :class:`ContactEvents` (each records the
    contacts of its atoms, in compiled code), ordered through the link
    (``pyhost.engines.ranks.Link``); what rank 0 asks of them is joined here, events and flux
    histories only. The interface is ContactEvents' (but meshes_by_history, a test's probe)."""

    def __init__(self, lmp, link, fix: str = FIX):
        self.link, self.joined = link, []
        link.order("events", "attach", (fix,))
        self.local = ContactEvents(lmp, fix)

    @property
    def window(self) -> int:
        return self.local.window

    @collective
    def _all(self, name: str, *args):
        """Every rank does it; rank 0's answer, and with GATHERED all ranks' in rank order."""
        self.link.order("events", name, args)
        mine = ask(self.local, name, args)
        return self.link.gather(mine) if name in GATHERED else mine

    def conduction(self, fix: str, window: int) -> None:
        self._all("conduction", fix, window)

    def primitives(self, ids, codes) -> bool:
        return all(self._all("primitives", list(ids), list(codes)))

    def meshes(self, ids, codes) -> bool:
        return all(self._all("meshes", list(ids), list(codes)))

    def wall_conduction(self, meshes: bool, params) -> bool:
        return all(self._all("wall_conduction", meshes, np.asarray(params)))

    def keep_last(self) -> bool:
        return self._all("keep_last")

    def prime(self) -> None:
        self._all("prime")

    def sync(self) -> None:
        self._all("sync")

    def heat_gran_heat(self) -> tuple[float, float]:
        parts = self._all("heat_gran_heat")                # (summed in rank order)
        return float(sum(p[0] for p in parts)), float(sum(p[1] for p in parts))

    def restitution(self, keys, speed, normal) -> None:
        self._all("restitution", np.asarray(keys), np.asarray(speed), np.asarray(normal))

    def forget(self, keys) -> None:
        self._all("forget", np.asarray(keys))

    @property
    def waiting(self) -> int:
        return sum(self._all("waiting"))

    @property
    def open_count(self) -> int:
        return sum(self._all("open_count"))

    def totals(self) -> tuple[int, int]:
        parts = self._all("totals")
        return sum(p[0] for p in parts), sum(p[1] for p in parts)

    def take(self) -> np.ndarray:
        ev, self.joined = join_moved(np.concatenate(self._all("take")))
        return ev

    def histories(self, all: bool = False) -> tuple:
        parts = self._all("histories", all)
        return tuple(np.concatenate([p[k] for p in parts]) for k in range(5))

    def appeared(self) -> tuple:
        """As ContactEvents.appeared, each atom once: at the first step any rank saw it (one
        that moved to a rank that had not seen so large an id appears there again, later)."""
        parts = self._all("appeared")
        ids, T, step = (np.concatenate([p[k] for p in parts]) for k in range(3))
        order = np.lexsort((step, ids))
        first = order[np.r_[True, ids[order][1:] != ids[order][:-1]]] if len(ids) else order
        return ids[first], T[first], step[first]

    def close(self) -> None:
        self.local.close()          # the other ranks' go with their LIGGGHTS
