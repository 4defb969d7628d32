"""Lasting conduction between particles: through the solid contact of two touching particles
(``effects.contact_conduction``) and through the gas between two near each other
(``effects.gap_conduction``), by the models of ``plugins.conduction``. Present when the scene
asks for either (``conduction``); SI units.

Every ``conduction.every`` DEM steps the particles' pairs within reach are found (centre
distance, from LIGGGHTS' positions now), each pair's conductance H [W/K] is computed from the
real materials, and the heat of the interval since the last update is moved in LIGGGHTS'
``Temp`` (``plugins.conduction.exchange``: exact for an isolated pair at any interval). The
heat only moves between particles, so the energy balance (``effects.balance``) holds to
round-off with no term of its own; ``heat_conducted_contact`` and ``heat_conducted_gap`` in
summary.json are the sums of |q| of the two paths.

Who owns a contact's time. A collision's heat (``effects.collisions``) stands for the first
t_coll of its contact, t_coll the duration under the real material's model: the contact path
conducts only from the collision's begin + t_coll on. So a contact found at an update over
[t0, t1] whose collision began at t_b conducts for max(0, t1 - max(t0, t_b + t_coll)); when
collision heat is on, the contact events are harvested at each update, so every collision
begun up to t1 is known then. A contact that began without a collision (there at the start or a
restart, or without approach speed), or any contact when the scene has no collision heat,
conducts for the whole interval in which it is found at its end (a contact that begins
within an interval is counted from the interval's start: at most ``every`` steps too early).
The gas path conducts during collisions too (the collision models are the solid contact's).

Walls at a fixed temperature (``HostWall.temperature``; primitive planes and cylinders, a box
scene's faces) conduct into the particles that touch them by the same models, the wall a sphere
of ``WALL_RADIUS`` particle radii (R* within 0.1 % of the particle's radius, the plane's limit)
of the wall's material, and the pair's exact relaxation with the wall's capacity infinite. Their
heat is the balance's ``heat_from_walls`` (as a collision's with a wall) and summary.json's
``heat_conducted_wall``. A wall contact conducts over every interval it is found in, its
collision's t_coll included (a collision with a heated wall counts its heat twice during its
t_coll, about 1e-5 s). Gap models with a reach beyond contact (``rong_horio``, whose lens is
around the larger body: the wall) are refused with heated walls; ``lethe``'s macrogap is a
contact's and goes to walls. ``network`` gives the conductances [W/K] the frozen stage
(``pyhost.frozen``) integrates.
"""
from __future__ import annotations

import numpy as np

from plugins.conduction import CONTACT, GAP, Gas, Pair, exchange
from plugins.dem.hertz import effective_modulus
from pyhost.collisions import contact_keys
from pyhost.effects import Effect
from pyhost.engines.liggghts.script import ScriptError
from pyhost.walls import primitive_overlap


WALL_RADIUS = 1e3
"""A wall's radius in the conduction models, in radii of the particle it touches [-]."""


