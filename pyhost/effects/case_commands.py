"""A CFDEM case's own LIGGGHTS commands between coupling steps (its constant/liggghtsCommands,
``pyhost.engines.cfdem_commands``): each run where CFDEM runs it, after the coupling step's
DEM steps and before the fluid gets the particles, as CFDEM's coupling does. CFDEM's
packedBedTemp holds its bed at 600 K this way (``set region total property/atom Temp 600``
at every coupling step); its ErgunTestMPI and settlingTestMPI write LIGGGHTS restarts at the
fluid's write times. What a command changes of the particles' temperatures is the energy
balance's ``energy_set_by_script``. Present when the case's file has such commands.
Its total: ``case_commands_run``, the commands run. SI units."""
from __future__ import annotations

import math

import numpy as np

from pyhost.effects import Effect, by_id
from pyhost.engines.cfdem_commands import SMALL, read_commands, write_times
from pyhost.engines.liggghts.script import Command


class CaseCommands(Effect):
    """``commands``: the case's (``read_commands``); ``control``: the fluid case's controlDict
    (its write times); ``start`` [s]: the time the fluid starts from; ``driven`` [s]: the
    coupled time the case runs (its last coupling step)."""

    TOTALS = dict(case_commands_run=0)

    @classmethod
    def build(cls, loop):
        """The effect for the loop's scene, a user's fluid case, or None: no command besides the
        coupled run in its liggghtsCommands (or none: not a CFDEM case, no fluid case)."""
        if loop.fluid is None or not loop.scene.fluid.case:
            return None
        case = loop.scene.folder / loop.scene.fluid.case
        commands = read_commands(case, loop.scene.time.couple_every)
        if not commands:
            return None
        from foamlib import FoamFile    # (here: foamlib costs 0.1-0.2 s, and every run imports this module's TOTALS)
        from pyhost.engines.fluid_case import start_time

        control = FoamFile(case / "system" / "controlDict").as_dict()
        start = start_time(case)[0]
        driven = loop.driven if loop.driven is not None else float(control["endTime"]) - start
        return cls(loop, commands, control, start, driven)

    def __init__(self, loop, commands, control: dict, start: float, driven: float):
        super().__init__(loop)
        self.commands = commands
        self.control = control
        self.start_time = start
        self.interval = loop.scene.time.couple_every * loop.dem.dt
        self.last = math.floor((driven + SMALL) / loop.dem.dt / loop.scene.time.couple_every)    # CFDEM's lastCouplingStep
        self.said = set()              # commands said at their first run

    def couple(self) -> None:
        loop = self.loop
        k = loop.steps // loop.every["couple"]    # CFDEM's coupling step, from 1
        t0, t1 = self.start_time + (k - 1) * self.interval, self.start_time + k * self.interval
        wrote = write_times(self.control, self.start_time, t0, t1) > 0 if any(
            c.when == "write" for c in self.commands) else False
        writes = write_times(self.control, self.start_time, self.start_time, t1) if wrote else 0
        due = [c for c in self.commands
               if c.due(k, self.last, writes, wrote, self.start_time, loop.dem.dt, loop.every["couple"])]
        if not due:
            return
        before = self.temperatures()
        for c in due:                      # (its folders made; the bridge tries a command the first time only)
            cmd = Command(c.command(t1), c.file, c.line)
            loop.dem.commands([cmd])
            if c.text not in self.said:
                self.said.add(c.text)
                print(f"fluid time {t1:g} s: {c.where}: '{cmd.text}' (the case's liggghtsCommands, as CFDEM runs them; "
                      "said at the first run of each)")
        loop.totals["case_commands_run"] += len(due)
        if before is not None:
            self.count_set(before)

    def temperatures(self):
        """(ids, T, m c) of the particles now, copied; None without particle temperatures."""
        loop = self.loop
        if loop.find("balance") is None:
            return None
        atoms = loop.dem.atoms(True)
        return atoms.id.copy(), atoms.T.copy(), atoms.mass * loop.capacity[loop.materials_of(atoms.type)]

    def count_set(self, before) -> None:
        """What the commands changed of the particles' temperatures (those there before and
        after) [J] goes to the energy balance as set by the script, at their heat capacities
        before (a change of mass is the balance's own term)."""
        ids, T, C = before
        atoms = self.loop.dem.atoms(True)
        T_after = by_id(atoms.id, atoms.T, ids, missing=np.nan)
        kept = ~np.isnan(T_after)
        self.loop.totals["energy_set_by_script"] += float(np.sum(C[kept] * (T_after[kept] - T[kept])))
        self.loop.track_particles(atoms)
