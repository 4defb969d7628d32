"""The DEM of a scene for the coupling loop, on the LIGGGHTS bridge (``pyhost.liggghts``).

Implements what ``pyhost.loop.Coupling`` needs: ``run(steps)``, ``state()`` (positions and
velocities in particle order), ``add_velocity`` and, when the scene has a fluid,
``set_force`` (the fluid's force on each particle, held until the next call). The input is
generated from the validated scene (``pyhost.dem_input``); the bridge tries it in a forked
copy first, so a LIGGGHTS error arrives as ``LiggghtsError`` with LIGGGHTS' own message.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pyhost.dem_input import Particles, input_lines, write_data
from pyhost.failures import particles_lost
from pyhost.liggghts import Liggghts

FLUID_FIX = "fluid"


class SceneDem:
    """LIGGGHTS running a scene's particles (ids 1..N in ``particles`` order)."""

    def __init__(self, scene, particles: Particles, workdir: Path, fluid_force: bool = False):
        workdir = Path(workdir).resolve()
        workdir.mkdir(parents=True, exist_ok=True)
        data = write_data(workdir / "particles.data", scene, particles)
        script = workdir / "in.dem"
        lines = ["atom_modify sort 0 0"] + input_lines(scene, data)
        if fluid_force:
            lines.append(f"fix {FLUID_FIX} all external pf/array 1")
        script.write_text("\n".join(lines) + "\n")
        self.n = len(particles.radius)
        self.scene, self.group, self.before = scene, particles.group, None    # for particles_lost
        self.fluid_force = fluid_force
        self.lmp = Liggghts(workdir)
        self.lmp.file(script)
        self.lmp.run(0)
        if fluid_force:     # run 0 added the fix's array while it was uninitialised memory, and the
            self.lmp.external_force(FLUID_FIX)[:] = 0.0   # first step would integrate that force:
            self.lmp.command("run 0")                     # zero it and set up again
        self._views()

    def _views(self) -> None:
        if self.lmp.nlocal != self.n:
            raise particles_lost(self)
        self.order = np.argsort(self.lmp.atom("id"))        # local index of particle k (id k + 1)
        self.identity = bool(np.all(self.order == np.arange(self.n)))
        self.x, self.v = self.lmp.atom("x"), self.lmp.atom("v")

    def run(self, steps: int) -> None:
        self.before = (self.lmp.step * self.lmp.dt, *(a.copy() for a in self.state()))
        self.lmp.run(int(steps))
        self._views()

    def state(self):
        if self.identity:
            return self.x, self.v
        return self.x[self.order], self.v[self.order]

    def add_velocity(self, index, dv) -> None:
        np.add.at(self.v, self.order[np.asarray(index)], dv)

    def set_force(self, force) -> None:
        """Force [N] on each particle (particle order), applied every step until changed."""
        self.lmp.external_force(FLUID_FIX)[self.order] = force

    def close(self) -> None:
        self.lmp.close()
