"""Does ``python -m pyhost post`` take time linear in the number of dump frames? It wrote the
.pvd index of its VTK series after every frame, so 100,000 frames did not finish in 900 s.

Writes N frames of a small dump (2 spheres that meet once; one file holding every step, as
``dump custom`` with a fixed file name writes it), post-processes them and prints the wall
time per frame for each N: flat means linear. One run, on whatever else the machine runs.

Run: .venv/bin/python tools/bench_post_frames.py [--frames 1000 3000 10000]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FRAME = ("ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 0.01\n0 0.01\n0 0.01\n"
         "ITEM: ATOMS id type x y z vx vy vz radius \n1 1 {x1:.9g} 0.005 0.005 0.1 0 0 0.001\n"
         "2 1 {x2:.9g} 0.005 0.005 -0.1 0 0 0.001\n")
SCENE = """[materials.glass]
types = [1]
temperature = 300.0
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.22
yield_stress = 500e6
heat_capacity = 800.0
conductivity = 1.0
dem = { youngs_modulus = 5e6, restitution = 0.8, poisson_ratio = 0.3 }
"""


def dump(path: Path, frames: int, dt: float) -> None:
    """Two spheres approaching at 0.2 m/s, touching in the middle of the series (no bounce:
    one collision, found from positions)."""
    with open(path, "w") as f:
        for k in range(frames):
            t = (k - frames / 2) * dt
            f.write(FRAME.format(step=k, x1=0.004 + 0.1 * t, x2=0.006 - 0.1 * t))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, nargs="+", default=[1000, 3000, 10000])
    args = ap.parse_args(argv)
    dt = 1e-5
    print(f"{'frames':>8} {'wall s':>8} {'ms per frame':>13}")
    with tempfile.TemporaryDirectory(prefix="collheat-bench-post-") as tmp:
        tmp = Path(tmp)
        (tmp / "scene.toml").write_text(SCENE)
        for n in args.frames:
            dump(tmp / f"d{n}.dump", n, dt)
            start = time.perf_counter()
            r = subprocess.run([sys.executable, "-m", "pyhost", "post", str(tmp / f"d{n}.dump"), "--scene",
                                str(tmp / "scene.toml"), "--dt", str(dt), "--out", str(tmp / f"out{n}"),
                                "--model", "A"], capture_output=True, text=True, cwd=ROOT)
            wall = time.perf_counter() - start
            if r.returncode:
                print(r.stderr[-2000:], file=sys.stderr)
                return 1
            print(f"{n:>8} {wall:>8.1f} {1e3 * wall / n:>13.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
