#!/usr/bin/env python3
"""What recording contact events inside LIGGGHTS costs: a pile of spheres poured into a box
(plain LIGGGHTS through the bridge, one run of N steps) against the same run with the
event recorder (plugins/liggghts/contact_events.cpp) attached, alternated, twice each,
in one process. Prints wall times and their ratio, and the events recorded.

    .venv/bin/python tools/bench_events.py [--particles 5000] [--steps 4000]

The machine is shared: compare the ratio, measured in one run, with nothing else running.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pyhost.collisions import WALL_BASE  # noqa: E402
from pyhost.engines.events import ContactEvents  # noqa: E402
from pyhost.engines.liggghts import Liggghts, granular_box  # noqa: E402


def pile(workdir, n: int, events: bool):
    side = 0.002 * (n / 0.3) ** (1 / 3) * 1.6          # a box the particles fill to about a third
    lg = Liggghts(workdir)
    lg.commands(granular_box((0, 0, 0), (side, side, 2 * side), youngs=5e6, poisson=0.3, restitution=0.8,
                             friction=0.5, skin=5e-4, dt=1e-5))
    lg.commands(f"""
        fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
        fix gravi all gravity 9.81 vector 0 0 -1
        region fill block 0.001 {side - 0.001} 0.001 {side - 0.001} 0.001 {2 * side - 0.001} units box
        fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
        fix pdd all particledistribution/discrete 15485867 1 pts 1.0
        fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 -0.5 insert_every once overlapcheck yes all_in yes particles_in_region {n} region fill
        fix integrate all nve/sphere
    """)
    ev = None
    if events:
        ev = ContactEvents(lg)
        ev.primitives(["floor"], [WALL_BASE])
    lg.run(1)
    return lg, ev


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--particles", type=int, default=5000)
    ap.add_argument("--steps", type=int, default=4000)
    args = ap.parse_args(argv)
    times = {False: [], True: []}
    for rep in range(2):
        for events in (False, True):
            with tempfile.TemporaryDirectory() as tmp:
                lg, ev = pile(tmp, args.particles, events)
                start = time.perf_counter()
                lg.run(args.steps)
                times[events].append(time.perf_counter() - start)
                if ev is not None:
                    begun, ended = ev.totals()
                    n_events = len(ev.take())
                    ev.close()
                lg.close()
    plain, with_events = min(times[False]), min(times[True])
    print(f"{args.particles} spheres, {args.steps} steps: plain {plain:.2f} s, with events {with_events:.2f} s "
          f"(best of 2 each), ratio {with_events / plain:.3f}; {begun} contacts begun, {ended} ended, "
          f"{n_events} events taken")
    return 0


if __name__ == "__main__":
    sys.exit(main())
