"""The coupling loop: the DEM advances, the host samples contacts, moves collision heat.

The DEM is any object with
    run(steps)                      advance the particles by whole DEM steps,
    state() -> (x, v)               positions [m] and velocities [m/s], (N, 3), in particle order,
    add_velocity(index, dv)         change the velocities of some particles [m/s],
    set_force(F)                    (fluid scenes) force on each particle [N] until changed,
and the fluid, when the scene has one, a started ``pyhost.openfoam.FluidSolver``;
the loop builds only what the scene asks for (``Scene.effects_summary``): no contact
sampling for an isothermal scene without restitution feedback, no heat arrays without a
heat model. Temperatures live in the host (``self.T``), which is the only place they change.
How a contact is classified (collision, then enduring) is told in ``pyhost.collisions``.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from pyhost.collisions import (WALL_BASE, ContactTracker, DemHertz, contact_keys, exchange_heat,
                               temperature_difference)
from pyhost.contact_heat import evaluate, restitution_impulse, side_heat
from pyhost.contacts import ContactFinder
from pyhost.dem_input import Particles, material_index
from pyhost.output import CsvLog, Progress, VtkSeries

COLLISION_COLUMNS = ("time", "i", "j", "wall", "v0", "Q", "e", "t_coll", "model")
FLUID_COLUMNS = ("u_inlet", "pressure_drop", "bed_height")


def layer_pressure_drop(fluid) -> float:
    """Mean pressure [Pa] of the fluid's lowest cell layer less that of its highest. Layers
    are matched with a tolerance: cell centres of one layer differ in their last digits."""
    p, _ = fluid.fields()
    z = fluid.cell_centres[:, 2]
    tol = 1e-6 * (z.max() - z.min())
    return float(p[z < z.min() + tol].mean() - p[z > z.max() - tol].mean())


class Coupling:
    """One run of a scene with a DEM engine; ``run()`` returns the summary it also writes."""

    def __init__(self, scene, dem, particles: Particles, out: Path, progress_every: float = 5.0, fluid=None):
        self.scene, self.dem, self.p, self.out = scene, dem, particles, Path(out)
        self.fluid = fluid              # a started pyhost.openfoam.FluidSolver, or None (dry)
        self.fluid_frames = VtkSeries(self.out / "vtk", "fluid") if fluid is not None and scene.output.vtk else None
        self.effects = scene.effects_summary()
        self.materials = list(scene.materials.values())
        self.wall_material = np.array([material_index(scene)[w.material] for w in scene.walls], int)
        self.T_wall = np.array([w.temperature if w.temperature > 0 and self.effects["wall_heat"] else np.nan
                                for w in scene.walls])
        self.T = particles.temperature.astype(float).copy()
        self.C = particles.mass * np.array([m.heat_capacity for m in self.materials])[particles.material]
        self.tracker = ContactTracker()
        d = scene.domain
        self.contacts = ContactFinder(particles.radius, d.box, d.periodic, [w.plane for w in scene.walls])
        self.open = {}                  # contact key -> (start time, model t_coll, e, v0)
        self.t, self.step = 0.0, 0
        self.totals = dict(collisions=0, wall_collisions=0, heat_moved=0.0, heat_from_walls=0.0,
                           capped=0, clipped=0, enduring_heat=0.0)
        self.CT0 = float(np.sum(self.C * self.T))
        self.collisions = CsvLog(self.out / "collisions.csv", COLLISION_COLUMNS
                                 + tuple(f"Q_{m}" for m in scene.effects.heat_models[1:]))
        self.groups = [np.flatnonzero(particles.group == k) for k in range(len(scene.particles))]
        self.history = CsvLog(self.out / "history.csv", ("time", "T_mean", "T_min", "T_max")
                              + tuple(f"T_group{k}" for k in range(len(self.groups)))
                              + ("sum_mcT", "heat_from_walls", "collisions", "capped", "clipped")
                              + (FLUID_COLUMNS if fluid is not None else ()))
        self.frames = VtkSeries(self.out / "vtk", "particles") if scene.output.vtk else None
        self.progress = Progress(scene.time.end, progress_every)

    def run(self) -> dict:
        tm = self.scene.time
        n_end = round(tm.end / tm.dem_step)
        sample = tm.sample_every if self.effects["contact_extraction"] else n_end
        frame = max(1, round(self.scene.output.every / tm.dem_step))
        couple = tm.couple_every if self.fluid is not None else n_end
        try:
            if self.fluid is not None:
                self.couple_fluid(couple * tm.dem_step)
            self.write_frame()
            while self.step < n_end:
                n = min(sample - self.step % sample, frame - self.step % frame, couple - self.step % couple,
                        n_end - self.step)
                self.dem.run(n)
                self.step += n
                self.t = self.step * tm.dem_step
                if self.effects["contact_extraction"] and self.step % sample == 0:
                    self.sample_contacts(sample * tm.dem_step)
                if self.fluid is not None and self.step % couple == 0 and self.step < n_end:
                    self.couple_fluid(couple * tm.dem_step)
                if self.step % frame == 0 or self.step == n_end:
                    self.write_frame()
                self.progress.update(self.t, f", {self.totals['collisions']} collisions")
        except BaseException as exc:          # keep what was computed: summary of the run so far
            self.finish(status=f"stopped at t = {self.t:g} s by {type(exc).__name__}: {exc}")
            raise
        return self.finish()

    def couple_fluid(self, duration: float) -> None:
        """The fluid's force on each particle from the current fluid, then the fluid advanced
        over the next coupling interval with these particles' fraction and drag."""
        x, v = self.dem.state()
        d = self.scene.domain
        lo, hi = np.array(d.box[0::2]), np.array(d.box[1::2])
        x = np.where(d.periodic, lo + np.mod(x - lo, hi - lo), x)   # the DEM wraps only at re-neighbouring
        self.dem.set_force(self.fluid.couple(x, v, 2.0 * self.p.radius, duration))

    def sample_contacts(self, dt_sample: float) -> None:
        self.dt_sample = dt_sample
        x, v = self.dem.state()
        c = self.contacts(x, v)
        keys = contact_keys(c.i, c.j)
        opened, closed = self.tracker.update(keys)
        if len(opened):
            self.start_collisions(c, keys, opened)
        if len(closed):
            self.end_collisions(closed, x, v)
        if self.effects["enduring_conduction"]:
            self.conduct_enduring(c, keys, dt_sample)

    def partner_arrays(self, i, j):
        """Whether each partner j is a wall, and its material index, radius [m], mass [kg]."""
        wall = j >= WALL_BASE
        jj = np.where(wall, 0, j)
        w = np.where(wall, j - WALL_BASE, 0)
        mat = np.where(wall, self.wall_material[w] if len(self.wall_material) else 0, self.p.material[jj])
        return wall, mat, np.where(wall, np.inf, self.p.radius[jj]), np.where(wall, np.inf, self.p.mass[jj])

    def dem_laws(self, mi, mj):
        """The DEM's contact law for each material pair (LIGGGHTS' effective modulus)."""
        laws = {}
        for a, b in set(zip(mi.tolist(), mj.tolist())):
            A, B = self.materials[a].dem, self.materials[b].dem
            Y = 1.0 / ((1 - A.poisson_ratio**2) / A.youngs_modulus + (1 - B.poisson_ratio**2) / B.youngs_modulus)
            laws[a, b] = DemHertz(Y, 0.5 * (A.restitution + B.restitution))
        return laws

    def start_collisions(self, c, keys, rows) -> None:
        i, j = c.i[rows], c.j[rows]
        wall, mj, R_j, m_j = self.partner_arrays(i, j)
        mi, R_i, m_i = self.p.material[i], self.p.radius[i], self.p.mass[i]
        R_eff = np.where(wall, R_i, R_i * R_j / np.where(wall, 1.0, R_i + R_j))
        m_eff = np.where(wall, m_i, m_i * m_j / np.where(wall, 1.0, m_i + m_j))
        v0 = np.empty(len(rows))
        for (a, b), law in self.dem_laws(mi, mj).items():
            s = (mi == a) & (mj == b)
            v0[s] = law.impact_speed(c.delta[rows][s], c.approach[rows][s], R_eff[s], m_eff[s],
                                     window=self.dt_sample)
        models = self.scene.effects.heat_models
        model = models[0] if models else "none"
        moved = e = t_coll = np.zeros(len(rows))
        side = {}
        if models:
            args = (self.scene.effects.heat_path, self.materials, mi, mj, R_i, R_j, v0, np.ones(len(rows)))
            G, e, t_coll = evaluate(model, *args)                               # Q per kelvin [J/K]
            if len(models) > 1:         # side columns: the same collisions at the same dT, nothing moved
                dT = temperature_difference(self.T, i, j, self.T_wall)
                side = {f"Q_{m}": g * dT for m, g in side_heat(models[1:], *args).items()}
            moved, capped, from_walls = exchange_heat(self.T, self.C, i, j, G, self.T_wall)
            self.totals["capped"] += capped
            self.totals["heat_from_walls"] += from_walls
            self.totals["heat_moved"] += float(np.abs(moved[~wall]).sum())
            by_model = self.heat_by_model()
            for m, q in zip(models, [moved] + list(side.values())):
                by_model[m] += float(np.abs(q[~wall]).sum())
        for k, key in enumerate(keys[rows]):
            self.open[int(key)] = (self.t, t_coll[k], e[k], v0[k])
        self.totals["collisions"] += len(rows)
        self.totals["wall_collisions"] += int(wall.sum())
        self.collisions.write_columns(time=np.full(len(rows), self.t), i=i + 1, j=np.where(wall, 0, j + 1),
                                      wall=np.where(wall, j - WALL_BASE + 1, 0), v0=v0, Q=moved, e=e,
                                      t_coll=t_coll, model=np.full(len(rows), model), **side)

    def heat_by_model(self) -> dict:
        """Heat between particles [J], sum of |Q| over collisions, of each heat model: the one
        that moved it and the side models on the same collisions."""
        return self.totals.setdefault("heat_by_model", dict.fromkeys(self.scene.effects.heat_models, 0.0))

    def end_collisions(self, closed, x, v) -> None:
        info = [self.open.pop(int(k)) for k in closed]
        if not self.scene.effects.restitution_feedback or self.scene.effects.contact_heat == "none":
            return
        i = (closed >> 31).astype(int)
        j = (closed & ((1 << 31) - 1)).astype(int)
        wall, _, _, m_j = self.partner_arrays(i, j)
        jj = np.where(wall, 0, j)
        normal = np.zeros((len(i), 3))
        for k in np.flatnonzero(wall):
            plane = self.scene.walls[j[k] - WALL_BASE].plane
            normal[k, "xyz".index(plane[0])] = 1.0 if plane.endswith("lo") else -1.0
        d = x[i] - x[jj]
        normal[~wall] = d[~wall] / np.linalg.norm(d[~wall], axis=1)[:, None]
        e = np.array([inf[2] for inf in info])
        v0 = np.array([inf[3] for inf in info])
        v_j = np.where(wall[:, None], 0.0, v[jj])
        dv_i, dv_j, clipped = restitution_impulse(v[i], v_j, self.p.mass[i], m_j, normal, e, v0)
        self.totals["clipped"] += clipped
        self.dem.add_velocity(i, dv_i)
        if (~wall).any():
            self.dem.add_velocity(j[~wall], dv_j[~wall])

    def conduct_enduring(self, c, keys, dt_sample) -> None:
        """Conduction through contacts older than their collision, h = 4 k_i k_j/(k_i + k_j) A^1/2
        (the enduring-contact law of LIGGGHTS' heat/gran) with A = pi R* delta, over the part
        of the sample interval that lies beyond the collision's own duration."""
        age = np.array([self.t - self.open[int(k)][0] - self.open[int(k)][1] for k in keys])
        rows = np.flatnonzero(age > 0)
        if not len(rows):
            return
        i, j = c.i[rows], c.j[rows]
        wall, mj, R_j, _ = self.partner_arrays(i, j)
        k_i = np.array([m.conductivity for m in self.materials])[self.p.material[i]]
        k_j = np.array([m.conductivity for m in self.materials])[mj]
        R_i = self.p.radius[i]
        R_eff = np.where(wall, R_i, R_i * R_j / np.where(wall, 1.0, R_i + R_j))
        h = 4 * k_i * k_j / (k_i + k_j) * np.sqrt(np.pi * R_eff * c.delta[rows])
        moved, capped, from_walls = exchange_heat(self.T, self.C, i, j, h * np.minimum(age[rows], dt_sample),
                                                  self.T_wall)
        self.totals["enduring_heat"] += float(np.abs(moved).sum())
        self.totals["heat_from_walls"] += from_walls
        self.totals["capped"] += capped

    def bed_state(self, x) -> tuple:
        """The fluid columns of history.csv: the superficial inlet velocity [m/s]; the pressure
        drop the particles cause [Pa], mean p of the lowest cell layer less that of the highest,
        less the fluid's own hydrostatic head between them; the bed height [m], twice the mean
        particle centre height above the box floor (exact for a uniform bed)."""
        z = self.fluid.cell_centres[:, 2]
        head = self.scene.fluid.density * self.scene.domain.gravity[2] * (z.max() - z.min())
        return (float(self.scene.fluid.inlet_at(self.t)), layer_pressure_drop(self.fluid) + head,
                2.0 * float(np.mean(x[:, 2] - self.scene.domain.box[4])))

    def write_frame(self) -> None:
        tot = self.totals
        x, v = self.dem.state() if self.frames is not None or self.fluid is not None else (None, None)
        group_means = tuple(float(np.sum(self.C[g] * self.T[g]) / np.sum(self.C[g])) for g in self.groups)
        self.history.write([(self.t, float(self.T.mean()), float(self.T.min()), float(self.T.max()))
                            + group_means + (float(np.sum(self.C * self.T)), tot["heat_from_walls"],
                                             tot["collisions"], tot["capped"], tot["clipped"])
                            + (self.bed_state(x) if self.fluid is not None else ())])
        if self.frames is not None:
            self.frames.write(self.t, x, id=np.arange(1, len(x) + 1), radius=self.p.radius, velocity=v,
                              temperature=self.T)
        if self.fluid_frames is not None:
            p, u = self.fluid.fields()
            self.fluid_frames.write(self.t, self.fluid.cell_centres, alpha=self.fluid.alpha, velocity=u, pressure=p)

    def finish(self, status: str = "completed") -> dict:
        self.progress.update(self.t, f", {self.totals['collisions']} collisions", force=True)
        CT = float(np.sum(self.C * self.T))
        self.heat_by_model()
        summary = dict(self.totals, status=status, time=self.t, steps=self.step, sum_mcT_start=self.CT0,
                       sum_mcT_end=CT,
                       energy_balance_error=(CT - self.CT0 - self.totals["heat_from_walls"]) / self.CT0)
        (self.out / "summary.json").write_text(json.dumps(summary, indent=1))
        self.collisions.close()
        self.history.close()
        return summary
