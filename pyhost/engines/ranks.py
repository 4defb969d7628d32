"""The host under ``mpirun -np N python -m pyhost run CASE``: LIGGGHTS' own MPI does the work.

LIGGGHTS decomposes its domain over all N ranks (one LIGGGHTS on ``MPI.COMM_WORLD``, opened
through mpi4py). The host itself (scene, loop, plugin, output, the fluid solver's link) runs
on rank 0 only. The other ranks *follow*: they wait for rank 0's next order and make the same
collective LIGGGHTS call (a command, a run, a variable), or hand their local atoms and contact
events to rank 0 (``gather``) and take back their own slice of what the host changed
(temperatures, velocities, fluid forces: ``scatter``, in the local order they sent). Every
collision is recorded once, by the rank owning the atom of the smaller id (a wall contact:
the particle's owner; ``pyhost.engines.events``), and the total m c T is summed over all
ranks' atoms.

Orders are ``(name, args)`` tuples broadcast from rank 0 (mpi4py's pickled ``bcast``); each
name is one method of :class:`Follower`. Nothing here is a parallel algorithm of ours: the
domain decomposition, ghost exchange and migration are LIGGGHTS'.
"""
from __future__ import annotations

import os
import time

import numpy as np

from pyhost.engines.atoms import local_view

ROOT = 0
ENGINE = [None]
"""This process's LIGGGHTS while a ``Dem.each_rank`` function runs on it (rank 0's and each
follower's): for a function that needs more than its atoms (the fluid's force fix)."""


def world():
    """mpi4py's COMM_WORLD when this process is one of several MPI ranks (started by
    mpirun), else None: a serial run never imports mpi4py."""
    size = int(os.environ.get("OMPI_COMM_WORLD_SIZE") or os.environ.get("PMI_SIZE") or 1)
    if size <= 1:
        return None
    try:
        from mpi4py import MPI
    except ImportError as exc:
        raise RuntimeError("this run has several MPI ranks but mpi4py is missing: run tools/setup.sh --engines") from exc
    return MPI.COMM_WORLD if MPI.COMM_WORLD.Get_size() > 1 else None


def local_atoms(lmp, temperature: bool) -> tuple:
    """This rank's atoms as copies: id, x, v, radius, rmass, type (and Temp)."""
    parts = [_plain(lmp.atom(name)) for name in ("id", "x", "v", "radius", "rmass", "type")]
    if temperature:
        parts.append(_plain(lmp.temperature()) if lmp.nlocal else np.zeros(0))
    return tuple(parts)


def local_snapshot(lmp) -> tuple:
    """Copies of this rank's atoms' ids, x and v (``Dem.keep_snapshot``)."""
    return tuple(_plain(lmp.atom(name).copy()) for name in ("id", "x", "v"))


def local_atoms_of(lmp, ids, temperature: bool) -> tuple:
    """Of these atom ids, those this rank owns: their local indices, and their rows as
    :func:`local_atoms` gives them."""
    here = lmp.atom("id").astype(np.int64)
    rows = np.flatnonzero(np.isin(here, np.asarray(ids, np.int64)))
    return rows, tuple(_plain(np.ascontiguousarray(a[rows])) for a in local_atoms(lmp, temperature))


def _plain(a) -> np.ndarray:
    """A contiguous array whose buffer mpi4py knows: numpy's own format ('i', 'd'), not the
    explicit little-endian one ('<i', '<d') that arrays made from ctypes memory keep, copies
    included."""
    if memoryview(a).format == a.dtype.char and a.flags.c_contiguous:
        return a
    out = np.empty(a.shape, np.dtype(a.dtype.char))     # numpy's builtin dtype (np.array keeps ctypes')
    out[...] = a
    return out


def gather_arrays(comm, arrays) -> tuple:
    """Every rank's arrays (the same number, dtypes and trailing shapes on all ranks), joined
    in rank order on rank 0 through MPI's typed ``Gatherv`` (one copy, no pickling); returns
    (arrays, rows per rank) on rank 0, (None, None) elsewhere. Collective."""
    arrays = [_plain(a) for a in arrays]
    counts = comm.gather(len(arrays[0]) if arrays else 0, root=ROOT)
    joined = []
    for a in arrays:
        if comm.Get_rank() != ROOT:
            comm.Gatherv(a, None, root=ROOT)
            continue
        width = int(np.prod(a.shape[1:], dtype=np.int64))
        whole = np.empty((sum(counts),) + a.shape[1:], a.dtype)
        comm.Gatherv(a, [whole, [c * width for c in counts]], root=ROOT)
        joined.append(whole)
    return (tuple(joined), counts) if comm.Get_rank() == ROOT else (None, None)


