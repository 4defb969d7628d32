"""``python -m pyhost dpmfoam CASE OUT``: a case of OpenFOAM's DPMFoam (its gas, its kinematic
cloud of colliding particles) written as a case of this host (pyhost/engines/dpmfoam_case.py),
to run with ``python -m pyhost run OUT`` once case.toml names the particles' real material."""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "write a DPMFoam case (OpenFOAM's lagrangian/DPMFoam) as a case of this host"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("case", type=Path, help="the DPMFoam case folder (0/, constant/, system/); only read")
    p.add_argument("out", type=Path, help="the new folder: CFD/, DEM/, case.toml")
    p.add_argument("--impact-speed", type=float, default=1.0,
                   help="speed [m/s] of the collision the DEM step resolves with the case's "
                        "collisionResolutionSteps")
    p.add_argument("--hot-below", type=float, metavar="Z",
                   help="height z [m] below which the beads start hot (atom type 1; the others type 2); "
                        "DPMFoam's beads have no temperature (default: all cold)")
    p.add_argument("--temperatures", type=float, nargs=2, default=(400.0, 300.0), metavar=("HOT", "COLD"),
                   help="the beads' initial temperatures [K]")


def run(args) -> int:
    from pyhost.engines.dpmfoam_case import convert

    if not args.impact_speed > 0:
        raise ValueError(f"--impact-speed: must be > 0 m/s, got {args.impact_speed}")
    done = convert(args.case, args.out, args.impact_speed, args.hot_below, tuple(args.temperatures))
    walls = ", ".join(f"{p} {e:.4f}" for p, e in done["walls"].items())
    print(f"{args.out}: {done['particles']} particles; DEM step {done['dt']:.4g} s, {done['couple_every']} per gas "
          f"step of {done['deltaT']:g} s; restitution {done['e_pair']:.4f} between particles, {walls} at the "
          f"walls; drag {done['drag']}"
          + (f"; patches typed patch for the gas: {', '.join(done['retyped'])}" if done["retyped"] else "")
          + (f"; {done['hot']} beads start at {args.temperatures[0]:g} K, the others at {args.temperatures[1]:g} K"
             if args.hot_below is not None else f"; the beads start at {args.temperatures[1]:g} K"))
    print(f"next: give the particles' real material in {args.out / 'case.toml'}, then "
          f"python -m pyhost run {args.out}")
    return 0
