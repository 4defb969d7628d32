"""Collision heat, restitution and the collision log: every contact that begins is a collision,
its impact speed recorded at first touch inside LIGGGHTS (contact events, pyhost.engines.events),
its heat from the plugin moved at the next harvest in the order of the collisions, the
model's restitution imposed at its end if asked, a script's fix heat/gran undone during the
collision's model time. Present when the scene needs contacts (``contact_extraction``:
collision heat or restitution feedback). SI units.

How a contact is classified. A contact begins at the first step the recorder finds the two
overlapping (``r_i + r_j - |x_i - x_j| > 0``, LIGGGHTS' own test) and ends at the first step
it does not. Its begin is a collision; the collision's heat Q accounts for the first t_coll
of the contact, the collision's duration under the real material's model. A contact that is
still open after t_coll is *enduring*. From then on it conducts only through the script's
fix heat/gran (or the box scenes' ``enduring_conduction``), if any, whose flux during the
first t_coll is taken back. So no stretch of a contact's time is counted twice. Contacts
present at the start (or a restart) are open and enduring, not collisions.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from plugins.dem.impulse import restitution_impulse
from pyhost.collisions import Bodies, collide, contact_keys, ended_later, log_wall, material_of, minimum_image, wall_of
from pyhost.effects import Effect
from pyhost.effects.rank_heat import RankHeat, on_rank
from pyhost.engines.atoms import Atoms
from pyhost.engines.events import BEGIN, END, join_moved
from pyhost.output import ColumnLog, CsvLog, collision_kinds

ON_RANKS_FROM = 256
"""Collisions in the last harvest (on all ranks) from which the next is moved on each rank; a
run whose harvests are smaller has rank 0 move them (``harvest_partly``, or on the atoms a
frame gathers). Each harvest on the ranks costs about 1 ms more on rank 0 (the plugin's
fixed cost of a call on every rank, the merging): on hot-cold-box with restitution feedback
(6 collisions per harvest, every 10 steps) moving them on the ranks took 10-35 % more wall
time on two ranks."""

ON_RANKS = True
"""Whether a harvest under MPI moves collision heat on each rank (``harvest_on_ranks``);
False: rank 0 moves all in time order (``harvest_partly`` between frames, else on the atoms
the frame gathers), the reference tests/cases/test_mpi.py compares it with."""

HARVEST_EVERY = 1000
"""DEM steps between harvests of the contact events at most (they are also taken at every
frame and checkpoint, and at a fluid exchange that reads temperatures): bounds the
recorder's buffer and the wait of a signal (a stop is taken between two DEM chunks)."""

HARVEST_PARTICLE_STEPS = 10**8
"""Under MPI, DEM steps between harvests at most this over the number of particles: rank 0
holds the collision rows of all ranks of one harvest at once (some 100 bytes each, several
times over while they are joined, sorted and logged; the dense gas has about 4 collisions per
particle per 1000 steps), so a gas of 1,000,000 particles harvests every 100 steps instead
of HARVEST_EVERY (docs/mpi.md: at 1000 steps rank 0 peaked at 2.1 GB and rank 1 at 1.8 GB,
every 100 steps at 0.83 and 0.73 GB); 100,000 particles and fewer keep HARVEST_EVERY. Without
the script's conduction the heat moved does not depend on the interval (``harvest``)."""

COLLISION_COLUMNS = ("time", "step", "i", "j", "wall", "v0", "Q", "e", "t_coll", "model")


