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
Walls do not conduct through this effect.
"""
from __future__ import annotations

import numpy as np

from plugins.conduction import CONTACT, GAP, Gas, Pair, exchange
from plugins.dem.hertz import effective_modulus
from pyhost.collisions import contact_keys
from pyhost.effects import Effect
from pyhost.engines.liggghts.script import ScriptError


class LastingConduction(Effect):
    """``owned``: contact key -> end [s] of its last collision's model time (contacts whose
    collision heat still stands for their time)."""

    TOTALS = dict(heat_conducted_contact=0.0, heat_conducted_gap=0.0)

    def __init__(self, loop):
        super().__init__(loop)
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
        self.t_last = loop.t
        self.owned = {}
        self.every = dict(conduct=c.every)

    def after_chunk(self, due: dict) -> None:
        if due["conduct"]:
            self.conduct()

    def end_run(self) -> None:
        """The run's steps since the last update."""
        self.conduct()

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

    def conduct(self) -> None:
        """The heat of the interval since the last update moved between the pairs now within
        reach (the module doc)."""
        loop = self.loop
        t0, t1 = self.t_last, loop.t
        self.t_last = t1
        if not t1 > t0:
            return
        atoms = loop.dem.atoms(True)
        loop.track_particles(atoms)
        r_max = float(atoms.radius.max(initial=0.0))
        reach = self.gap.reach(r_max, self.gas) if self.gap is not None else 0.0
        i, j, dist = self.neighbours(atoms, reach)
        if len(i):
            mi, mj = loop.materials_of(atoms.type[i]), loop.materials_of(atoms.type[j])
            pair = Pair(atoms.radius[i], atoms.radius[j], dist, self.k[mi], self.k[mj], self.E_dem[mi, mj],
                        self.E_real[mi, mj])
            G_contact = (self.contact.conductance(pair) * self.contact_time(atoms.id[i], atoms.id[j], t0, t1)
                         if self.contact is not None else np.zeros(len(i)))
            G_gap = self.gap.conductance(pair, self.gas) * (t1 - t0) if self.gap is not None else np.zeros(len(i))
            G = G_contact + G_gap
            on = G > 0
            i, j, G, G_contact = i[on], j[on], G[on], G_contact[on]
            C = loop.C
            q = exchange(atoms.T, C, i, j, G)
            n = len(atoms.T)
            atoms.T[:] += (np.bincount(i, q, n) - np.bincount(j, q, n)) / C
            share = G_contact / G
            self.loop.totals["heat_conducted_contact"] += float(np.abs(q * share).sum())
            self.loop.totals["heat_conducted_gap"] += float(np.abs(q * (1.0 - share)).sum())
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
