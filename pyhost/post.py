"""Collision heat of a finished LIGGGHTS run, from its dump files (``python -m pyhost post``).

1. The particle dumps are read once (``pyhost.dumps``): each particle's type and radius by id,
   its initial temperature (the scene's, else the dump's ``f_Temp`` at its first appearance),
   and, without contact dumps, the contacts of every frame from positions (periodic images
   from the box, the scene's box faces and the script's primitive walls, ``pyhost.walls``).
2. With contact dumps (``compute pair/gran/local`` / ``wall/gran/local``), a pair's first
   appearance is its collision; a particle touching several triangles of one mesh at once is
   one collision. Its normal impact speed is the approach speed at first appearance, carried
   back to touch with the DEM's own contact law (``DemHertz.impact_speed``) over the overlap.
3. Each model gives every collision's heat per kelvin, e and t_coll (``plugins.heat.batch.evaluate``);
   the heat is moved collision by collision, in time order, with the temperatures of that
   moment (``plugins.heat.exchange.exchange_heat``), while the particle dumps are replayed into a VTK
   series of temperatures and heat received. A script's ``set ... property/atom Temp`` between
   frames changes every model's temperatures by what the dumped temperature changed across it.

Output (``out``): collisions.csv.gz, summary.json, vtk/particles.pvd, post.png. A failure
keeps what was written before it, and summary.json then says ``"complete": false``, as it
does when frames were skipped (``skipped``: how many warnings say so).
"""
from __future__ import annotations

import csv
import gzip
import json
from pathlib import Path

import numpy as np

from plugins.heat import MODELS
from plugins.heat.exchange import exchange_heat
from pyhost.collisions import (Bodies, FirstAppearances, Found, carried_back, conductances, contact_keys, log_wall,
                               material_of, shortest_collision, sphere_mass, wall_code, wall_of)
from pyhost.contacts import find_contacts
from pyhost.dumps import Clock, DumpError, DumpReader
from pyhost.engines.liggghts.dump_contacts import ContactDumps
from pyhost.engines.liggghts.dump_script import script_dem_contacts_of
from pyhost.engines.liggghts.names import BOX, CONDUCTION, CONDUCTION_FIX, TEMPERATURE, WALL_CONTACTS
from pyhost.outdir import run_output, write_atomic
from pyhost.output import Progress, VtkSeries, naming
from pyhost.scene import PostScene

TEMPERATURES = ("own", "dumps")
"""How post's particle temperatures evolve: ``own``, from each particle's first temperature by
the models' collision heat (and the script's Temp sets); ``dumps``, taken from the dumps at every
frame (the run's own conduction and sources), the collisions until the next frame moving heat
from there: what the models' collisions would move in the run's own temperature field."""


class Particles:
    """Per-id arrays (index = LIGGGHTS id), grown as ids appear: type (0 unseen), radius [m],
    initial temperature [K] (NaN until known)."""

    def __init__(self):
        self.type, self.radius, self.T0 = np.zeros(0, int), np.zeros(0), np.zeros(0)

    def add(self, ids, types, radius, temperature=None) -> None:
        n = int(ids.max()) + 1 if len(ids) else 0
        if n > len(self.type):
            grow = n - len(self.type)
            self.type = np.concatenate([self.type, np.zeros(grow, int)])
            self.radius = np.concatenate([self.radius, np.full(grow, np.nan)])
            self.T0 = np.concatenate([self.T0, np.full(grow, np.nan)])
        self.type[ids], self.radius[ids] = types, radius
        if temperature is not None:
            self.T0[ids] = np.where(np.isnan(self.T0[ids]), temperature, self.T0[ids])


ATOMS_REQUIRED = ("id", "type", "position", "velocity", "radius")