class CollisionHeat(Effect):
    """``walls``: the HostWall of every LIGGGHTS wall, in the order of their contact codes
    (``at_run``); the checkpoint's output marks to continue from: ``loop.logs``. Its interval:
    ``harvest``, every time.sample_every steps with restitution feedback, else HARVEST_EVERY."""

    TOTALS = dict(collisions=0, particle_particle=0, particle_wall=0, heat_moved=0.0, heat_from_walls=0.0,
                  capped=0, clipped=0, heat_gran_undone=0.0, heat_gran_walls_undone=0.0,
                  outside_model_range=0, contacts_without_impact=0, collisions_of_departed=0,
                  collisions_moved_on_ranks=0, contacts_changed_rank=0, restitution_late=0,
                  restitution_not_imposed=0, heat_gran_undo_cut=0, heat_by_model=None)

    def __init__(self, loop):
        super().__init__(loop)
        scene = loop.scene
        self.t_coll_of = {}                      # (key, begin step) -> t_coll [s] of pair collisions under heat/gran
        self.restitution = scene.effects.restitution_feedback and loop.heat
        self.targets = {}                        # key -> (separation speed, normal) the recorder imposes at the end
        self.last_batch = ON_RANKS_FROM          # collisions of the last harvest (MPI: where the next moves)
        columns = COLLISION_COLUMNS + tuple(f"Q_{m}" for m in scene.effects.heat_models[1:])
        mark = loop.logs.get("collisions")
        self.log = (ColumnLog(loop.out / "collisions", collision_kinds(columns), mark)
                    if scene.output.collisions == "binary" else CsvLog(loop.out / "collisions.csv", columns, mark))
        self.every = dict(harvest=scene.time.sample_every if self.restitution else HARVEST_EVERY)

    @property
    def dem(self):
        return self.loop.dem

    @property
    def scene(self):
        return self.loop.scene

    @property
    def totals(self) -> dict:
        return self.loop.totals

    @property
    def warned(self) -> set:
        return self.loop.warned

    @classmethod
    def end_totals(cls, totals: dict, scene) -> None:
        """A scene without collisions: each model's 0 J."""
        if totals["heat_by_model"] is None:
            totals["heat_by_model"] = dict.fromkeys(scene.effects.heat_models, 0.0)

    def begin(self, resumed: bool) -> None:
        """The walls' contacts now are open ones: one that begins at the next step is a collision
        (prepare's set-up left the lists). Under MPI the harvests come at most every
        HARVEST_PARTICLE_STEPS / N steps."""
        self.dem.events.sync()
        if self.dem.link is not None and not self.restitution:
            n = self.dem.count()
            self.every = dict(harvest=max(1, min(HARVEST_EVERY, HARVEST_PARTICLE_STEPS // max(n, 1))))

    def at_run(self, walls) -> None:
        """The LIGGGHTS walls as the host sees them (a script may add walls between runs)."""
        self.walls = walls
        self.wall_index = {(w.fix, w.mesh): k for k, w in enumerate(walls)}
        self.T_wall = np.array([w.temperature if self.loop.effects["wall_heat"] else np.nan for w in walls])
        self.wall_material = np.array([w.material for w in walls], int)
        self.bodies = Bodies(self.loop.materials, self.loop.type_material, self.wall_material)
        heated = {(w.fix, w.mesh) for w, T in zip(walls, self.T_wall) if np.isfinite(T)}
        self.conducting = self.dem.event_walls(self.wall_index, heated)   # codes: heat/gran's share taken back

    def after_chunk(self, due: dict) -> None:
        """The contacts' work at the end of a DEM chunk: the events harvested, if due. Under MPI
        without a fix heat/gran, each rank moves its own collisions' heat (``harvest_on_ranks``)
        unless the last harvest was small (ON_RANKS_FROM); a harvest that comes alone then
        gathers only the colliding atoms to rank 0 (``harvest_partly``)."""
        loop = self.loop
        alone = self.harvest_alone(due)
        if not (alone or self.wants_harvest(due)):
            return
        before = self.totals["collisions"]
        ranks = self.dem.link is not None and not self.dem.events.window
        if ranks and ON_RANKS and loop.heat and self.last_batch >= ON_RANKS_FROM:
            self.harvest_on_ranks()
        elif alone:
            self.harvest_partly()
        else:
            atoms = self.dem.atoms(loop.heat)
            loop.track_particles(atoms)
            self.harvest(atoms, final=bool(due["checkpoint"]))
        self.last_batch = self.totals["collisions"] - before

    def wants_harvest(self, due: dict) -> bool:
        """Whether this chunk's end needs the events taken now: a harvest, a frame or a
        checkpoint is due, or a fluid exchange that reads the temperatures (convection) or
        comes while a fix heat/gran conducts, or a lasting conduction update (which must know
        every collision begun, to leave each its t_coll). A fluid exchange without either
        changes no temperature and reads none: the events wait for the next of the others, in
        larger batches (the heat moved is the same, collision after collision in their order)."""
        fluid = self.loop.find("fluid")
        convects = fluid is not None and fluid.convection
        return any(due[k] for k in ("harvest", "frame", "checkpoint", "conduct")) or (
            due["couple"] and (convects or bool(self.dem.events.window)))

    def end_run(self) -> None:
        """At the end of each of the script's runs: the events so far (under MPI without a fix
        heat/gran, on the atoms of those events only: ``harvest_partly``)."""
        if self.dem.link is not None and not self.dem.events.window:
            self.harvest_partly()
            return
        self.harvest(self.dem.atoms(self.loop.heat))

    def state(self) -> tuple[dict, dict]:
        return (dict(logs=dict(collisions=self.log.mark()), last_batch=self.last_batch),
                dict(target_keys=np.array(list(self.targets), np.int64),
                     target_speed=np.array([v[0] for v in self.targets.values()]),
                     target_normal=np.array([v[1] for v in self.targets.values()]).reshape(-1, 3)))

    def restore(self, state: dict) -> None:
        self.last_batch = state.get("last_batch", ON_RANKS_FROM)    # where the next harvest's heat moves (MPI)
        if self.restitution and len(state.get("target_keys", ())):   # separation speeds of contacts still open
            self.dem.events.restitution(state["target_keys"], state["target_speed"], state["target_normal"])
            self.targets = dict(zip(state["target_keys"].tolist(),
                                    zip(state["target_speed"].tolist(), state["target_normal"].tolist())))

    def close(self) -> None:
        self.log.close()

    def flag_outside_range(self, count: int, v_max: float) -> None:
        """``count`` collisions the contact models do not cover (plugins.heat.validity, as
        ``collide`` flags them; the fastest at v_max [m/s]): counted in summary.json
        (outside_model_range), said once; their heat is moved."""
        self.totals["outside_model_range"] += count
        if count and "outside_model_range" not in self.warned:
            self.warned.add("outside_model_range")
            print(f"warning: a collision at v0 = {v_max:.4g} m/s is outside the contact models' "
                  "range (indentation beyond the smaller radius, or an output overflows): its heat is the models' "
                  "extrapolation; such collisions are counted in summary.json as outside_model_range")

    def partners(self, atoms, i, j):
        """For contacts between local atoms i and partners j (atom ids, or wall codes): j as a
        local index or wall code, and both bodies (``pyhost.collisions.Partners``: materials,
        radii [m], masses [kg] as LIGGGHTS has them)."""
        wall, _ = wall_of(j)
        jl = np.where(wall, j, atoms.index(np.where(wall, 0, j)))
        jj = np.where(wall, 0, jl)
        where, table = str(self.scene.path), self.bodies.type_material
        return jl, self.bodies.partners(j, material_of(table, atoms.type[i], where), atoms.radius[i],
                                        material_of(table, atoms.type[jj], where), atoms.radius[jj], atoms.mass[i],
                                        atoms.mass[jj])

    def harvest_alone(self, due) -> bool:
        """Whether this chunk's end asks only for a harvest, under MPI with no fix heat/gran.
        Nothing but the host changes a temperature then, and each atom's heat content in the
        balance is brought up to date when it is next seen."""
        return (self.dem.link is not None and not self.dem.events.window
                and due["harvest"] and not any(v for k, v in due.items() if k != "harvest"))

    def harvest_partly(self) -> None:
        """A harvest under MPI for which rank 0 gathers only the atoms of the events (the
        others stay on their ranks): ``harvest`` on them."""
        ev = self.dem.events.take()
        if not len(ev):
            return
        ids = np.unique(np.r_[ev["i"], ev["j"][~ev["wall"]]])
        atoms = self.dem.atoms_of(ids, self.loop.heat)
        self.loop.track_particles(atoms, departures=False)
        self.harvest(atoms, ev=ev)

    def harvest_on_ranks(self) -> None:
        """A harvest under MPI with collision heat and no fix heat/gran: each rank moves the
        heat of its own collisions, on its own atoms (``pyhost.effects.rank_heat``); rank 0 moves
        those left over on the atoms of their events only (``harvest``), counts all, writes all
        rows in the serial order and, with restitution feedback, gives every collision its
        separation speed (gathering the atoms of the contacts that ended before it could)."""
        loop, balance = self.loop, self.loop.find("balance")
        models = self.scene.effects.heat_models
        setup = RankHeat(loop.materials, loop.type_material, loop.capacity, tuple(models),
                         self.scene.effects.heat_path, self.T_wall, self.wall_material, loop.clock,
                         np.packbits(balance.seen), len(balance.seen),
                         loop.known.T if loop.known.by == "type" else None, self.restitution)
        parts = self.dem.each_rank(on_rank, setup)
        for p in parts:
            if len(p["new"][0]):   # inserted atoms a rank gave their starting temperature: they come in
                balance.track(Atoms(p["new"][0], None, None, p["new"][3], p["new"][1], p["new"][2], p["new"][4]),
                              departures=False)
        for p in parts:
            if len(p["ids"]):      # the heat contents changed on the ranks, as a partial harvest sees them
                before = Atoms(p["ids"], None, None, None, p["mass"], p["type"], p["T_before"])
                balance.track(before, departures=False)
                balance.track(dataclasses.replace(before, T=p["T_after"]), departures=False)
            self.totals["capped"] += p["capped"]
            if p["still"]:
                self.totals["contacts_without_impact"] += p["still"]
            if p["flagged"]:
                self.flag_outside_range(p["flagged"], p["v_flagged"])
        moved = [(p["cols"], p["step"], p["jj"], p.get("begun")) for p in parts]
        ev, self.dem.events.joined = join_moved(np.concatenate([p["events"] for p in parts]))
        need = [ev["i"][ev["kind"] == BEGIN], ev["j"][(ev["kind"] == BEGIN) & ~ev["wall"]]]
        if self.restitution:
            need += self.restitution_atoms(np.concatenate([p["begun"] for p in parts]), ev[ev["kind"] == END])
        ids = np.unique(np.concatenate(need))
        atoms = None
        if len(ids):
            atoms = self.dem.atoms_of(ids, loop.heat)
            loop.track_particles(atoms, departures=False)
        count = sum(len(p["step"]) for p in parts)
        if count:
            self.totals["collisions_moved_on_ranks"] += count
        self.harvest(atoms, ev=ev, moved=moved)

    def restitution_atoms(self, begun, ends) -> list:
        """The ids whose atoms restitution feedback needs at this harvest: of the collisions
        whose contact already ended (their speed is imposed now) and of the ended contacts whose
        speed the recorder could not impose (``ask_restitution``, ``ended_with_targets``)."""
        late = ended_later(begun, ends)
        targeted = [k in self.targets for k in contact_keys(ends["i"], ends["j"]).tolist()]
        missed = np.array(targeted, bool) & ~ends["imposed"]
        return [begun["i"][late], begun["j"][late & ~begun["wall"]],
                ends["i"][missed], ends["j"][missed & ~ends["wall"]]]

    def harvest(self, atoms, final: bool = False, ev=None, moved=()) -> None:
        """The contact events recorded inside LIGGGHTS since the last harvest: each begun
        contact is a collision, at its impact speed as recorded at first touch, its heat moved
        now in the order the collisions happened. Without a fix heat/gran nothing else changes
        a temperature between two harvests (they come at every frame and checkpoint, at a fluid
        exchange that reads the temperatures, and at least every HARVEST_EVERY steps), so the
        heat is what it would be if moved at each collision's own step (tests/cases/
        test_batch_delay.py); with one, each collision takes the temperature difference it
        began with (the recorder notes the two temperatures at its first step), and what
        heat/gran conducted through each new contact during the collision's model time is taken
        back (``take_back_heat_gran``; ``final``: also for contacts younger than its window, at
        a checkpoint or the end). A
        collision whose particle left the simulation before the harvest (deleted, out of the
        box) is counted apart (collisions_of_departed) and moves no heat: its heat content left
        when it was last seen; so is one that began with no approach speed
        (contacts_without_impact). ``moved``: batches of collisions whose heat the ranks moved
        (``harvest_on_ranks``), concluded with this harvest's own (``conclude``)."""
        ev = self.dem.events.take() if ev is None else ev
        begin, ends = ev[ev["kind"] == BEGIN], ev[ev["kind"] == END]
        if self.dem.events.joined:               # open contacts that moved between ranks (MPI)
            self.totals["contacts_changed_rank"] += len(self.dem.events.joined)
        if self.targets and len(ends):
            self.ended_with_targets(atoms, ends)
        batches = list(moved) + (self.collide_begun(atoms, begin) if len(begin) else [])
        if self.dem.events.window:
            dt = self.dem.dt
            for key, began, went in self.dem.events.joined:    # a flux history goes on on another rank
                if (key, began) in self.t_coll_of:
                    self.t_coll_of[key, went] = self.t_coll_of[key, began] - (went - began) * dt
            self.take_back_heat_gran(atoms, final)
        self.conclude(atoms, batches, ends)

    def conclude(self, atoms, batches, ends) -> None:
        """A harvest's collisions, in batches of (log columns, steps, partners j as ids or wall
        codes, their BEGIN events or None) whose heat is moved: counted and logged in the
        serial order (step, walls last, ids; one batch is in it already), and with restitution
        feedback given their separation speeds (``ask_restitution``, with the harvest's ENDs)."""
        if not sum(len(b[1]) for b in batches):
            return
        step, j = (np.concatenate([b[k] for b in batches]) for k in (1, 2))
        cols = {k: np.concatenate([b[0][k] for b in batches]) for k in batches[0][0]}
        order = np.lexsort((j, cols["i"], wall_of(j)[0], step))
        cols = {k: v[order] for k, v in cols.items()}
        self.record(cols)
        conduction = self.loop.find("conduction")
        if conduction is not None:
            conduction.collided(cols)
        if self.restitution:
            self.ask_restitution(atoms, np.concatenate([b[3] for b in batches])[order], cols["e"], ends)

    def ended_with_targets(self, atoms, ends) -> None:
        """Contacts given a separation speed that ended since the last harvest: the recorder
        imposed it at the end, unless the pair's atoms were on two ranks (MPI: the recorder
        changes only its own rank's atoms) or one was gone. Those get it now, from the
        velocities now (restitution_late), as a contact shorter than the harvest interval does.
        Under MPI every rank forgets these contacts' speeds (each keeps all, as a contact may
        move between ranks)."""
        keys = contact_keys(ends["i"], ends["j"])
        late = []
        for r, (key, imposed) in enumerate(zip(keys.tolist(), ends["imposed"].tolist())):
            target = self.targets.pop(key, None)
            if target is not None and not imposed:
                late.append((r,) + target)
        if self.dem.link is not None:
            self.dem.events.forget(keys)
        if late:
            rows = np.array([r for r, _, _ in late])
            present = (atoms.index(ends["i"][rows]) >= 0) & (ends["wall"][rows] | (atoms.index(ends["j"][rows]) >= 0))
            self.totals["restitution_not_imposed"] += int((~present).sum())
            self.totals["restitution_late"] += int(present.sum())
            self.impose_separation(atoms, ends["i"][rows], ends["j"][rows], np.array([n for _, _, n in late]),
                                   np.ones(len(rows)), np.array([v for _, v, _ in late]))

    def collide_begun(self, atoms, begin) -> list:
        """The begun contacts of a harvest: their heat moved in order (``collide``); returns
        them as one batch for ``conclude`` (none if no collision)."""
        i = atoms.index(begin["i"])
        j_here = np.where(begin["wall"], 0, atoms.index(np.where(begin["wall"], begin["i"], begin["j"])))
        here = (i >= 0) & (j_here >= 0)
        if not here.all():
            self.totals["collisions_of_departed"] += int((~here).sum())
        # a contact that begins without closing in (particles grown into each other by a fix
        # adapt, or placed touching) is no impact: open, with no collision heat
        still = here & ~(begin["vn"] > 0)
        if still.any():
            self.totals["contacts_without_impact"] += int(still.sum())
        begin = begin[here & ~still]
        # in the order of step, then ids: not of the recorder's lists, which follow the atoms'
        # order in memory (a restart or another number of ranks changes it)
        begin = begin[np.lexsort((begin["j"], begin["i"], begin["wall"], begin["step"]))]
        if not len(begin):
            return []
        cols = self.collide(atoms, begin["i"], begin["j"], begin["vn"], begin["step"], T_begin=begin["T"])
        if self.dem.events.window:              # each collision's model time, until its flux history comes
            pair = ~begin["wall"] | np.isin(begin["j"], list(self.conducting))
            keys = contact_keys(begin["i"][pair], begin["j"][pair]).tolist()
            self.t_coll_of.update(zip(zip(keys, begin["step"][pair].tolist()), cols["t_coll"][pair].tolist()))
        return [(cols, begin["step"], begin["j"], begin)]

    def ask_restitution(self, atoms, begin, e, ends) -> None:
        """Restitution feedback on contact events: each collision's separation speed e v0 (e
        above 1 clipped, counted) handed to the recorder, which imposes it at the step the
        contact ends. A contact that ended before this harvest (shorter than the harvest
        interval, time.sample_every steps) gets it now, from the velocities now (counted as
        restitution_late). ``e``: each begun collision's restitution from its model."""
        v0 = begin["vn"]
        self.totals["clipped"] += int(np.sum(e > 1.0))
        speed = np.minimum(e, 1.0) * v0
        keys = contact_keys(begin["i"], begin["j"])
        late = ended_later(begin, ends)
        ask = ~late & ~np.isnan(speed)
        if ask.any():
            self.dem.events.restitution(keys[ask], speed[ask], begin["n"][ask])
            self.targets.update(zip(keys[ask].tolist(), zip(speed[ask].tolist(), begin["n"][ask].tolist())))
        if late.any():
            self.totals["restitution_late"] += int(late.sum())
            self.impose_separation(atoms, begin["i"][late], begin["j"][late], begin["n"][late],
                                   np.minimum(e[late], 1.0), v0[late])

    def take_back_heat_gran(self, atoms, final: bool) -> None:
        """What the script's fix heat/gran conducted through each new pair contact during the
        collision's model duration t_coll, taken back (the collision heat stands for that time):
        from the recorder's flux history of the contact, step m from the begin carrying flux f_m
        [W] over dt, Q = dt sum_m f_m clip(t_coll / dt - m, 0, 1) [J] into the smaller id. Exact
        per step. So for a new contact with a wall through which heat/gran conducts and whose
        collisions get heat (``conducting``): Q into the particle, taken from it, counted in
        ``heat_gran_walls_undone`` (heat the script's walls gave, which the balance counts in
        heat_from_script_walls)."""
        i, j, start, filled, flux = self.dem.events.histories(all=final)
        if not len(i):
            return
        keys = contact_keys(i, j).tolist()
        t_coll = np.array([self.t_coll_of.pop(k, np.nan) for k in zip(keys, start.tolist())])
        if final:                                           # every history is in: what is left has none
            self.t_coll_of = {}
        dt, window = self.dem.dt, flux.shape[1]
        steps = t_coll / dt
        cut = np.isfinite(steps) & (steps > window) & (filled == window)
        if cut.any():
            self.totals["heat_gran_undo_cut"] += int(cut.sum())
        share = np.clip(np.nan_to_num(steps)[:, None] - np.arange(window), 0.0, 1.0)
        share[np.arange(window) >= filled[:, None]] = 0.0
        q = dt * np.sum(flux * share, axis=1)              # heat heat/gran moved into i [J]
        wall, _ = wall_of(j)
        a, b = atoms.index(i), np.where(wall, -1, atoms.index(np.where(wall, 0, j)))
        ok = np.isfinite(t_coll) & (a >= 0) & ((b >= 0) | wall) & (q != 0)
        on_wall = ok & wall
        if on_wall.any():
            np.subtract.at(atoms.T, a[on_wall], q[on_wall] / self.loop.C[a[on_wall]])
            self.totals["heat_gran_walls_undone"] += float(q[on_wall].sum())
        ok &= ~wall
        a, b, q = a[ok], b[ok], q[ok]
        np.subtract.at(atoms.T, a, q / self.loop.C[a])
        np.add.at(atoms.T, b, q / self.loop.C[b])
        self.totals["heat_gran_undone"] += float(np.abs(q).sum())

    def collide(self, atoms, ids_i, j, v0, step, T_begin=None) -> dict:
        """Collisions of particles ``ids_i`` with partners ``j`` (ids, or wall codes) at impact
        speeds v0 [m/s], begun at LIGGGHTS' step ``step`` of the run under way: the plugin's heat
        moved in this order (``pyhost.collisions.collide``). Returns their columns of the collision log (Q, e
        and t_coll zero without particle temperatures): ``record`` counts and writes them.
        ``T_begin`` (n, 2) [K]: the two temperatures when each began (NaN: as now), where
        something else (a fix heat/gran) changed them since: each collision's temperature
        difference is the one it began with, plus what earlier collisions of this batch moved."""
        i = atoms.index(ids_i)
        jl, p = self.partners(atoms, i, j)
        wall = p.wall
        models = self.scene.effects.heat_models
        heat = dict.fromkeys(("Q", "e", "t_coll"), np.zeros(len(i)))
        if self.loop.heat:
            shift = None
            if T_begin is not None:         # (T_i - T_j) then minus now, before this batch
                drift = T_begin - np.column_stack([atoms.T[i], np.where(wall, np.nan, atoms.T[np.where(wall, i, jl)])])
                shift = np.nan_to_num(drift[:, 0]) - np.where(wall, 0.0, np.nan_to_num(drift[:, 1]))
            heat, flagged, capped = collide(models, self.scene.effects.heat_path, self.bodies, p, v0, atoms.T,
                                            self.loop.C, i, jl, self.T_wall, shift)
            self.totals["capped"] += capped
            if flagged.any():
                self.flag_outside_range(int(flagged.sum()), float(np.max(v0[flagged])))
        return dict(time=self.loop.time_of(step), step=step, i=ids_i, j=np.where(wall, 0, j), wall=log_wall(j), v0=v0,
                    model=np.full(len(i), models[0] if models else "none"), **heat)

    def record(self, cols: dict) -> None:
        """Collisions' columns (``collide``), in the serial order: counted in the totals (heat
        between particles as sum |Q|, the walls' heat summed in order) and written to the
        collision log."""
        wall = cols["wall"] > 0
        if self.loop.heat:
            Q = cols["Q"]
            q_walls = Q[wall]
            self.totals["heat_from_walls"] += 0.0 - float(np.cumsum(q_walls)[-1]) if len(q_walls) else 0.0
            self.totals["heat_moved"] += float(np.abs(Q[~wall]).sum())
            by_model = self.heat_by_model()
            for k, m in enumerate(self.scene.effects.heat_models):     # the first moved the heat
                by_model[m] += float(np.abs(cols["Q" if k == 0 else f"Q_{m}"][~wall]).sum())
        self.totals["collisions"] += len(wall)
        self.totals["particle_wall"] += int(wall.sum())
        self.totals["particle_particle"] += int((~wall).sum())
        self.log.write_columns(**cols)

    def heat_by_model(self) -> dict:
        """Heat between particles [J], sum of |Q| over collisions, of each heat model: the one
        that moved it and the side models on the same collisions."""
        if self.totals["heat_by_model"] is None:
            self.totals["heat_by_model"] = dict.fromkeys(self.scene.effects.heat_models, 0.0)
        return self.totals["heat_by_model"]

    def impose_separation(self, atoms, ids_i, ids_j, normal, e, v0) -> int:
        """The model's separation speed e v0 [m/s] imposed now on each pair's normal velocity
        (particles ``ids_i`` and ``ids_j``, or a wall code: the line of centres, nearest
        image; a wall's ``normal`` as given), momentum conserved; skipped where a particle is
        gone or e is NaN (contacts there at a restart: no collision). Returns how many e above
        1 were clipped."""
        i = atoms.index(ids_i)
        here = (i >= 0) & ~np.isnan(e)
        jl, p = self.partners(atoms, np.maximum(i, 0), ids_j)
        wall, m_j = p.wall, p.m_j
        here &= wall | (jl >= 0)
        normal = np.array(normal, float)
        jj = np.where(wall, 0, np.maximum(jl, 0))
        d = atoms.x[np.maximum(i, 0)] - atoms.x[jj]
        lo, hi, periodic = self.dem.box()
        d = minimum_image(d, hi - lo, periodic)
        normal[~wall] = d[~wall] / np.linalg.norm(d[~wall], axis=1)[:, None]
        v_j = np.where(wall[:, None], 0.0, atoms.v[jj])
        dv_i, dv_j, clipped = restitution_impulse(atoms.v[np.maximum(i, 0)], v_j, atoms.mass[np.maximum(i, 0)],
                                                  m_j, normal, e, v0)
        self.dem.add_velocity(i[here], dv_i[here])
        pair = here & ~wall
        if pair.any():
            self.dem.add_velocity(jl[pair], dv_j[pair])
        return clipped

    def settle(self) -> None:
        """The contact events recorded since the last harvest, taken now (a run stopped
        between harvests: its checkpoint and summary hold every collision)."""
        if self.loop.ready and (self.dem.events.waiting or self.dem.events.window):
            atoms = self.dem.atoms(self.loop.heat)
            self.loop.track_particles(atoms)
            self.harvest(atoms, final=True)
