"""Engine bridge costs, printed (no asserts): run after ``tools/setup.sh --engines``.

    .venv/bin/python tools/bench_engines.py [--particles 1000] [--repeat 200]

Fluid (pyhost.engines.openfoam.FluidSolver, named pipes):
  - exchange only: a request answered without fluid work (FIELDS) and the particle
    look-up (LOCATE: positions out; cell, U, grad p back), per coupling step;
  - a whole coupling step (look-up, drag, per-cell fields out, one fluid step) against the
    fluid step alone, serial and with mpirun -np 2.
LIGGGHTS (pyhost.engines.liggghts.Liggghts, in process):
  - a run chunk (run N pre no post no), a contact list read, the forked trial of a command.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pyhost.engines.fluid_case import box_case  # noqa: E402
from pyhost.engines.liggghts import Liggghts, granular_box  # noqa: E402
from pyhost.engines.openfoam import FluidSolver  # noqa: E402


def per_call(fn, repeat: int) -> float:
    """Median wall time of one call (s) over ``repeat`` calls after two warm-ups."""
    fn(), fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def bench_fluid(workdir: Path, particles: int, repeat: int, nprocs: int) -> None:
    cells = (20, 20, 20)
    case = box_case(workdir / f"fluid-np{nprocs}", lo=(0, 0, 0), hi=(0.1, 0.1, 0.1), cells=cells,
                    boundaries={f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")},
                    rho=1.2, nu=1.5e-5, dt=1e-4, nprocs=nprocs)
    rng = np.random.default_rng(10007)
    x = rng.uniform(0.001, 0.099, (particles, 3))
    v = rng.normal(0.0, 0.1, (particles, 3))
    with FluidSolver(case, nprocs=nprocs, drag="difelice") as fluid:
        fields = per_call(fluid.fields, repeat)
        locate = per_call(lambda: fluid.locate(x), repeat)
        step = per_call(lambda: fluid.couple(x, v, 1e-3, 1e-4), repeat)
        fluid.particle_forces(x, v, 1e-3)
        advance = per_call(lambda: fluid.advance(1e-4), repeat)
    n = int(np.prod(cells))
    print(f"fluid np={nprocs}, {n} cells, {particles} particles:")
    print(f"  exchange without fluid work (FIELDS, {n} p + U back): {fields * 1e3:8.3f} ms")
    print(f"  particle look-up (LOCATE: x out; cell, U, grad p back): {locate * 1e3:8.3f} ms")
    print(f"  fluid step alone (ADVANCE, cell fields out):          {advance * 1e3:8.3f} ms")
    print(f"  whole coupling step (couple):                         {step * 1e3:8.3f} ms")
    print(f"  => host-side exchange and drag per coupling step:     "
          f"{(step - advance) * 1e3:8.3f} ms")


def bench_liggghts(workdir: Path, repeat: int) -> None:
    with Liggghts(workdir / "dem") as dem:
        dem.commands(granular_box((0, 0, 0), (0.02, 0.02, 0.02), youngs=5e6, poisson=0.3,
                                  restitution=0.9, friction=0.5, skin=5e-4, dt=1e-6))
        dem.commands("""
            lattice sc 0.00199
            region fill block 0.001 0.019 0.001 0.019 0.001 0.019 units box
            create_atoms 1 region fill
            set group all diameter 0.002 density 2500
            fix integrate all nve/sphere
        """)
        dem.add_pair_contacts()
        dem.run(0)
        run1 = per_call(lambda: dem.run(1), repeat)
        contacts = per_call(dem.pair_contacts, repeat)
        tried = per_call(lambda: dem.command("variable dummy equal 1"), 20)
        n, nc = dem.natoms, len(dem.pair_contacts())
    print(f"LIGGGHTS, {n} particles, {nc} contacts:")
    print(f"  run chunk of 1 step (pre no post no):  {run1 * 1e3:8.3f} ms")
    print(f"  pair contact list read:                {contacts * 1e3:8.3f} ms")
    print(f"  command with its forked trial:         {tried * 1e3:8.3f} ms")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=200)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-engines-") as tmp:
        bench_liggghts(Path(tmp), args.repeat)
        for nprocs in (1, 2):
            bench_fluid(Path(tmp), args.particles, args.repeat, nprocs)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
