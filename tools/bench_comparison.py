"""What side models cost: time per collision of each heat model through the host's call
(``plugins.heat.batch.evaluate``, fast path), on the hot-cold bed's material.

Collisions: N particle pairs of the bed's 1 mm aluminium beads (cases/hot-cold-bed), impact
speeds log-uniform in 0.01-1 m/s, one material pair; best of ``--repeats`` runs, one core.
Prints each model's time per collision and the extra cost of running every other
registered model as side columns beside A.

Run: .venv/bin/python tools/bench_comparison.py [--n 200000] [--repeats 5]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from plugins.heat import MODEL_NAMES
from plugins.heat.batch import evaluate, side_heat
from pyhost.scene import load_scene


def best_time(call, repeats):
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200_000, help="collisions per run")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    scene = load_scene("cases/hot-cold-bed/case.toml")
    mats = list(scene.materials.values())
    rng = np.random.default_rng(0)
    n = args.n
    zeros, R = np.zeros(n, int), np.full(n, scene.particles[0].radius)
    v0, dT = np.exp(rng.uniform(np.log(0.01), 0.0, n)), np.ones(n)
    call = lambda m: evaluate(m, "fast", mats, zeros, zeros, R, R, v0, dT)
    for m in MODEL_NAMES:                       # build tables and trajectories outside the timing
        call(m)
    print(f"{n} collisions, best of {args.repeats}, fast path, aluminium pairs (R = {R[0]:g} m)")
    print(f"{'model':>20} {'us per collision':>17}")
    times = {}
    for m in MODEL_NAMES:
        times[m] = best_time(lambda: call(m), args.repeats) / n
        print(f"{m:>20} {times[m] * 1e6:17.3f}")
    others = [m for m in MODEL_NAMES if m != "A"]
    side = best_time(lambda: side_heat(others, "fast", mats, zeros, zeros, R, R, v0, dT), args.repeats) / n
    print(f"A with {', '.join(others)} as side columns: {(times['A'] + side) * 1e6:.3f} us per collision "
          f"({(times['A'] + side) / times['A']:.1f} x A alone)")


if __name__ == "__main__":
    main()
