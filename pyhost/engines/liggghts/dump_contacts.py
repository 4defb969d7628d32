"""Collisions from LIGGGHTS' contact dumps, for post (``pyhost.post.Post`` takes these methods):
the ``dump local`` files of ``compute pair/gran/local`` and ``wall/gran/local`` grouped by
compute, a contact's first appearance in its stream its begin (``FirstAppearances``), a
particle touching several triangles of one mesh at once one contact (the row of largest
overlap), the mesh wall fix the rows belong to (wall/gran/local reports the script's last
one), and a check that the contact dumps are of the run the particle dumps are of. The
particles' temperature column LIGGGHTS dumps (``f_Temp``, or a heat/gran's own). SI units.

What ``Post`` provides them: ``contacts`` (paths), ``scene``, ``script``, ``computes``,
``particles``, ``frame_steps``, ``same_run``, ``warnings``, ``dumps``, ``clock``, ``skip``,
``reader()``, ``frames()``, ``open_at_start()``, ``frame_box()``, ``wall_codes(entry, meshes)``
and ``interval``, which this sets.
"""
from __future__ import annotations

import numpy as np

from pyhost.collisions import FirstAppearances, Found, contact_keys, minimum_image
from pyhost.dumps import DumpError, DumpReader, expand, local_compute, processor_parts
from pyhost.output import Progress


