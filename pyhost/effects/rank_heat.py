"""Collision heat on each MPI rank, for the rank's own particles (``CollisionHeat.harvest_on_ranks``).

Under mpirun every rank records the contacts of its own atoms (``pyhost.engines.events``): a
pair on the rank owning the smaller id, a wall contact on the particle's owner. At a harvest
(without a fix heat/gran; after one of at least ``ON_RANKS_FROM`` collisions), each rank takes
its events and moves the heat of its collisions, in their order, into LIGGGHTS' ``Temp`` of its
own atoms (``on_rank``, run on every rank). A partner owned by another rank (a pair across the cut)
takes part with its temperature and heat capacity as its owner has them at the harvest's
start, and the heat it received goes to its owner, which adds it to the particle's
temperature once its own collisions are moved. Rank 0 gets the collisions' log rows, the
balance's heat contents of the atoms whose temperature changed, a few counts, and the events
left over, which it moves itself on the atoms of those events only (``CollisionHeat.harvest``):

- a collision of a particle of a type without material, or one rank 0 has not seen yet
  (inserted since its last look) when its starting temperature is not its type's (box
  scenes; a script's particle takes its material's temperature on its rank);
- a collision whose particle is no longer on the rank that recorded it (it moved to
  another rank, or left the simulation, before the harvest);
- a contact that moved between ranks while open (``moved``: rank 0 joins the two halves).

Each collision's heat leaves one body and enters the other, so the particles' sum(m c T)
changes only by the walls' heat, as serially. Heat moves collision after collision with the
temperatures of that moment; a particle whose collisions of one batch are moved in two places
(two ranks, or a rank and rank 0) sees those of the other place's after its own instead of in
their order. The heat of such a collision differs from the serial order's by the other
collisions' share of its temperature difference (in tests/cases/test_mpi.py: at most 7.2e-6
of the largest collision's heat). Rank 0 writes the log rows of all in the serial order (step,
walls last, ids). SI units.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pyhost.collisions import Bodies, collide, log_wall, material_of
from pyhost.engines.events import BEGIN, END
from pyhost.tables import lookup


@dataclass(frozen=True)
class RankHeat:
    """What each rank needs to move collision heat (the host's view, sent with each harvest):
    the scene's materials (real and DEM, ``plugins.heat.batch``), the material index of each
    atom type (-1: none), the heat capacity of each material [J/(kg K)], the heat models (the
    first moves heat, the others are side columns), the plugin's path, each wall's
    temperature [K] (NaN: adiabatic) and real material (-1: the particle's), the run's clock
    (``Coupling.clock``: a collision's time [s] from its step), which ids rank 0 has seen
    (``np.packbits``, ``seen_count`` of them) and the
    temperature [K] an atom of each type starts at (NaN: its own; None: rank 0 sets them);
    with ``restitution`` (feedback), the ENDs and the collisions' events go to rank 0 too."""

    materials: list
    type_material: np.ndarray
    capacity: np.ndarray
    models: tuple
    path: str
    T_wall: np.ndarray
    wall_material: np.ndarray
    clock: tuple
    seen: np.ndarray
    seen_count: int
    T_of_type: np.ndarray | None
    restitution: bool = False


def on_rank(atoms, events, comm, setup: RankHeat) -> dict:
    """One rank's part of a harvest (collective: every rank calls it): its events taken, the
    heat of its collisions moved into its ``atoms``' T (the engine's own memory, writable),
    the heat of partners on other ranks sent to their owners. Returns:

    - ``cols``: those collisions' log rows, with their ``step`` and partner code ``jj`` (the
      order rank 0 sorts by);
    - ``still`` (contacts begun without an approach speed), ``capped``, ``flagged`` (outside
      the models' range) and ``v_flagged`` (the fastest of those);
    - for the balance: ``ids``, ``mass`` [kg], ``type``, ``T_before`` and ``T_after`` [K] of
      this rank's atoms whose temperature changed, and ``new``: the atoms rank 0 had not
      seen, given their starting temperature here (ids, mass, type, radius and the
      temperature they had before);
    - ``events``: those left to rank 0 (with restitution feedback also every END, and the
      collisions' events as ``begun``). Without restitution feedback an END is dropped
      unless it moved between ranks: nothing else reads it."""
    allgather = comm.allgather if comm is not None else (lambda mine: [mine])     # (serially: one rank)
    ev = events.take()
    ids, types, T, mass, radius = atoms.id, atoms.type, atoms.T, atoms.mass, atoms.radius
    material = material_of(setup.type_material, types)
    wall, i, j = ev["wall"], ev["i"], ev["j"]
    j_atom = np.where(wall, i, j)
    top = int(max(ids.max(initial=0), i.max(initial=0), j_atom.max(initial=0))) + 1
    local = np.full(top, -1, np.int64)
    local[ids] = np.arange(len(ids))
    seen = np.zeros(top, bool)
    n = min(top, setup.seen_count)
    seen[:n] = np.unpackbits(setup.seen, count=setup.seen_count)[:n].astype(bool)
    begun = (ev["kind"] == BEGIN) & ~ev["moved"]
    here_ids = np.zeros(top, bool)
    here_ids[ids] = True
    asked = np.unique(j_atom[begun & here_ids[i] & ~here_ids[j_atom]])     # partners on other ranks
    wanted = np.unique(np.concatenate(allgather(asked)))
    # atoms rank 0 has not seen yet (inserted since) among those of the events and those asked
    # for: their material's temperature now, as rank 0 sets it when it first sees an atom
    if setup.T_of_type is not None:
        involved = np.zeros(top, bool)
        involved[np.r_[i[begun], j_atom[begun], wanted[wanted < top]]] = True
        fresh = np.flatnonzero(involved[ids] & ~seen[ids] & (material >= 0))
        T_set = lookup(setup.T_of_type, types[fresh])
        result_new = (ids[fresh], mass[fresh].copy(), types[fresh].copy(), radius[fresh].copy(), T[fresh].copy())
        T[fresh] = np.where(np.isnan(T_set), T[fresh], T_set)
        seen[ids[fresh]] = True
    else:
        result_new = (np.zeros(0, np.int64), np.zeros(0), np.zeros(0, types.dtype), np.zeros(0), np.zeros(0))
    ok = np.zeros(top, bool)            # here, seen by rank 0 (or as it will), of a type with material
    ok[ids] = seen[ids] & (material >= 0)
    have = local[wanted[wanted < top]] if len(wanted) else np.zeros(0, np.int64)
    have = have[have >= 0]
    have = have[ok[ids[have]]]
    # (no rank asked for any: every rank knows it from the same ``wanted``, and skips both exchanges)
    mine = (ids[have], T[have].copy(), mass[have].copy(), radius[have].copy(), material[have])
    answers = allgather(mine) if len(wanted) else [mine]
    r_id, r_T, r_m, r_R, r_mat = (np.concatenate([a[k] for a in answers]) for k in range(5))
    remote = np.full(max(top, int(r_id.max(initial=0)) + 1), -1, np.int64)
    remote[r_id] = len(ids) + np.arange(len(r_id))
    if len(remote) > top:
        local, ok = np.r_[local, np.full(len(remote) - top, -1)], np.r_[ok, np.zeros(len(remote) - top, bool)]
    li = local[i]
    lj = np.where(local[j_atom] >= 0, local[j_atom], remote[j_atom])
    here = begun & ok[i] & (wall | ok[j_atom] | (remote[j_atom] >= 0))
    out = ev["moved"] | (begun & ~here)
    if setup.restitution:              # rank 0 gives the separation speeds: it needs the ends
        out |= ev["kind"] == END
    go = np.flatnonzero(here)
    still = go[~(ev["vn"][go] > 0)]
    go = go[ev["vn"][go] > 0]
    go = go[np.lexsort((j[go], i[go], wall[go], ev["step"][go]))]     # the order of the serial harvest
    a, b, w = li[go], lj[go], wall[go]
    # this rank's atoms, then the partners of other ranks: temperatures, capacities, radii, materials
    T_all, R_all, mat_all = np.r_[T, r_T], np.r_[radius, r_R], np.r_[material, r_mat]
    m_all = np.r_[mass, r_m]
    C_all = m_all * setup.capacity[np.maximum(mat_all, 0)]
    T_before = T.copy()
    result = dict(events=ev[out], still=len(still), capped=0, flagged=0, v_flagged=0.0, new=result_new)
    bodies = Bodies(setup.materials, setup.type_material, setup.wall_material)
    p = bodies.partners(j[go], mat_all[a], R_all[a], mat_all[b], R_all[b], m_all[a], m_all[b])
    if len(go):
        heat, flagged, capped = collide(setup.models, setup.path, bodies, p, ev["vn"][go], T_all, C_all, a,
                                        np.where(w, j[go], b), setup.T_wall, None)
        result.update(capped=capped, flagged=int(flagged.sum()),
                      v_flagged=float(ev["vn"][go][flagged].max(initial=0.0)))
    else:
        heat = {k: np.zeros(0) for k in ("Q", "e", "t_coll")} | {f"Q_{m}": np.zeros(0) for m in setup.models[1:]}
    T[:] = T_all[:len(ids)]
    # the heat partners on other ranks received, to their owners, added after the owners' own
    into = (~w) & (b >= len(ids))
    sent = allgather((j[go][into], heat["Q"][into])) if len(wanted) else []
    for got_id, got_q in sent:
        owned = (got_id < len(local)) & (local[np.minimum(got_id, len(local) - 1)] >= 0)
        k = local[got_id[owned]]
        np.add.at(T, k, got_q[owned] / C_all[k])       # (in the order sent: the rank, then the collision)
    changed = np.flatnonzero(T != T_before)
    if setup.restitution:
        result["begun"] = ev[go]
    result.update(ids=ids[changed], mass=mass[changed].copy(), type=types[changed].copy(),
                  T_before=T_before[changed], T_after=T[changed].copy(), step=ev["step"][go], jj=j[go],
                  cols=dict(time=setup.clock[0] + (ev["step"][go] - setup.clock[1]) * setup.clock[2],
                            step=ev["step"][go], i=i[go], j=np.where(w, 0, j[go]),
                            wall=log_wall(j[go]), v0=ev["vn"][go],
                            model=np.full(len(go), setup.models[0]), **heat))
    return result