class LastingConduction(Effect):
    """``owned``: contact key -> end [s] of its last collision's model time (contacts whose
    collision heat still stands for their time); ``walls``: the HostWalls at a temperature and
    their geometry (``pyhost.walls`` primitives)."""

    TOTALS = dict(heat_conducted_contact=0.0, heat_conducted_gap=0.0, heat_conducted_wall=0.0,
                  frozen_stage=None)     # the frozen stage's figures (pyhost.frozen), when a scene has one

    def __init__(self, loop):
        super().__init__(loop)
        self.walls = []                      # (HostWall, primitive) of the walls at a temperature (at_run)
        # scipy's tree only where a scene conducts: every other run is spared its import
        from scipy.spatial import cKDTree

        self.tree = cKDTree
        scene = loop.scene
        fx = scene.effects
        self.contact = CONTACT.lookup(fx.contact_conduction) if fx.contact_conduction != "none" else None
        self.gap = GAP.lookup(fx.gap_conduction) if fx.gap_conduction != "none" else None
        c = scene.conduction
        self.gas = Gas(c.gas_conductivity, c.lens, c.min_distance, c.gas_parameter)
        if self.contact is not None and loop.dem.info.heat_gran:
            raise ScriptError(f"{scene.path}: effects.contact_conduction = {fx.contact_conduction!r}: the script's fix "
                              f"heat/gran {loop.dem.info.heat_gran!r} conducts through the same contacts; remove one")
        mats = loop.materials
        self.k = np.array([m.conductivity for m in mats])
        self.E_real = np.array([[effective_modulus(a.youngs_modulus, a.poisson_ratio, b.youngs_modulus, b.poisson_ratio)
                                 for b in mats] for a in mats])
        softened = [m.dem for m in mats]      # the DEM's contact of each material (None: in no pair)
        self.E_dem = np.array([[effective_modulus(a.youngs_modulus, a.poisson_ratio, b.youngs_modulus, b.poisson_ratio)
                                if a and b else np.nan for b in softened] for a in softened])
        self.sigma = np.array([m.roughness for m in mats])
        self.slope = np.array([m.surface_slope for m in mats])
        self.hardness = np.array([m.microhardness for m in mats])
        if fx.contact_conduction == "lethe_rough":
            for m, name in zip(mats, scene.materials):
                if not (m.roughness > 0 and m.surface_slope > 0 and m.microhardness > 0):
                    raise ScriptError(f"{scene.path}: materials.{name}: contact_conduction = \"lethe_rough\" needs "
                                      "its roughness, surface_slope and microhardness (> 0)")
        self.t_last = loop.t
        self.owned = {}
        self.every = dict(conduct=c.every)

    def after_chunk(self, due: dict) -> None:
        if due["conduct"]:
            self.conduct()

    def end_run(self) -> None:
        """The run's steps since the last update."""
        self.conduct()

    def at_run(self, walls) -> None:
        """At each of a script's runs: the walls at a temperature that conduct, with their
        geometry from the script (a box scene's generated one included); ScriptError for one the
        host cannot place."""
        info = self.loop.dem.info
        self.walls = []
        for w in walls:
            if not np.isfinite(w.temperature) or w.material < 0:
                continue
            wall = info.walls.get(w.fix)
            if wall is None or wall.primitive is None or any(v is None for v in wall.primitive[1] or (None,)):
                raise ScriptError(f"{self.loop.scene.path}: wall {w.fix!r} at {w.temperature:g} K: lasting "
                                  "conduction from walls needs a primitive wall with numbers (a mesh wall, or one "
                                  "placed by variables, is not placed by the host): give it no temperature")
            if self.gap is not None and self.gap.reach(1.0, self.gas) > 0:
                raise ScriptError(f"{self.loop.scene.path}: wall {w.fix!r} at {w.temperature:g} K: gap conduction "
                                  f"{self.gap.name!r} reaches beyond contact around the larger body, which a wall "
                                  "is: use gap_conduction = \"lethe\" with heated walls, or give the wall no temperature")
            self.walls.append((w, wall.primitive))

    def collided(self, cols: dict) -> None:
        """Collisions just logged (``CollisionHeat.conclude``): their pair contacts belong to
        their collision heat until begin + t_coll."""
        pair = cols["wall"] == 0
        if pair.any():
            ends = (cols["time"] + cols["t_coll"])[pair]
            self.owned.update(zip(contact_keys(cols["i"][pair], cols["j"][pair]).tolist(), ends.tolist()))

    def neighbours(self, atoms, reach: float):
        """Local indices (i, j) of the pairs whose surfaces are less than ``reach`` [m] apart
        (overlapping ones included), and their centre distances [m] (nearest periodic image)."""
        x = np.asarray(atoms.x, float)
        if len(x) < 2:
            return np.zeros(0, int), np.zeros(0, int), np.zeros(0)
        lo, hi, periodic = self.loop.dem.box()
        span = np.asarray(hi, float) - np.asarray(lo, float)
        cut = 2.0 * float(atoms.radius.max()) + reach
        if np.any(periodic):
            # the tree's torus wraps the periodic sides; the others get room enough not to wrap
            size = np.where(periodic, span, 3.0 * span + 2.0 * cut)
            y = np.where(periodic, np.mod(x - lo, span), x - lo + span + cut)
            found = self.tree(y, boxsize=size).query_pairs(cut, output_type="ndarray")
        else:
            found = self.tree(x).query_pairs(cut, output_type="ndarray")
        i, j = found[:, 0], found[:, 1]
        d = x[i] - x[j]
        d = np.where(periodic, d - span * np.round(d / span), d)
        dist = np.sqrt(np.sum(d * d, axis=1))
        near = dist < atoms.radius[i] + atoms.radius[j] + reach
        return i[near], j[near], dist[near]

    def network(self, atoms):
        """The conducting links of the particles ``atoms`` now: (i, j, H_contact, H_gap) of the
        particle pairs (local indices, conductances [W/K]) and (p, T_w, H_contact, H_gap) of the
        particles touching a wall at a temperature (T_w [K]); links with H = 0 left out."""
        loop = self.loop
        r_max = float(atoms.radius.max(initial=0.0))
        reach = self.gap.reach(r_max, self.gas) if self.gap is not None else 0.0
        i, j, dist = self.neighbours(atoms, reach)
        zero = np.zeros(0)
        pairs = (i, j, zero, zero)
        if len(i):
            mi, mj = loop.materials_of(atoms.type[i]), loop.materials_of(atoms.type[j])
            pair = Pair(atoms.radius[i], atoms.radius[j], dist, self.k[mi], self.k[mj], self.E_dem[mi, mj],
                        self.E_real[mi, mj], *self.surfaces(mi, mj))
            pairs = self._links((i, j), pair)
        p, T_w, Hc, Hg = [np.zeros(0, int)], [zero], [zero], [zero]
        if self.walls and len(atoms.id):
            mat = loop.materials_of(atoms.type)
            for w, primitive in self.walls:
                delta, _ = primitive_overlap(atoms.x, atoms.radius, primitive)
                at = np.flatnonzero(delta > 0)
                r = atoms.radius[at]
                R = WALL_RADIUS * r
                m = mat[at]
                pair = Pair(r, R, r + R - delta[at], self.k[m], self.k[w.material], self.E_dem[m, w.material],
                            self.E_real[m, w.material], *self.surfaces(m, w.material))
                at, hc, hg = self._links((at,), pair)
                p.append(at)
                T_w.append(np.full(len(at), w.temperature))
                Hc.append(hc)
                Hg.append(hg)
        return pairs, (np.concatenate(p), np.concatenate(T_w), np.concatenate(Hc), np.concatenate(Hg))

    def surfaces(self, mi, mj):
        """Equivalent roughness [m], slope [-] and effective microhardness [Pa] of the pairs of
        materials mi, mj, as Lethe combines them (``plugins.conduction.Pair``)."""
        Hi, Hj = self.hardness[mi], self.hardness[mj]
        with np.errstate(divide="ignore", invalid="ignore"):
            H = np.where(Hi + Hj > 0, 2.0 * Hi * Hj / (Hi + Hj), 0.0)
        return np.hypot(self.sigma[mi], self.sigma[mj]), np.hypot(self.slope[mi], self.slope[mj]), H

    def _links(self, index, pair):
        """(index arrays, H_contact, H_gap) [W/K] of the links of ``pair``, those with H = 0 dropped."""
        n = len(pair.distance)
        Hc = self.contact.conductance(pair) if self.contact is not None else np.zeros(n)
        Hg = self.gap.conductance(pair, self.gas) if self.gap is not None else np.zeros(n)
        on = (Hc + Hg) > 0
        return (*(a[on] for a in index), Hc[on], Hg[on])

    def conduct(self) -> None:
        """The heat of the interval since the last update moved between the pairs now within
        reach, and from the walls at a temperature (the module doc)."""
        loop = self.loop
        t0, t1 = self.t_last, loop.t
        self.t_last = t1
        if not t1 > t0:
            return
        atoms = loop.dem.atoms(True)
        loop.track_particles(atoms)
        (i, j, Hc, Hg), (p, T_w, Wc, Wg) = self.network(atoms)
        if len(i) or len(p):
            G_contact = Hc * self.contact_time(atoms.id[i], atoms.id[j], t0, t1) if len(i) else Hc
            G = np.r_[G_contact + Hg * (t1 - t0), (Wc + Wg) * (t1 - t0)]
            n = len(atoms.T)
            # the walls: nodes n, n+1, ... of infinite capacity at their temperature
            T = np.r_[atoms.T, T_w]
            C = np.r_[loop.C, np.full(len(p), np.inf)]
            a, b = np.r_[i, p].astype(int), np.r_[j, n + np.arange(len(p))].astype(int)
            q = exchange(T, C, a, b, G)
            atoms.T[:] += np.bincount(a, q, n + len(p))[:n] / loop.C - np.bincount(b, q, n + len(p))[:n] / loop.C
            qp, qw = q[:len(i)], q[len(i):]
            share = np.divide(G_contact, G[:len(i)], out=np.zeros(len(i)), where=G[:len(i)] > 0)
            self.loop.totals["heat_conducted_contact"] += float(np.abs(qp * share).sum())
            self.loop.totals["heat_conducted_gap"] += float(np.abs(qp * (1.0 - share)).sum())
            self.loop.totals["heat_conducted_wall"] += float(qw.sum())
            self.loop.totals["heat_from_walls"] += float(qw.sum())
            # the balance sees the temperatures as moved here: the next run's resync must not count
            # this interval's wall heat again as set by the script (the end of a run conducts after
            # the balance's last look)
            loop.track_particles(atoms)
        self.owned = {k: end for k, end in self.owned.items() if end > t1}

    def contact_time(self, ids_i, ids_j, t0: float, t1: float) -> np.ndarray:
        """Time [s] each pair's contact path conducts over [t0, t1]: all of it, less what its
        collision's heat stands for (the module doc)."""
        if not self.owned:
            return np.full(len(ids_i), t1 - t0)
        ends = np.array([self.owned.get(k, -np.inf) for k in contact_keys(ids_i, ids_j).tolist()])
        return np.maximum(0.0, t1 - np.maximum(t0, ends))

    def state(self) -> tuple[dict, dict]:
        return (dict(conduction_t=self.t_last),
                dict(conduction_owned_keys=np.array(list(self.owned), np.int64),
                     conduction_owned_ends=np.array(list(self.owned.values()), float)))

    def restore(self, state: dict) -> None:
        # (a checkpoint of a run without conduction: it starts at the restart)
        self.t_last = state.get("conduction_t", self.loop.t)
        self.owned = dict(zip(state.get("conduction_owned_keys", np.zeros(0, np.int64)).tolist(),
                              state.get("conduction_owned_ends", np.zeros(0)).tolist()))
