"""The fluid exchange: the fluid's force on each particle and the particles' fraction and drag
to the fluid every coupling interval; with ``[effects] convection``, the gas-particle heat
over the interval (particles' Temp at once, the opposite heat into the gas's cells). Its
history columns: the bed's state (inlet velocity, pressure drop, height) and the gas's
(temperature, heat content and what crossed). SI units."""
from __future__ import annotations

import math
import os

import numpy as np

from plugins import convection
from plugins.drag import fluid_fraction
from pyhost.effects import Effect, by_id
from pyhost.failures import drag_unresolved, left_the_mesh
from pyhost.output import VtkSeries

TOTAL_TOLERANCE = 1e-4
"""Largest |total_energy_balance_error| of a completed run with convection (relative to the
particles' and the gas's energy and what crossed the fluid's boundaries): the project's cases
give 1e-12 and below; CFDEM's packedBedTemp, whose fvSolution solves T to its own tolerance,
1.04e-7 (tools/corpus.py). A convected heat lost on one side shows as its share of that total
(packedBedTemp: 540 J convected of 5,400 J, 0.1)."""

ON_RANKS: bool | None = None
"""Where the particles' side of each exchange is done (``pyhost.engines.fluid_ranks``): None,
on each MPI rank under mpirun where the case allows it (``per_rank_grid``), else on rank 0
with every atom gathered; False, always gathered; True, where the case allows it, serially too
(a test's switch: the same numbers as the gather path then, bit for bit)."""

FLUID_COLUMNS = ("u_inlet", "pressure_drop", "bed_height")
GAS_COLUMNS = ("T_gas_mean", "gas_energy", "heat_convected", "heat_convected_gross", "heat_through_fluid_boundaries",
               "heat_moved")


def overlapping(setting: str, dem_ranks: int, fluid_ranks: int) -> bool:
    """Whether the fluid advances while the DEM runs its next chunk (``[fluid] overlap``).
    "auto": when the two fit on this process's cores side by side, a serial DEM and the
    fluid's ranks; not under mpirun, where the ranks are bound to cores and the fluid, started
    by rank 0, would share rank 0's. The results are the same either way: the advance uses the
    particles of the exchange before it, and the DEM's chunk the forces of that exchange."""
    if setting != "auto":
        return setting == "always"
    return dem_ranks == 1 and 1 + fluid_ranks <= len(os.sched_getaffinity(0))


def upwards(fluid) -> np.ndarray:
    """The unit vector against the case's gravity (+z where it has none)."""
    g = fluid.gravity()
    norm = float(np.linalg.norm(g))
    return -g / norm if norm > 0 else np.array([0.0, 0.0, 1.0])


def layer_pressure_drop(fluid, up) -> float:
    """Mean pressure [Pa] of the fluid's lowest cell layer along ``up`` less that of its
    highest. Layers are matched with a tolerance: cell centres of one layer differ in their
    last digits (NaN for a mesh one cell high)."""
    p, _ = fluid.fields()
    h = fluid.cell_centres @ up
    span = h.max() - h.min()
    if not span > 1e-9 * np.abs(h).max():     # one layer along up: heights apart in their last digits only
        return math.nan
    tol = 1e-6 * span
    return float(p[h < h.min() + tol].mean() - p[h > h.max() - tol].mean())


def per_rank_grid(loop, fluid):
    """The fluid mesh's grid (``fluid_ranks.BoxGrid``) when the exchange can be done on each
    rank (``ON_RANKS``): the host's own box case (a user's case is gathered), with its
    ``cell`` interpolation (controlDict's particleInterpolation), the ``centre`` void fraction
    and no convection (each of those needs the gathered particles); else None."""
    from foamlib import FoamFile

    from pyhost.engines.fluid_ranks import BoxGrid

    wanted = loop.dem.link is not None if ON_RANKS is None else ON_RANKS
    if not wanted or loop.scene.fluid.case or fluid.void_fraction != "centre" or loop.effects["convection"]:
        return None
    if FoamFile(fluid.case / "system" / "controlDict").get("particleInterpolation", "cell") != "cell":
        return None
    points = np.asarray(FoamFile(fluid.case / "constant" / "polyMesh" / "points")[None], float).reshape(-1, 3)
    return BoxGrid.of(points, fluid.cell_centres)


