"""Probes: the mean particle temperature in named regions of the scene's ``[output] probes``
(``NAME = [xmin, xmax, ymin, ymax, zmin, zmax]`` [m]; a layer at a depth is a thin box across
the bed), written to ``OUT/probes.csv``: ``time`` [s] and one column per probe [K], at every
frame of the run and at the frozen stage's rows (``pyhost.frozen``). Present only when a scene
names probes.

A probe's value is the heat-capacity-weighted mean sum(C T) / sum(C) of the particles whose
centres lie in its region (the region's bounds included), its heat content per capacity as a
thermocouple among equal beads reads their mean; NaN when no centre is in it.
"""
from __future__ import annotations

import numpy as np

from pyhost.effects import Effect
from pyhost.output import CsvLog


def probe_means(regions: dict, x, T, C) -> list[float]:
    """Each region's sum(C T) / sum(C) [K] over the particles of centres ``x`` (n, 3) [m] in
    it, temperatures ``T`` [K], capacities ``C`` [J/K]; NaN where none is in it."""
    x, T, C = np.asarray(x, float).reshape(-1, 3), np.asarray(T, float), np.asarray(C, float)
    out = []
    for box in regions.values():
        lo, hi = np.asarray(box[0::2], float), np.asarray(box[1::2], float)
        inside = np.all((x >= lo) & (x <= hi), axis=1)
        weight = C[inside].sum()
        out.append(float((C[inside] * T[inside]).sum() / weight) if weight > 0 else float("nan"))
    return out


class Probes(Effect):
    """``regions``: the scene's probes, by name (their order is the file's columns')."""

    def __init__(self, loop):
        super().__init__(loop)
        self.regions = dict(loop.scene.output.probes)
        self.log = CsvLog(loop.out / "probes.csv", ("time",) + tuple(self.regions), loop.logs.get("probes"))

    @classmethod
    def build(cls, ctx):
        return cls(ctx) if ctx.scene.output.probes else None

    def write(self, t: float, x, T, C) -> None:
        """One row at time ``t`` [s] from the particles' centres, temperatures and capacities."""
        self.log.write([(t, *probe_means(self.regions, x, T, C))])

    def frame(self) -> None:
        loop = self.loop
        atoms = loop.dem.atoms(True)
        loop.track_particles(atoms)
        self.write(loop.t, atoms.x, atoms.T, loop.C)

    def state(self) -> tuple[dict, dict]:
        return dict(logs=dict(probes=self.log.mark())), {}

    def close(self) -> None:
        self.log.close()