class ContactDumps:
    """Post's reading of LIGGGHTS' contact dumps and temperature column."""

    def temperature_column(self, f) -> str | None:
        """The frame's column of LIGGGHTS' particle temperature (f_Temp, or a heat/gran's own)."""
        return next((c for c in ("f_Temp", *(f"f_{h}" for h in (self.script.heat_gran if self.script else ())))
                     if c in f), None)

    def contact_streams(self) -> dict:
        """Contact dump files grouped by the compute their columns come from (one stream each)."""
        streams = {}
        heads, parts = processor_parts(expand(self.contacts))    # (an MPI run's files per processor)
        for p in heads:
            streams.setdefault(local_compute(p), []).extend([p, *parts.get(p, ())])
        return streams

    def dump_contacts(self, found: Found) -> None:
        """Collisions from contact dumps: a contact's first appearance in its stream."""
        intervals = []
        for cid, paths in self.contact_streams().items():
            first, previous = FirstAppearances(), None
            progress = Progress(float("inf"), self.progress_every)
            for f in self.frames(self.reader(paths, computes=self.computes)):
                progress.update(f.time, f"; reading the contact dumps of {cid}: {found.count()} collisions found")
                if f.kind not in ("pair", "wall"):
                    raise DumpError(f.file, f.timestep, f.line, "not a dump of compute pair/gran/local or wall/gran/local")
                missing = [g for g in ("x_i", "v_i", "id_i") + (("x_j", "v_j", "id_j") if f.kind == "pair"
                                                                  else ("x_contact", "v_wall", "mesh"))
                           if g not in f.groups]
                if missing:
                    raise DumpError(f.file, f.timestep, f.line, f"contact dump lacks {', '.join(missing)}: the compute "
                                                            "needs the keywords pos, vel and id, all dumped")
                window = f.time - previous[1] if previous is not None else None
                if previous is not None:
                    intervals.append((window, f.step - previous[0]))
                previous = (f.step, f.time)
                if len(f):
                    self.add_dump_contacts(f, cid, first, found, window)
                else:
                    first.new(np.empty(0, np.int64))        # an empty frame ends every contact
        if intervals:
            self.interval = min(intervals)
        self.check_same_run()

    def wall_index(self, cid: str) -> int:
        fixes = [k for k, w in enumerate(self.scene.walls) if w.fix]
        if self.script and self.script.mesh_wall_fixes:
            fix = self.script.mesh_wall_fixes[-1]       # wall/gran/local reports the last mesh wall fix
            match = [k for k in fixes if self.scene.walls[k].fix == fix]
            if not match:
                raise ValueError(f"{self.scene.path}: wall contacts of compute {cid} come from fix {fix}: "
                                 f"no [[walls]] entry has fix = {fix!r}")
            return match[0]
        if len(fixes) != 1:
            raise ValueError(f"{self.scene.path}: wall contacts of compute {cid}: which [[walls]] entry they belong "
                             f"to needs exactly one wall with 'fix', or --script; {len(fixes)} have one")
        return fixes[0]

    SAME_RUN_FRAMES = 8     # contact frames checked against the particle dumps

    def keep_for_same_run(self, f, ids_i) -> None:
        """The first few contact frames with rows at a step the particle dumps also have, for
        ``check_same_run``."""
        if f.step in self.frame_steps and f.step not in self.same_run and len(self.same_run) < self.SAME_RUN_FRAMES:
            self.same_run[f.step] = (f.file, f.timestep, f.line, ids_i.copy(), f.vector("x_i").copy())

    def check_same_run(self) -> None:
        """Contact frames at steps the particle dumps also have: their particles must be where
        those dumps put them (contact dumps of another run with the same ids would otherwise
        be taken for this one's). The particle dumps are read again up to the last such step:
        only the first 8 particle frames were kept, so a run whose first contacts come later
        (particle dumps every 20 steps of a pour) was never checked. Tolerance: the dumps' 6
        significant digits. A warning when no contact frame with rows shares a step with them."""
        if not self.same_run:
            self.warnings.append("no contact frame with contacts is at a step of the particle dumps: that the "
                                 "contact dumps are of the run the particle dumps are of is not checked")
            return
        pending = dict(self.same_run)
        for f in DumpReader(self.dumps, clock=self.clock, skip_bad_frames=self.skip, require=("id", "position")):
            if f.step in pending:
                self.compare_positions(pending.pop(f.step), f)
            if not pending or f.step > max(pending):
                return

    def compare_positions(self, contact, f) -> None:
        file, timestep, line, ids_i, x_i = contact
        ids, x, box, periodic = f["id"].astype(np.int64), f.positions(), self.frame_box(f), f.periodic
        at = np.full(int(max(ids.max(initial=0), ids_i.max(initial=0))) + 1, -1)
        at[ids] = np.arange(len(ids))
        rows = at[ids_i]
        seen = rows >= 0
        d = x_i[seen] - x[rows[seen]]
        if box is not None:
            d = minimum_image(d, box[:, 1] - box[:, 0], periodic)
            scale = np.abs(box).max()
        else:
            scale = np.abs(x).max(initial=0.0)
        tol = 1e-5 * scale + 1e-3 * self.particles.radius[ids_i[seen]]
        far = np.flatnonzero(np.linalg.norm(d, axis=1) > tol)
        if len(far):
            k = far[0]
            raise DumpError(file, timestep, line,
                            f"particle {ids_i[seen][k]} is at {x_i[seen][k].tolist()} m here and at "
                            f"{x[rows[seen][k]].tolist()} m in the particle dumps at the same step: the contact "
                            "dumps are not of the run the particle dumps are of")

    def add_dump_contacts(self, f, cid, first, found, window) -> None:
        ids_i = self.checked_ids(f, f["id_i"])
        self.keep_for_same_run(f, ids_i)
        r_i = self.particles.radius[ids_i]
        if f.kind == "pair":
            ids_j = self.checked_ids(f, f["id_j"])
            d = minimum_image(f.vector("x_i") - f.vector("x_j"), f.box[:, 1] - f.box[:, 0], f.periodic)
            v_rel = f.vector("v_i") - f.vector("v_j")
            gap = self.particles.radius[ids_j] + r_i
            j = ids_j
        else:
            d = f.vector("x_i") - f.vector("x_contact")
            v_rel = f.vector("v_i") - f.vector("v_wall")
            gap = r_i
            j = self.wall_codes(self.wall_index(cid), f["mesh"].astype(np.int64))
        dist = np.linalg.norm(d, axis=1)
        n = d / np.where(dist > 0, dist, 1.0)[:, None]
        delta = f["delta"] if "delta" in f else gap - dist
        approach = -np.einsum("ij,ij->i", v_rel, n)
        keys = contact_keys(ids_i, j)
        order = np.lexsort((-delta, keys))               # per key, the row of largest overlap first
        keys, first_row = np.unique(keys[order], return_index=True)
        rows = order[first_row]
        new = first.new(keys)
        if window is None:                               # the stream's first frame
            self.open_at_start(f, len(keys))
            return
        rows = rows[new]
        found.add(step=f.step, i=ids_i[rows], j=j[rows], delta=delta[rows], approach=approach[rows], window=window)

    def checked_ids(self, f, ids):
        ids = ids.astype(np.int64)
        known = (ids < len(self.particles.type)) & (ids > 0)
        known[known] = self.particles.type[ids[known]] > 0
        if not known.all():
            raise DumpError(f.file, f.timestep, f.line, f"particle id {ids[~known][0]} is in no particle dump")
        return ids