class Broadcast:
    """A numpy array rank 0 sends to every rank by MPI's typed ``Bcast`` inside a collective
    call (``Dem.each_rank``'s function calls :meth:`get`): an order's arguments are pickled
    (``Link.order``), and this object pickles to its shape and dtype only, so a per-id table
    of the host (O(N)) is not pickled with the order. Serially (comm None) it is the array."""

    def __init__(self, array):
        self.array = np.ascontiguousarray(array)
        self.shape, self.dtype = self.array.shape, self.array.dtype.str

    def __getstate__(self):
        return dict(shape=self.shape, dtype=self.dtype)

    def __setstate__(self, state):
        self.array, self.shape, self.dtype = None, state["shape"], state["dtype"]

    def get(self, comm) -> np.ndarray:
        """The array on every rank (collective under MPI: every rank calls it)."""
        if comm is None:
            return self.array
        buf = _plain(self.array) if comm.Get_rank() == ROOT else np.empty(self.shape, np.dtype(self.dtype).char)
        if buf.size:
            comm.Bcast(buf, root=ROOT)
        return buf


def sum_bits(comm, bits: np.ndarray) -> np.ndarray | None:
    """The bitwise OR of every rank's uint8 ``bits`` (the same length on all ranks), on rank 0
    (None elsewhere); serially the bits. Collective."""
    if comm is None:
        return bits
    from mpi4py import MPI
    bits = _plain(np.ascontiguousarray(bits, np.uint8))
    out = np.empty_like(bits) if comm.Get_rank() == ROOT else None
    comm.Reduce(bits, out, op=MPI.BOR, root=ROOT)
    return out


def local_values(lmp, names) -> tuple:
    """Copies of these per-atom arrays of this rank's atoms (``Liggghts.atom`` names)."""
    return tuple(lmp.atom(name).copy() for name in names)


def put_by_id(lmp, ids, arrays: dict) -> None:
    """Per-atom values given for all atoms by id: this rank's atoms take theirs. They stand
    for the next run, which then starts without a set-up (that would compute the forces
    again: see pyhost.checkpoint)."""
    here = lmp.atom("id").astype(np.int64)
    ids = np.asarray(ids, np.int64)
    lookup = np.full(int(max(ids.max(initial=0), here.max(initial=0))) + 1, -1, np.int64)
    lookup[ids] = np.arange(len(ids))
    rows = lookup[here]
    if np.any(rows < 0):
        raise ValueError(f"{int(np.sum(rows < 0))} atoms of LIGGGHTS are not among the ids given")
    for name, values in arrays.items():
        lmp.atom(name)[:] = np.asarray(values)[rows]
    lmp.keep_set_up()


def write_local(lmp, T=None, v=None, force=None, force_fix: str | None = None, rows=None) -> None:
    """This rank's own slice of what the host changed, in the local order it sent (``rows``:
    the local indices it sent, if it sent only some atoms)."""
    at = slice(None) if rows is None else rows
    if T is not None and len(T):
        lmp.temperature()[at] = T
    if v is not None and len(v):
        lmp.atom("v")[at] = v
    if force is not None and lmp.nlocal:
        lmp.external_force(force_fix)[:] = force


def local_random_states(lmp, keys) -> dict:
    """This rank's state of each random generator named "what id" (``Liggghts.random_state``)."""
    found = {k: lmp.random_state(*k.split(" ", 1)) for k in keys}
    return {k: v for k, v in found.items() if v is not None}


def set_random_states(lmp, states: dict, rank: int, size: int) -> None:
    """Each random generator's state saved by this rank, when the run has as many ranks as the
    one that saved them."""
    for key, per_rank in states.items():
        if len(per_rank) == size:
            lmp.random_state(*key.split(" ", 1), int(per_rank[rank]))


class Link:
    """Rank 0's side: orders to the followers, and the collective data exchanges."""

    def __init__(self, comm):
        self.comm = comm
        self.size = comm.Get_size()
        self.closed = False
        self.broken = False     # an error inside a collective call: the followers may wait in another one

    def order(self, name: str, *args) -> None:
        if self.closed:
            raise RuntimeError(f"MPI order '{name}' after the other ranks were released")
        if self.broken:
            raise RuntimeError(f"MPI order '{name}': the ranks are out of step after an error inside a collective call")
        self.comm.Ibarrier().Wait()        # the followers wait in theirs (see Follower.next)
        self.comm.bcast((name, args), root=ROOT)

    def gather(self, mine):
        return self.comm.gather(mine, root=ROOT)

    def scatter(self, parts):
        return self.comm.scatter(parts, root=ROOT)

    def close(self) -> None:
        """The followers end (they close their LIGGGHTS if one is open); once."""
        if not self.closed and not self.broken:
            self.order("close")
            self.closed = True

    def abort(self, code: int) -> None:
        """End every rank (MPI_Abort): after an error inside a collective call, the followers
        cannot be released in order. mpirun exits with ``code``."""
        import sys
        sys.stdout.flush()
        sys.stderr.flush()
        self.comm.Abort(code)