class FluidExchange(Effect):
    """``fluid``: the running solver (pyhost.engines.openfoam.FluidSolver, the context's
    ``fluid``); its interval: ``couple``, every time.couple_every DEM steps."""

    TOTALS = dict(heat_convected=0.0, heat_convected_gross=0.0)

    @classmethod
    def build(cls, ctx):
        return cls(ctx, ctx.fluid) if ctx.fluid is not None else None

    def __init__(self, loop, fluid):
        super().__init__(loop)
        self.fluid = fluid
        self.every = dict(couple=loop.scene.time.couple_every)
        self.convection = loop.effects["convection"]
        self.columns = FLUID_COLUMNS + (GAS_COLUMNS if self.convection else ())
        self.frames = (VtkSeries(loop.out / "vtk", "fluid", loop.logs.get("fluid"))
                       if loop.scene.output.vtk else None)
        self.force = (np.zeros(0, np.int64), np.zeros((0, 3)))   # ids and force [N] of the last coupling
        self.gas_energy0 = 0.0
        self.up = upwards(fluid)
        self.inlet = None               # a user's case: its inflow speed of the time (fluid_case.inlet_speed)
        if loop.scene.fluid.case:
            from pyhost.engines.fluid_case import inlet_speed, start_time
            self.inlet = inlet_speed(fluid.case, start_time(fluid.case)[1] or "0")
        link = loop.dem.link
        self.overlap = overlapping(loop.scene.fluid.overlap, 1 if link is None else link.size, loop.scene.fluid.ranks)
        self.grid = per_rank_grid(loop, fluid)     # not None: each rank does its particles' part

    def start(self) -> None:
        if self.loop.scene.fluid.case:
            self.check_box()
        T_gas = self.fluid.temperature() if self.convection else None
        self.couple()
        # the solver starts from the first fluid fraction it gets (no flow displaces the gas of
        # the particles as placed): the gas's initial heat content with that fraction
        self.gas_energy0 = float(np.sum(self.fluid.heat_capacity() * T_gas)) if self.convection else 0.0

    def check_box(self) -> None:
        """A user's case: the DEM's box against the extent of the fluid's mesh (its points), said
        once where the box reaches beyond it: a particle there has no gas, and the run stops
        when one goes there (``left_the_mesh``). A box inside the extent can still hold places
        the mesh has not (a hopper's funnel): those the run finds as particles go there."""
        from pyhost.engines.fluid_case import mesh_extent

        mesh = mesh_extent(self.fluid.case)
        if mesh is None:
            return
        lo, hi, periodic = self.loop.dem.box()
        tol = 1e-6 * float(np.max(mesh[1] - mesh[0]))
        beyond = [f"{'xyz'[a]} {side} by {gap:.4g} m" for a in range(3) for side, gap in
                  (("lo", mesh[0][a] - lo[a]), ("hi", hi[a] - mesh[1][a])) if gap > tol]
        if beyond:
            print(f"warning: the DEM's box [{', '.join(f'{v:.4g}' for v in lo)}] .. [{', '.join(f'{v:.4g}' for v in hi)}] m "
                  f"reaches beyond the fluid's mesh ({'; '.join(beyond)}): a particle there has no gas, and the run "
                  "stops when one goes there (exit 3)")

    def couple(self) -> None:
        """The fluid's force on each particle from the current fluid, then the fluid advanced
        over the next coupling interval with these particles' fraction and drag (with
        ``overlap``, while the DEM runs that interval: the next use of the fluid waits for it)."""
        if self.grid is not None:
            return self.couple_on_ranks()
        from pyhost.engines.openfoam import OutsideMesh  # (loaded with the solver; every run imports this module's TOTALS)

        loop = self.loop
        atoms = loop.dem.atoms(temperature=self.convection)
        lo, hi, periodic = loop.dem.box()
        x = np.where(periodic, lo + np.mod(atoms.x - lo, hi - lo), atoms.x)   # the DEM wraps only at re-neighbouring
        interval = loop.every["couple"] * loop.dem.dt
        try:
            forces = self.fluid.particle_forces(x, atoms.v, 2.0 * atoms.radius)
        except OutsideMesh as exc:          # a failed simulation (exit 3), not bad input
            raise left_the_mesh(atoms.id[exc.index], x[exc.index], atoms.v[exc.index], loop.t) from None
        failure = drag_unresolved(atoms.id, self.fluid.exchange, atoms.mass, 2.0 * atoms.radius, interval,
                                  loop.dem.dt, loop.t)
        if failure is not None:
            raise failure
        self.fluid.advance(interval, self.fluid.substeps(interval),
                           heat=self.convect(atoms, interval) if self.convection else None, wait=not self.overlap)
        loop.dem.set_force(forces)
        self.force = (atoms.id.copy(), forces)

    def couple_on_ranks(self) -> None:
        """``couple`` with each rank's particles on their rank (``pyhost.engines.fluid_ranks``):
        rank 0 sends every rank the fluid of each cell and gets back each cell's sums over the
        particles, O(cells); a particle outside the mesh or with its drag unresolved fails the
        run as in ``couple``, named as there."""
        from pyhost.engines.dem import FLUID_FIX
        from pyhost.engines.fluid_ranks import Job, exchange_on_rank

        loop, fluid, grid = self.loop, self.fluid, self.grid
        lo, hi, periodic = loop.dem.box()
        interval = loop.every["couple"] * loop.dem.dt
        u, gradp = fluid.cell_fluid()
        job = Job(grid.faces, grid.to_grid(u), grid.to_grid(gradp), grid.to_grid(fluid.cell_volumes), lo, hi,
                  periodic, fluid.rho, fluid.nu, fluid.drag, fluid.alpha_min, interval, FLUID_FIX)
        parts = loop.dem.each_rank(exchange_on_rank, job)
        if any("outside" in p for p in parts):      # a failed simulation (exit 3), not bad input
            ids, x, v = (np.concatenate([p["outside"][k] for p in parts]) for k in range(3))
            raise left_the_mesh(ids, x, v, loop.t)
        if any(len(p["unresolved"][0]) for p in parts):     # (their forces are set: the run stops here)
            ids, k, mass, d = (np.concatenate([p["unresolved"][c] for p in parts]) for c in range(4))
            raise drag_unresolved(ids, k, mass, d, interval, loop.dem.dt, loop.t)
        sums = parts[0]
        fluid.take_particles(fluid_fraction(grid.to_solver(sums["solid"]), fluid.cell_volumes, fluid.alpha_min),
                             grid.to_solver(sums["ksum"]), grid.to_solver(sums["kv"]))
        fluid.advance(interval, fluid.substeps(interval), wait=not self.overlap)
        self.force = None               # on the ranks: gathered only for a checkpoint (``state``)

    def convect(self, atoms, interval: float) -> np.ndarray:
        """Gas-particle heat over the coming interval [s] (plugins.convection): each particle's
        Temp takes its share now; returns the heat rate of each cell's gas [W], the opposite,
        for the fluid's advance over the interval."""
        loop, f, name = self.loop, self.fluid, self.loop.scene.effects.convection
        loop.track_particles(atoms)
        d = 2.0 * atoms.radius
        alpha = f.alpha[f.cell]
        re = convection.particle_reynolds(alpha, f.slip, d, f.nu)
        pr = convection.prandtl(f.nu, f.rho, f.cp, f.kappa)
        for key, share in convection.outside(name, re, pr, alpha).items():
            if key not in loop.warned:
                loop.warned.add(key)
                lo, hi = convection.CORRELATIONS.lookup(name).validity[key]
                print(f"warning: convection '{name}' extrapolated: {share:.1%} of the particles have {key} outside "
                      f"[{lo:g}, {hi:g}] at t = {loop.t:g} s")
        G = convection.conductance(name, re, pr, alpha, f.kappa, d)
        q, _ = convection.exchange(atoms.T, loop.C, G, f.cell, f.temperature(), f.heat_capacity(), interval)
        atoms.T[:] += q / loop.C
        loop.totals["heat_convected"] += float(q.sum())
        loop.totals["heat_convected_gross"] += float(np.abs(q).sum())
        loop.track_particles(atoms)
        return -np.bincount(f.cell, q, len(f.cell_volumes)) / interval

    def row(self, atoms) -> tuple:
        return self.bed_state(atoms) + (self.gas_state() if self.convection else ())

    def bed_state(self, atoms) -> tuple:
        """The fluid columns of history.csv, heights taken against gravity (``upwards``): the
        superficial inlet velocity [m/s] (a user's case: the mean speed of the gas coming in
        through its fixed-inflow patches, ``fluid_case.inlet_speed``; NaN for a closed case or
        an inlet condition it does not read); the pressure drop the particles cause [Pa], mean
        p of the lowest cell layer less that of the highest, less the fluid's own hydrostatic
        head between them; the bed height [m], twice the mean particle centre height above the
        box's lowest face (exact for a uniform bed)."""
        loop = self.loop
        up = self.up
        h = self.fluid.cell_centres @ up
        head = self.fluid.rho * float(self.fluid.gravity() @ up) * (h.max() - h.min())
        lo, hi, _ = loop.dem.box()
        floor = float(np.sum(np.minimum(lo * up, hi * up)))
        if loop.scene.fluid.case:
            inlet = self.inlet(loop.t) if self.inlet is not None else math.nan
        else:
            inlet = float(loop.scene.fluid.inlet_at(loop.t))
        height = 2.0 * float(np.mean(atoms.x @ up - floor)) if len(atoms.x) else math.nan
        return inlet, layer_pressure_drop(self.fluid, up) + head, height

    def gas_state(self) -> tuple:
        """The gas columns of history.csv: the heat-capacity weighted mean gas temperature [K],
        the gas's heat content rho c alpha V T summed over cells [J]; since the start [J]: the
        heat convected into the particles (net, and the sum of its magnitudes), the heat into
        the gas through the fluid's boundaries, and beside them the heat moved by collisions
        between particles (sum of magnitudes)."""
        C = self.fluid.heat_capacity()
        E = float(np.sum(C * self.fluid.temperature()))
        t = self.loop.totals
        return (E / C.sum(), E, t["heat_convected"], t["heat_convected_gross"], self.fluid.boundary_heat,
                t["heat_moved"])

    def frame(self) -> None:
        if self.frames is not None:
            p, u = self.fluid.fields()
            self.frames.write(self.loop.t, self.fluid.cell_centres, alpha=self.fluid.alpha, velocity=u, pressure=p)

    def join(self) -> None:
        """The last advance, if it ran beside the DEM: a failure in it stops this run like any
        other (summary, exit 3)."""
        self.fluid.wait()

    def flush(self) -> None:
        self.fluid.wait()
        if self.frames is not None:
            self.frames.flush()

    def state(self) -> tuple[dict, dict]:
        if self.force is None:          # the exchange on the ranks: their forces now, as set there
            from pyhost.engines.dem import FLUID_FIX
            from pyhost.engines.fluid_ranks import force_on_rank
            parts = self.loop.dem.each_rank(force_on_rank, FLUID_FIX)
            self.force = tuple(np.concatenate([p[k] for p in parts]) for k in range(2))
        return (dict(gas_energy0=self.gas_energy0, logs=dict(fluid=self.frames.frames if self.frames else None)),
                dict(fluid_ids=self.force[0], fluid_force=self.force[1]))

    def restore(self, state: dict) -> None:
        """The fluid force of the last coupling, until the next."""
        self.gas_energy0 = state.get("gas_energy0", 0.0)
        ids, force = state["fluid_ids"], state["fluid_force"]
        self.loop.dem.set_force(by_id(ids, force, self.loop.dem.atoms(False).id))
        self.force = (ids, force)

    def finish(self, summary: dict, status: str) -> None:
        """With convection, the energy balance of particles and gas together (the gas gains
        through its boundaries); the particles' own is the balance effect's."""
        balance = self.loop.find("balance")
        if not (self.convection and status == "completed" and balance is not None and balance.residual is not None):
            return
        t = self.loop.totals
        _, gas, _, _, through, _ = self.gas_state()
        residual = balance.residual + (t["heat_convected"] + gas - self.gas_energy0 - through)
        error = residual / max(balance.came_in + self.gas_energy0 + abs(through), 1e-300)
        summary.update(gas_energy_start=self.gas_energy0, gas_energy_end=gas, heat_through_fluid_boundaries=through,
                       total_energy_balance_error=error)
        if not abs(error) <= TOTAL_TOLERANCE and not balance.failure:
            self.failure = (f"energy balance of particles and gas broken: {residual:.6g} J off ({error:.3g} of the "
                            f"energy of both and what crossed the fluid's boundaries, allowed {TOTAL_TOLERANCE:g}): "
                            "heat went between the phases without being counted on both sides, or the gas energy "
                            "equation was not solved to its tolerance (the case's fvSolution, T); the terms are in "
                            "summary.json")
            summary["status"] = f"failed at the end: {self.failure}"
