"""The frozen-bed thermal stage: after a scene's last DEM run (``[frozen] end`` > 0), the
particles stay where the DEM left them and only heat moves, for ``end`` seconds, at thermal
steps of ``[frozen] step`` set for heat alone (the DEM's step resolves collisions, 1e-5 s; a
settled bed's heat needs steps of about a second, as MFiX and Lethe freeze theirs). SI units.

The network is the lasting-conduction effect's (``LastingConduction.network``), taken once at
the start: particle pairs with H_ij = H_contact + H_gap [W/K] and the particles touching a wall
at a fixed temperature T_w with H_w [W/K]. Each particle i of capacity C_i = m_i c_i [J/K]:

    C_i dT_i/dt = sum_j H_ij (T_j - T_i) + sum_w H_iw (T_w - T_i),   i.e.  C dT/dt = b - A T,

A = L + diag(sum_w H_iw) (L the network's graph Laplacian, its rows and columns summing to
zero), b_i = sum_w H_iw T_w. Integrated by

- ``implicit``: backward Euler, (C/dt + A) T^{n+1} = C/dt T^n + b, one sparse LU factorisation
  (scipy.sparse.linalg.splu) for the whole stage; stable at any step, first order in it;
- ``explicit``: forward Euler, T^{n+1} = T^n + dt (b - A T^n)/C, refused above
  dt_max = min_i C_i / A_ii (every new temperature a convex combination of the old ones and
  the walls': no overshoot, and stable, Gershgorin's bound on the spectrum of C^-1 A).

The balance closes by construction: since L's columns sum to zero, sum_i C_i (T^{n+1} - T^n)
= dt sum_w H_iw (T_w - T_i^*) (T^* = T^{n+1} implicit, T^n explicit), which is what is added to
``heat_from_walls`` (and ``heat_conducted_wall``) step by step; ``heat_conducted_contact`` and
``heat_conducted_gap`` keep the DEM's part only (the stage's pair heat is not split by path). The temperatures go back into
LIGGGHTS' Temp and the run's time goes on by ``end``; frames (history.csv, VTK, probes.csv)
are written every ``[frozen] every``. The gas is not integrated: a scene with a fluid is
refused (the fluid's own energy equation is not frozen with the bed).
"""
from __future__ import annotations

import math

import numpy as np

from pyhost.engines.liggghts.script import ScriptError


def system(C, pairs, walls):
    """(A, b) of C dT/dt = b - A T (the module doc): ``C`` [J/K] (n,), ``pairs`` = (i, j, H)
    with H [W/K], ``walls`` = (p, T_w, H_w). A is a scipy.sparse CSC matrix [W/K], b [W]."""
    from scipy import sparse

    n = len(C)
    i, j, H = (np.asarray(a) for a in pairs)
    p, T_w, H_w = (np.asarray(a) for a in walls)
    K = sparse.coo_matrix((H, (i, j)), shape=(n, n)).tocsr()
    K = K + K.T
    degree = np.asarray(K.sum(axis=1)).ravel() + np.bincount(p.astype(int), H_w, n)
    A = (sparse.diags(degree) - K).tocsc()
    return A, np.bincount(p.astype(int), H_w * T_w, n)