class Post(ContactDumps):
    """One post-processing job; ``run()`` writes the output folder and returns the summary.
    ``heat_path``: the plugin's evaluation path (``fast`` or ``exact``, as a run's
    effects.heat_path)."""

    def __init__(self, dumps, scene: PostScene, out, contacts=(), script=None, computes=None, models=tuple(MODELS),
                 dt=None, skip_bad_frames=False, temperatures="own", progress_every=5.0, heat_path="fast"):
        if temperatures not in TEMPERATURES:
            raise ValueError(f"temperatures: {temperatures!r} is not one of {', '.join(TEMPERATURES)}")
        self.heat_path = heat_path
        self.temperatures = temperatures
        self.progress_every = progress_every    # wall seconds between progress lines [s]
        self.dumps, self.scene, self.out = list(dumps), scene, Path(out)
        self.contacts, self.script = list(contacts), script
        self.computes = dict(script.computes if script else {}) | dict(computes or {})
        self.models, self.skip = tuple(models), skip_bad_frames
        # the time of each step: the script's runs through their time step changes and resets, or one dt
        self.clock = script.clock if dt is None and script and script.clock else None
        if self.clock is None:
            dt = dt if dt is not None else (script.timestep if script else None)
            if dt is None:
                raise ValueError("the time step is unknown: give --dt, or --script with the script's 'timestep'")
            self.clock = Clock.steady(dt)
        self.warnings = list(script.warnings) if script else []
        if script and script.heat_gran and temperatures == "own":
            self.warnings.append(f"the script conducts heat with {CONDUCTION_FIX} ({', '.join(script.heat_gran)}): post's "
                                 "temperatures change by its models' collision heat and the script's Temp sets only, "
                                 f"not by {CONDUCTION}'s conduction through lasting contacts or its heat sources "
                                 "(--temperatures dumps takes the dumped temperatures at every frame)")
        self.materials = self.dem_contacts(scene, script)
        if script:
            unnamed = (set(script.wall_types) | set(script.primitives) | set(script.mesh_wall_fixes)) \
                - {w.fix for w in scene.walls if w.fix}
            if unnamed:
                self.warnings.append(f"the script's walls {', '.join(sorted(unnamed))} have no [[walls]] entry in "
                                     f"{scene.path}: their collisions are not counted")
        self.series = None               # the VTK series of the particles, once written
        self.particles = Particles()
        # the walls by number (pyhost.collisions.wall_code): each one's [[walls]] entry, one per wall and mesh
        self.wall_entry, self.wall_numbers = [], {}
        self.frame_steps = set()        # the steps of the particle frames
        self.same_run = {}              # step -> a contact frame to check against the particle frame of that step
        self.summary = dict(frames=0, particles=0, collisions=dict(particle_particle=0, particle_wall=0),
                            contacts_open_at_start=0, heat_J={m: 0.0 for m in self.models}, warnings=self.warnings,
                            complete=False, temperatures=temperatures)
        self.stop_step = None            # the last good step before a failure: nothing after it is used
        self.error, self.done = None, False

    @staticmethod
    def dem_contacts(scene: PostScene, script) -> list:
        """The scene's materials, each with the DEM contact the script sets for its atom types
        (checked against a given dem table), or its table where there is no script."""
        return list(scene.materials.values()) if script is None else script_dem_contacts_of(scene, script)

    def wall_codes(self, entry: int, meshes) -> np.ndarray:
        """The partner codes of the meshes ``meshes`` (0 for a plane or primitive wall) of the
        [[walls]] entry ``entry``: an entry's meshes numbered in their order, up to the largest
        seen, as a run numbers a wall fix's (post reads one mesh wall fix's contacts)."""
        meshes = np.asarray(meshes, np.int64)
        for m in range(int(meshes.max(initial=-1)) + 1):
            if (entry, m) not in self.wall_numbers:
                self.wall_numbers[entry, m] = len(self.wall_entry)
                self.wall_entry.append(entry)
        return wall_code(np.array([self.wall_numbers[entry, m] for m in meshes.tolist()], np.int64))

    # -- reading ----------------------------------------------------------------------------
    def reader(self, paths, **kw):
        r = DumpReader(paths, clock=self.clock, skip_bad_frames=self.skip, **kw)
        self.warnings.extend(r.warnings)
        return r

    def frames(self, reader):
        """Frames up to a failure; the failure is recorded, not raised, so what came before is kept."""
        seen, last = len(reader.warnings), -1
        try:
            for f in reader:
                if self.stop_step is not None and f.step > self.stop_step:
                    return
                last = f.step
                yield f
        except DumpError as exc:
            self.error = exc if self.error is None else self.error
            self.stop_step = last if self.stop_step is None else min(last, self.stop_step)
        finally:
            self.warnings.extend(reader.warnings[seen:])

    def survey(self) -> Found:
        """Pass over the particle dumps: particle table, frames, intervals; contacts from
        positions when there are no contact dumps."""
        found, first = Found(), FirstAppearances()
        walls = [(k, w.plane) for k, w in enumerate(self.scene.walls) if w.plane]  # box faces, primitive walls
        if not self.contacts:
            for k in range(len(self.scene.walls)):      # numbered as the entries (one mesh each)
                self.wall_codes(k, [0])
            primitives = self.script.primitives if self.script else {}
            for k, w in enumerate(self.scene.walls):
                if w.fix in primitives:
                    walls.append((k, primitives[w.fix]))
                elif w.fix:
                    self.warnings.append(f"wall fix {w.fix}: its contacts need --contacts dumps ({WALL_CONTACTS}), "
                                         "or --script when it is a primitive wall; without them it is ignored")
        steps, last = [], None
        progress = Progress(float("inf"), self.progress_every)
        for f in self.frames(self.reader(self.dumps, require=ATOMS_REQUIRED)):
            progress.update(f.time, f"; reading the dumps: frame {len(steps) + 1}, {found.count()} collisions "
                                    "found")
            ids, types = f["id"].astype(np.int64), f["type"].astype(int)
            unknown = sorted(set(types.tolist()) - set(self.scene.types))
            if unknown:
                raise ValueError(f"{f.file}: timestep {f.timestep}: atom type {unknown[0]} is in no material of "
                                 f"{self.scene.path} (materials.NAME.types)")
            column = self.temperature_column(f)
            self.particles.add(ids, types, f["radius"], f[column] if column else None)
            steps.append(f.step)
            last = f
            if not self.contacts:
                self.position_contacts(f, ids, walls, found, first, steps)
        self.summary["frames"] = len(steps)
        self.frame_steps = set(steps)
        self.summary["particles"] = len(last) if last is not None else 0
        # the shortest interval between two frames ([s], steps): what collisions it can miss
        self.interval = (min(zip(np.diff(self.clock.time(steps)), np.diff(steps))) if len(steps) > 1 else None)
        return found

    def frame_box(self, f):
        """The frame's box (3, 2) [m]; a VTK dump has none: the script's (``--script``)."""
        return f.box if f.box is not None else (self.script.box if self.script else None)

    def position_contacts(self, f, ids, walls, found, first, steps) -> None:
        if not len(f):
            first.new(np.empty(0, np.int64))
            return
        box = self.frame_box(f)
        if any(isinstance(w, str) for _, w in walls) and box is None:
            raise ValueError(f"{f.file}: a VTK dump has no box, so walls on its faces cannot be placed: give --script "
                             f"(its {BOX}), or use text dumps")
        x = f.positions()
        box = box if box is not None else np.stack([x.min(0) - 1.0, x.max(0) + 1.0], axis=1)
        c = find_contacts(x, f.vector("v"), f["radius"], box.ravel(), f.periodic, [p for _, p in walls])
        wall, w = wall_of(c.j)
        j = ids[np.where(wall, 0, c.j)]
        j[wall] = np.array([self.wall_codes(k, [0])[0] for k, _ in walls], np.int64)[w[wall]]
        keys = contact_keys(ids[c.i], j)
        new = first.new(keys)
        if len(steps) == 1:
            self.open_at_start(f, len(keys))
            return
        window = self.clock.time(steps[-1]) - self.clock.time(steps[-2])
        found.add(step=f.step, i=ids[c.i][new], j=j[new], delta=c.delta[new], approach=c.approach[new], window=window)

    def open_at_start(self, f, n: int) -> None:
        """The contacts of a stream's first frame began before the record does: their impact is
        not in it (a resting bed's contacts, integrated back, would each get an impact speed
        from their static overlap), so they are not collisions, as a run's contacts at a
        restart are not. Counted in summary.json's ``contacts_open_at_start``."""
        self.summary["contacts_open_at_start"] += n
        if n:
            self.warnings.append(f"{n} contacts are open in the first frame of {Path(f.file).name} (timestep "
                                 f"{f.step}): they began before the dumps do, so they are not counted as collisions")

    # -- physics from the plugin ---------------------------------------------------------------
    def partners(self, i, j):
        """The bodies (``pyhost.collisions.Bodies``) and both partners of collisions of
        particles ``i`` with partners ``j`` (ids or wall codes)."""
        names = list(self.scene.materials)
        type_material = np.full(max(self.scene.types) + 1, -1)
        type_material[list(self.scene.types)] = list(self.scene.types.values())
        bodies = Bodies(self.materials, type_material,
                        np.array([names.index(self.scene.walls[k].material) for k in self.wall_entry], int))
        jj = np.where(wall_of(j)[0], 0, j)
        t, R = self.particles.type, self.particles.radius
        return bodies, bodies.partners(j, material_of(type_material, t[i]), R[i], material_of(type_material, t[jj]),
                                       R[jj])

    def impact_speeds(self, c) -> np.ndarray:
        """Each collision's impact speed [m/s], its approach speed carried back to touch."""
        bodies, p = self.partners(c["i"], c["j"])
        names = list(self.scene.materials)
        v0 = carried_back(bodies, p, c["approach"], c["delta"], c["window"], names, self.scene.path)
        if len(v0) and self.interval is not None:
            self.shortest_collision(*shortest_collision(bodies, p, v0, names, self.scene.path))
        return v0

    def shortest_collision(self, t_c: float, v: float) -> None:
        """The DEM's shortest collision time t_c [s] among the collisions found (at the fastest
        impact v [m/s]) against the dump interval."""
        interval, steps = self.interval
        self.summary.update(dump_interval_s=interval, shortest_collision_s=t_c)
        if interval > t_c:
            self.warnings.append(
                f"the dump interval {interval:.3g} s ({steps} steps) exceeds the shortest DEM collision "
                f"time {t_c:.3g} s (Hertz, at {v:.3g} m/s): collisions shorter than the interval are missed "
                "and impact speeds are carried back over up to the whole interval")

    # -- the job ------------------------------------------------------------------------------------
    def run(self) -> dict:
        found = run_output(self.out)
        if found is not None:
            raise ValueError(f"--out {self.out}: holds the output of a run ({found}), whose summary.json post "
                             "would replace: give post a folder of its own")
        self.out.mkdir(parents=True, exist_ok=True)
        try:
            found = self.survey()
            if self.contacts:
                self.dump_contacts(found)
            c = found.array()
            c["v0"] = self.impact_speeds(c)
            self.heat(c)
        finally:
            if self.series is not None:
                self.series.flush()
            self.write_summary()
        if self.error is not None:
            raise self.error
        return self.summary

    def write_summary(self) -> None:
        self.summary["warnings"] = list(dict.fromkeys(self.warnings))    # the particle dumps are read twice
        self.summary["skipped"] = sum(w.startswith("skipped") for w in self.summary["warnings"])
        self.summary["complete"] = self.error is None and self.done and not self.summary["skipped"]
        if self.error is not None:
            self.summary["error"] = str(self.error)
        write_atomic(self.out / "summary.json", json.dumps(self.summary, indent=1, default=float))

    def heat(self, c) -> None:
        """Models over all collisions, heat moved in time order while the particle frames are
        replayed into the VTK series; collisions.csv.gz written batch by batch."""
        n = len(c["i"])
        bodies, p = self.partners(c["i"], c["j"])
        wall, mats = p.wall, self.materials
        go = c["v0"] > 0                     # contacts that formed without approach move no collision heat
        if (~go).any():
            self.warnings.append(f"{int((~go).sum())} contacts formed with no approach speed: no collision heat")
        G, e, t_coll = {}, {}, {}
        self.summary["outside_model_range"] = {}
        for model in self.models:
            G[model], e[model], t_coll[model] = np.zeros(n), np.full(n, np.nan), np.full(n, np.nan)
            flagged = np.zeros(0, bool)
            if go.any():
                g, ee, tt, flagged = conductances(model, self.heat_path, bodies, p[go], c["v0"][go])
                G[model][go], e[model][go], t_coll[model][go] = g, ee, tt
            self.summary["outside_model_range"][model] = int(flagged.sum())
            if flagged.any():
                self.warnings.append(f"model {model}: {int(flagged.sum())} collisions outside the contact models' range "
                                     f"(indentation beyond the smaller radius, or an overflow; fastest "
                                     f"{float(c['v0'][go][flagged].max()):.4g} m/s): their heat is the models' "
                                     "extrapolation")
        C = np.full(len(self.particles.type), np.nan)
        known = self.particles.type > 0
        heat_capacity = np.array([m.heat_capacity for m in mats])
        density = np.array([m.density for m in mats])
        mat = material_of(bodies.type_material, self.particles.type[known])
        C[known] = sphere_mass(self.particles.radius[known], density[mat]) * heat_capacity[mat]
        T0 = self.initial_temperatures(known, mat)
        T = {m: T0.copy() for m in self.models}
        received = {m: np.zeros(len(T0)) for m in self.models}
        T_wall = np.array([self.scene.walls[k].temperature if self.scene.walls[k].temperature > 0 else np.nan
                           for k in self.wall_entry] or [np.nan])
        counted = dict(particle_particle=int((~wall).sum()), particle_wall=int(wall.sum()))
        self.summary["collisions"] = counted
        self.summary["capped"] = {m: 0 for m in self.models}
        Q = {m: np.zeros(n) for m in self.models}
        columns = (("time", "i", "j", "type_i", "type_j", "wall", "v0")
                   + tuple(f"{k}_{m}" for m in self.models for k in ("Q", "e", "t_coll")))
        series = self.series = VtkSeries(self.out / "vtk", "particles")
        type_i = self.particles.type[c["i"]]
        type_j = np.where(wall, 0, self.particles.type[np.where(wall, 0, c["j"])])
        by_pair = np.stack([type_i, type_j], axis=1)
        by_pair[~wall] = np.sort(by_pair[~wall], axis=1)       # 1-2 and 2-1 are one pair of types
        pairs, pair_of = np.unique(by_pair, axis=0, return_inverse=True)
        pairs, pair_of = [tuple(p) for p in pairs.tolist()], pair_of.ravel()
        pair_sum = np.zeros(len(pairs))              # |Q| of the first model per type pair [J]
        times, pair_heat, last = [], [], None
        done = 0
        with naming(self.out / "collisions.csv.gz"), gzip.open(self.out / "collisions.csv.gz", "wt", newline="") as gz:
            out = csv.writer(gz)
            out.writerow(columns)

            def upto(step):
                nonlocal done
                end = int(np.searchsorted(c["step"], step, side="right"))
                s = slice(done, end)
                if end == done:
                    return
                for m in self.models:
                    moved, capped, _ = exchange_heat(T[m], C, c["i"][s], c["j"][s], G[m][s], T_wall)
                    Q[m][s] = moved
                    np.add.at(received[m], c["i"][s], -moved)
                    pp = ~wall[s]
                    np.add.at(received[m], c["j"][s][pp], moved[pp])
                    self.summary["capped"][m] += capped
                    self.summary["heat_J"][m] += float(np.abs(moved).sum())
                np.add.at(pair_sum, pair_of[s], np.abs(Q[self.models[0]][s]))
                cols = [self.clock.time(c["step"][s]), c["i"][s], np.where(wall[s], 0, c["j"][s]), type_i[s], type_j[s],
                        log_wall(c["j"][s], self.wall_entry), c["v0"][s]]
                for m in self.models:
                    cols += [Q[m][s], e[m][s], t_coll[m][s]]
                out.writerows(zip(*(np.asarray(a).tolist() for a in cols)))
                gz.flush()
                done = end

            told = self.script.temperature_sets if self.script and self.temperatures == "own" else ()
            sets = sorted(s for s in told if s[0] is not None)
            unplaced, before = [s for s in told if s[0] is None], None
            progress = Progress(float("inf"), self.progress_every)
            for f in self.frames(self.reader(self.dumps, require=ATOMS_REQUIRED)):
                progress.update(f.time, f"; replaying the dumps: heat of {done} of {n} collisions moved")
                between = []
                while sets and sets[0][0] < f.step:
                    between.append(sets.pop(0))
                if between and before is not None:  # (before the first frame: in the first appearances' temperatures)
                    upto(between[0][0])         # what collided before the script's sets, then the sets
                    self.follow_sets(between, before, f, T)
                upto(f.step)
                column = self.temperature_column(f)
                before = (f.step, f["id"].astype(np.int64), f[column] if column else None)
                ids = f["id"].astype(np.int64)
                if self.temperatures == "dumps":      # the run's own temperatures from here to the next frame
                    if column is None:
                        raise DumpError(f.file, f.timestep, f.line, "--temperatures dumps: the frame has no particle "
                                                                f"temperature ({TEMPERATURE})")
                    for m in self.models:
                        T[m][ids] = f[column]
                fields = dict(id=ids, type=f["type"].astype(int), radius=f["radius"], velocity=f.vector("v"))
                for m in self.models:
                    fields[f"T_{m}"], fields[f"dT_{m}"] = T[m][ids], T[m][ids] - T0[ids]
                    fields[f"heat_{m}"] = received[m][ids]
                series.write(f.time, f.positions(), **fields)
                times.append(f.time)
                pair_heat.append(pair_sum.copy())
                last = (f.time, f.positions(), fields[f"dT_{self.models[0]}"], self.models[0])
            upto(np.inf if self.stop_step is None else self.stop_step)
        for step, where, command in unplaced + sets:
            self.warnings.append(f"{where}: '{command}' {'at an unknown step' if step is None else f'at step {step}'}"
                                 f": no dump frames on both sides of it, so post's temperatures do not follow it")
        self.done = True
        if last is not None:
            from pyhost.pictures import plot_post
            self.summary["picture"] = str(plot_post(self.out, last, [f"{a}-{b or 'wall'}" for a, b in pairs],
                                                    times, pair_heat))

    def follow_sets(self, temperature_sets, before, f, T) -> None:
        """A script's ``set ... property/atom Temp`` commands between two frames: each
        particle's temperature in every model changes once by what the dumps' temperature
        changed between the frames (which holds the sets and the script's own conduction over
        those steps: heat/gran's, if any). Listed in summary.json's ``temperature_sets``."""
        said = [f"{where}: {command}" for _, where, command in temperature_sets]
        column = self.temperature_column(f)
        if before[2] is None or column is None:
            self.warnings.append(f"{'; '.join(said)}: the dumps have no particle temperature ({TEMPERATURE}), so post's "
                                 "temperatures do not follow it")
            return
        ids0, T0 = before[1], before[2]
        ids = f["id"].astype(np.int64)
        at = np.full(int(max(ids.max(initial=0), ids0.max(initial=0))) + 1, -1)
        at[ids0] = np.arange(len(ids0))
        both = at[ids] >= 0
        change = f[column][both] - T0[at[ids][both]]
        for m in self.models:
            T[m][ids[both]] += change
        moved = np.abs(change) > 0
        self.summary.setdefault("temperature_sets", []).append(dict(
            steps=[step for step, _, _ in temperature_sets], commands=said, frames=[before[0], f.step],
            particles_changed=int(moved.sum()), mean_change_K=float(change[moved].mean()) if moved.any() else 0.0))

    def initial_temperatures(self, known, mat) -> np.ndarray:
        T0 = np.full(len(self.particles.type), np.nan)
        given = np.array([self.scene.temperature.get(t, 0.0) for t in self.particles.type[known].tolist()])
        T0[known] = np.where(given > 0, given, self.particles.T0[known])
        missing = known & np.isnan(T0)
        if missing.any():
            name = list(self.scene.materials)[mat[np.flatnonzero(missing[known])[0]]]
            raise ValueError(f"{self.scene.path}: materials.{name}.temperature: needed (the dumps hold no {TEMPERATURE})")
        return T0