class Follower:
    """A rank other than 0: does what rank 0 orders, until ``close``."""

    def __init__(self, comm):
        self.comm, self.lmp = comm, None

    def serve(self) -> int:
        import signal
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):     # rank 0 stops the run and
            signal.signal(sig, signal.SIG_IGN)                         # then releases the followers
        while True:
            name, args = self.next()
            if name == "close":
                if self.lmp is not None:
                    self.lmp.close()
                return 0
            getattr(self, "do_" + name)(*args)

    def next(self):
        """Rank 0's next order. While rank 0 works alone (the plugin, output, the fluid solver),
        this rank waits in a non-blocking barrier, testing it with growing pauses (to 1 ms):
        a blocking MPI call would poll and take a core from the engines."""
        req, pause, spun = self.comm.Ibarrier(), 0.0, time.perf_counter()
        while not req.Test():
            if time.perf_counter() - spun > 1e-3:          # a short busy spell first: orders come in bursts
                pause = min(max(2 * pause, 2e-5), 1e-3)
                time.sleep(pause)
        return self.comm.bcast(None, root=ROOT)

    def do_open(self, cwd, workdir, variables) -> None:
        from pyhost.engines.liggghts import Liggghts
        os.chdir(cwd)
        self.lmp = Liggghts(workdir, variables=variables, comm=self.comm)

    def do_command(self, line) -> None:
        self.lmp.command(line)

    def do_context(self, text) -> None:
        self.lmp.context(text)

    def do_run(self, steps) -> None:
        from pyhost.engines.liggghts import LiggghtsError
        try:
            self.lmp.run(steps)
        except LiggghtsError:
            pass                  # rank 0 has the same error and reports it; orders go on

    def do_set_up_next(self) -> None:
        self.lmp.set_up_next()

    def do_variable(self, name) -> None:
        self.lmp.variable(name)

    def do_atoms(self, temperature) -> None:
        self.rows = None
        gather_arrays(self.comm, local_atoms(self.lmp, temperature))

    def do_atoms_of(self, ids, temperature) -> None:
        self.rows, parts = local_atoms_of(self.lmp, ids, temperature)
        gather_arrays(self.comm, parts)

    def do_count(self) -> None:
        self.comm.gather(self.lmp.nlocal, root=ROOT)

    def do_per_atom(self, names) -> None:
        self.comm.gather(local_values(self.lmp, names), root=ROOT)

    def do_mesh_times(self, times) -> None:
        for fix, t in times.items():
            self.lmp.move_mesh_time(fix, t)

    def do_random_states(self, keys) -> None:
        self.comm.gather(local_random_states(self.lmp, keys), root=ROOT)

    def do_set_random_states(self, states) -> None:
        set_random_states(self.lmp, states, self.comm.Get_rank(), self.comm.Get_size())

    def do_insertion_progress(self, progress) -> None:
        for fix, p in progress.items():
            self.lmp.insert_progress(fix, [float(x) for x in p])

    def do_put(self, ids, arrays) -> None:
        put_by_id(self.lmp, ids, arrays)

    def do_events(self, name, args) -> None:
        """This rank's contact event recorder (pyhost.engines.events.RankEvents)."""
        from pyhost.engines.events import GATHERED, ContactEvents, ask
        if name == "attach":
            self.events = ContactEvents(self.lmp, *args)
            return
        mine = ask(self.events, name, args)
        if name in GATHERED:
            self.comm.gather(mine, root=ROOT)

    def do_keep_snapshot(self) -> None:
        self.snap = local_snapshot(self.lmp)
        self.comm.gather(len(self.snap[0]), root=ROOT)

    def do_snapshot(self) -> None:
        gather_arrays(self.comm, self.snap)

    def do_each_rank(self, func, args, temperature=True) -> None:
        """``Dem.each_rank``: ``func`` on this rank's atoms and events, its result to rank 0."""
        ENGINE[0] = self.lmp
        self.comm.gather(func(local_view(self.lmp, temperature), getattr(self, "events", None), self.comm, *args),
                         root=ROOT)

    def do_write(self, force_fix) -> None:
        write_local(self.lmp, *self.comm.scatter(None, root=ROOT), force_fix=force_fix, rows=getattr(self, "rows", None))