def integrate(C, pairs, walls, T0, end: float, step: float, method: str = "implicit", every: float = 0.0,
              on_row=None):
    """Integrate the frozen network (the module doc) from temperatures ``T0`` [K] for ``end``
    [s] at steps of at most ``step`` [s] (end is a whole number of steps). ``on_row(t, T)`` is
    called every ``every`` [s] (0: every 10 steps) and at the end. Returns (T, Q_walls [J], dt,
    steps): the final temperatures, the heat the walls gave and the step taken. ``on_row`` gets
    (t, T, Q) with Q the walls' heat so far [J]. ScriptError for an explicit step above its
    bound."""
    from scipy.sparse.linalg import splu

    C = np.asarray(C, float)
    T = np.array(T0, float)
    A, b = system(C, pairs, walls)
    steps = max(1, math.ceil(end / step - 1e-9))
    dt = end / steps
    p, T_w, H_w = (np.asarray(a) for a in walls)
    p = p.astype(int)
    if method == "explicit":
        bound = float(np.min(C / np.maximum(A.diagonal(), 1e-300)))
        if dt > bound:
            raise ScriptError(f"frozen.step: {dt:g} s exceeds the explicit stability bound {bound:.4g} s "
                              "(min C_i / sum_j H_ij of the bed): take a smaller step or method = \"implicit\"")
    else:
        from scipy import sparse
        lu = splu((sparse.diags(C / dt) + A).tocsc())
    row_every = max(1, round(every / dt)) if every > 0 else 10
    Q = 0.0
    for k in range(1, steps + 1):
        if method == "explicit":
            Q += dt * float(np.sum(H_w * (T_w - T[p])))
            T = T + dt * (b - A @ T) / C
        else:
            T = lu.solve(C / dt * T + b)
            Q += dt * float(np.sum(H_w * (T_w - T[p])))
        if on_row is not None and (k % row_every == 0 or k == steps):
            on_row(k * dt, T, Q)
    return T, Q, dt, steps


def frozen_stage(loop, log=print) -> None:
    """The frozen stage of ``loop`` (a ``pyhost.loop.Coupling`` after its last run): the
    particles' temperatures integrated for ``scene.frozen.end`` seconds (the module doc), its
    frames written, its totals added to the run's; its figures in summary.json's
    ``frozen_stage``."""
    import time

    scene, fz = loop.scene, loop.scene.frozen
    if loop.fluid is not None:
        raise ScriptError(f"{scene.path}: frozen.end: the frozen stage does not integrate the gas; a scene with a "
                          "fluid cannot freeze its bed (remove [frozen] or the fluid)")
    cond = loop.ctx.find("conduction")
    if cond is None:
        raise ScriptError(f"{scene.path}: frozen.end: needs effects.contact_conduction or effects.gap_conduction")
    loop.settle()                           # the contact events not yet harvested
    cond.conduct()                          # the DEM's last interval, up to now
    atoms = loop.dem.atoms(True)
    loop.ctx.track_particles(atoms)
    C = loop.ctx.C.copy()
    (i, j, Hc, Hg), (p, T_w, Wc, Wg) = cond.network(atoms)
    H = Hc + Hg
    t0 = loop.t
    start = time.perf_counter()

    Q_before = (loop.totals["heat_from_walls"], loop.totals["heat_conducted_wall"])

    def on_row(t, T, Q):
        atoms.T[:] = T
        loop.t = t0 + t
        loop.totals["heat_from_walls"], loop.totals["heat_conducted_wall"] = (q + Q for q in Q_before)
        loop.write_frame()

    T, Q, dt, steps = integrate(C, (i, j, H), (p, T_w, Wc + Wg), atoms.T, fz.end, fz.step, fz.method, fz.every,
                                on_row)
    atoms.T[:] = T
    loop.t = t0 + fz.end
    cond.t_last = loop.t
    loop.totals["heat_from_walls"], loop.totals["heat_conducted_wall"] = (q + Q for q in Q_before)
    seconds = time.perf_counter() - start
    loop.totals["frozen_stage"] = dict(start=t0, end=loop.t, step=dt, steps=steps, method=fz.method,
                                       pairs=int(len(i)), pairs_in_contact=int(np.count_nonzero(Hc)),
                                       wall_links=int(len(p)), heat_from_walls=Q, wall_time=seconds)
    log(f"frozen stage: {fz.end:g} s in {steps} {fz.method} steps of {dt:g} s, {len(i)} pairs "
        f"({np.count_nonzero(Hc)} in contact), {len(p)} wall contacts, {Q:.6g} J from the walls ({seconds:.1f} s)")
