"""The coupling loop: read this file first (docs/architecture.md: the path to it and through it).

A scene's DEM is a LIGGGHTS script (the user's, or the box world generated from case.toml),
run command by command by ``pyhost.run_scene``; each ``run N`` becomes ``Coupling.advance(N)``,
which runs the DEM in chunks and calls the hooks of the effects the scene asks for
(``pyhost.effects.REGISTRY``, built by ``Scene.effects_summary``: one module each in
``pyhost.effects``, which says what each hook is for). The loop only schedules: a chunk ends
where the first interval of an effect (``Effect.every``: harvest, conduct, couple, frame) or
the loop's checkpoint ends; there the effects do their work, in the registry's order.

Temperatures live in LIGGGHTS' per-atom ``Temp``: the host reads and writes them there and
keeps no copy. A dry, isothermal scene runs the DEM and the frames only.
"""
from __future__ import annotations

import json
import math
from collections import defaultdict
from pathlib import Path

from pyhost import checkpoint, signals
from pyhost.effects import Context, end_totals
from pyhost.engines.dem import Dem
from pyhost.failures import InvariantBroken
from pyhost.outdir import write_atomic
from pyhost.output import Progress
from pyhost.tables import LossWatch, TypeMaterials


class Coupling:
    """The coupled run of a scene on a prepared ``Dem``; ``advance(n)`` runs n DEM steps,
    ``finish()`` writes and returns the summary.

    ``type_material``: material index of each atom type (index = type; -1: none);
    ``known``: each particle's group and starting temperature (``pyhost.tables.Known``);
    ``walls``: the HostWall of every LIGGGHTS wall, in the order of their contact codes;
    ``materials``: the real materials, their DEM contacts as the DEM has them.
    The contacts present at the start (overlaps as placed, a script's read_restart of a
    settled bed) are not collisions: open and enduring.
    ``resume``: a checkpoint's state (pyhost.checkpoint) to continue from, its logs appended to.
    ``driven`` [s]: the coupled time of a CFD-DEM script's last run (its case's last coupling step).
    """

    def __init__(self, scene, dem: Dem, out: Path, *, type_material, known, walls, materials, fluid=None,
                 end: float | None = None, progress_every: float = 5.0, resume: dict | None = None,
                 driven: float | None = None):
        self.scene, self.dem, self.out, self.fluid = scene, dem, Path(out), fluid
        self.clock = (0.0, 0, dem.dt)      # (t, step, dt): the time of LIGGGHTS' step s is t + (s - step) dt
        self.t = self.time_of(dem.step)     # the simulated time [s]: each step's time step summed
        self.t_step = dem.step              # the step LIGGGHTS numbers at time t
        self.t_begin = self.t               # the time at the start of the coupled run
        self.steps = 0                      # the coupled steps so far (whatever LIGGGHTS numbers them)
        self.every = {}
        self.ready = resume is not None      # a consistent state to checkpoint (after start())
        self.ctx = Context(scene, dem, self.out, fluid, driven, materials, TypeMaterials(type_material, scene.path),
                           known, resume["logs"] if resume else {}, _clock=self)
        self.effect_list = self.ctx.build()   # the effects the scene asks for, in the order they act
        self.at_run(walls)
        for effect in self.effect_list:
            effect.begin(resume is not None)
        self.watch = LossWatch(scene, dem, known) if known.by == "id" else None   # box scenes: losing any fails
        self.progress = Progress(end or math.inf, progress_every)
        self.schedule()
        self.program, self.run_left = None, 0  # the script's input loop (Program: where it stands at the run
                                               # under way, kept by a checkpoint), the run's steps to go
        self.inputs = {}                     # SHA-256 of each file the run read, at its start (a restart checks them)
        self.extend = 0.0                    # run --extend [s] (a checkpoint keeps it)
        self.resumed = resume is not None    # the next advance continues the checkpoint's run
        self.checkpoint_step = -1            # the coupled steps (``steps``) at the last checkpoint written
        self.frame_step = None               # the coupled steps at the last frame
        if resume is not None:
            checkpoint.restore(self, resume)

    @property
    def totals(self) -> dict:
        return self.ctx.totals

    def at_run(self, walls) -> None:
        """At each of a script's runs: the walls as the host sees them now, the effects' checks."""
        for effect in self.effect_list:
            effect.at_run(walls)

    def schedule(self) -> None:
        """DEM steps between the ends of each interval: the effects' and the checkpoints'."""
        self.every = {name: k for effect in self.effect_list for name, k in effect.every.items()}
        self.every["checkpoint"] = round(self.scene.output.checkpoint / self.dem.dt) if self.scene.output.checkpoint else 0

    def time_of(self, step) -> float:
        """The simulated time [s] of LIGGGHTS' step number ``step`` of the run under way."""
        t, at, dt = self.clock
        return t + (step - at) * dt

    # -- the loop -----------------------------------------------------------------------
    def start(self) -> None:
        """The effects' start (the first fluid exchange) and the first frame (after
        construction, so that an interrupt from here on finds a coupling to write its summary)."""
        if self.ready:                    # resumed: the checkpoint's state is all there is
            return
        for effect in self.effect_list:
            effect.start()
        self.write_frame()
        self.ready = True

    def advance(self, n: int) -> None:
        """n coupled DEM steps: the loop of the module doc. With checkpoints, a signal stops it
        only at the end of a step, where the state is whole (``signals.deferred``), and a
        checkpoint is written there (``run_scene``), periodic checkpoints asked for or not."""
        with signals.deferred():
            self._advance(n)

    def _advance(self, n: int) -> None:
        self.run_left = n
        if (self.dem.dt, self.dem.step) != (self.clock[2], self.t_step):
            # a 'timestep' or 'reset_timestep' since the last run: time goes on from where it was,
            # at the new step size, whatever LIGGGHTS numbers the steps (its own time, update's
            # atime, goes back at a reset_timestep and ignores a timestep change)
            self.clock = (self.t, self.dem.step, self.dem.dt)
            self.t_step = self.dem.step
        for effect in self.effect_list:     # (a restart continues a run: no script command came in between)
            effect.before_run(self.resumed)
        self.resumed = False
        self.schedule()                      # (a script's dumps and time step as they are now)
        while n > 0:
            step = self.steps
            chunk = min([n] + [k - step % k for k in self.every.values() if k])
            if self.watch is not None:
                self.watch.before_chunk(self.t)
            self.dem.run(chunk)
            if self.watch is not None:
                self.watch.after_chunk(self.time_of(self.dem.step))
            n -= chunk
            self.run_left = n
            self.steps += chunk
            step += chunk
            self.t, self.t_step = self.time_of(self.dem.step), self.dem.step
            due = defaultdict(bool, {name: k and step % k == 0 for name, k in self.every.items()})
            for effect in self.effect_list:
                effect.after_chunk(due)
            if due["couple"]:
                for effect in self.effect_list:
                    effect.couple()
            if due["frame"]:
                self.write_frame()
            if due["checkpoint"]:
                checkpoint.write(self)
            self.progress.of_run(self.t, self.totals)
            signals.check()
        for effect in self.effect_list:      # (a fluid's last advance, if it ran beside the DEM: a failure
            effect.join()                    # in it stops this run like any other, summary and exit 3)
        for effect in self.effect_list:
            effect.end_run()

    def write_frame(self) -> None:
        self.frame_step = self.steps
        for effect in self.effect_list:
            effect.frame()

    def settle(self) -> None:
        """The effects' work owed since the last chunk (the contact events recorded since the
        last harvest): a run stopped between harvests has them in its checkpoint and summary."""
        for effect in self.effect_list:
            effect.settle()

    # -- the end ------------------------------------------------------------------------
    def finish(self, status: str = "completed") -> dict:
        """The summary (summary.json), after the end's frame; a run that stopped reports the
        error that stopped it, the others as warnings."""
        try:                                  # (completed: heat/gran's flux histories still filling)
            self.settle()
        except Exception as err:              # the error that stopped the run is the one to report
            if status == "completed":
                raise
            print(f"warning: the collisions since the last harvest are not in the log ({type(err).__name__}: {err})")
        if status == "completed" and self.frame_step != self.steps:
            self.write_frame()                # the end's state in history.csv and the VTK series
        for effect in self.effect_list:      # (the fluid: its last advance, if it runs beside the DEM)
            try:
                effect.flush()
            except Exception as err:
                if status == "completed":
                    raise
                print(f"warning: {type(err).__name__} at the end of a run that stopped: {err}")
        self.progress.of_run(self.t, self.totals, force=True)
        end_totals(self.totals, self.scene)
        summary = dict(self.totals, status=status, time=self.t, steps=self.steps, step=self.dem.step,
                       groups=list(self.ctx.known.names))
        for effect in self.effect_list:
            effect.finish(summary, status)
        write_atomic(self.out / "summary.json", json.dumps(summary, indent=1))
        for effect in self.effect_list:
            effect.close()
        broken = [e.failure for e in self.effect_list if e.failure]
        if broken:                            # (the results are on disk: now exit 3, no exit 0)
            raise InvariantBroken("; ".join(broken))
        return summary
