"""Measures the cost of gas-particle convection: the same small bubbling bed (400 aluminium
beads of 1 mm, air at 1.5 m/s, collision heat model A) run once without and once with
``[effects] convection = "gunn"`` (gas energy equation + exchange every coupling), and the
ratio of their wall times. One run each: the machine's noise is in the figure.

Run: .venv/bin/python tools/convection_cost.py [--end 0.02]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SCENE = """
[effects]
fluid = true
contact_heat = "A"
convection = "{convection}"

[materials.aluminium]
density = 2700.0
youngs_modulus = 70e9
poisson_ratio = 0.33
yield_stress = 100e6
heat_capacity = 900.0
conductivity = 200.0
dem = {{ youngs_modulus = 5e6, restitution = 0.9, poisson_ratio = 0.33, friction = 0.3 }}

[[particles]]
material = "aluminium"
count = 400
radius = 0.5e-3
temperature = 300.0
region = [0.0, 0.02, 0.0, 0.004, 0.0, 0.012]

{walls}

[domain]
box = [0.0, 0.02, 0.0, 0.004, 0.0, 0.06]

[fluid]
inlet_velocity = 1.5
plenum = 0.004
cells = [5, 1, 16]
temperature = 400.0

[time]
dem_step = 4e-6
end = {end}
sample_every = 5
couple_every = 25

[output]
every = 0.005
vtk = false
pictures = false
"""


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--end", type=float, default=0.02, help="simulated time of each run [s]")
    args = p.parse_args()
    walls = "\n".join(f'[[walls]]\nplane = "{w}"\nmaterial = "aluminium"' for w in ("zlo", "xlo", "xhi", "ylo", "yhi"))
    times = {}
    with tempfile.TemporaryDirectory() as tmp:
        for convection in ("none", "gunn"):
            folder = Path(tmp) / convection
            folder.mkdir()
            (folder / "case.toml").write_text(SCENE.format(convection=convection, end=args.end, walls=walls))
            start = time.perf_counter()
            r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder)], cwd=ROOT,
                               capture_output=True, text=True)
            times[convection] = time.perf_counter() - start
            if r.returncode != 0:
                print(r.stdout[-2000:], r.stderr[-2000:])
                return 1
            print(f"convection = {convection!r}: {times[convection]:.2f} s wall time for {args.end:g} s simulated")
    print(f"cost of convection: {times['gunn'] / times['none']:.3f} x the run without it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
