"""Benchmark of the heat plugin's two paths (issue: collisions per second, error, exact cost).

Prints, for the paper's pair and each model:
- the exact path's time per collision (median and 90th percentile over speeds spanning all
  regimes), single core;
- the fast path's collisions per second on one core for 2e6 collisions (best and median of
  repeats), asking for e and Q (what a simulation needs), for e, t_coll, delta_max and Q, and
  for every output;
- the fast path's maximum relative error against the exact path for e, t_coll, delta_max
  and Q over v0/v_y log-uniform in [1e-3, 1e5] plus both regime onsets;
- the time to build a model's tables without a cache.

Run: .venv/bin/python tools/bench_fast.py [--samples 2000] [--n 2000000]
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

import numpy as np

from plugins.heat import MODELS, Pair, collide
from plugins.heat import fast

KEYS = ("e", "t_coll", "delta_max", "Q")


def exact_timing(pair, model, speeds):
    times = []
    for v in speeds:
        t = time.perf_counter()
        collide(v, pair, model)
        times.append(time.perf_counter() - t)
    return np.median(times), np.percentile(times, 90)


def throughput(pair, model, n, outputs, repeats=5):
    rng = np.random.default_rng(0)
    v0 = pair.v_y * np.exp(rng.uniform(np.log(1e-3), np.log(1e5), n))
    rates = []
    for _ in range(repeats):
        t = time.perf_counter()
        fast.collide_fast(v0, pair, model, outputs=outputs)
        rates.append(n / (time.perf_counter() - t))
    return max(rates), statistics.median(rates), min(rates)


def max_error(pair, model, samples):
    rng = np.random.default_rng(1)
    v_y, v_p = pair.onset_speeds()
    v0 = np.concatenate([pair.v_y * np.exp(rng.uniform(np.log(1e-3), np.log(1e5), samples)),
                         [v * f for v in (v_y, v_p) for f in (1 - 1e-9, 1 + 1e-9)]])
    out = fast.collide_fast(v0, pair, model, outputs=KEYS)
    worst = {k: 0.0 for k in KEYS}
    for j, v in enumerate(v0):
        c = collide(v, pair, model)
        for k in KEYS:
            worst[k] = max(worst[k], abs(out[k][j] / getattr(c, k) - 1))
    return worst


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=2000, help="collisions compared with the exact path")
    ap.add_argument("--n", type=int, default=2_000_000, help="collisions per fast-path call")
    args = ap.parse_args()
    pair = Pair()
    speeds = pair.v_y * np.geomspace(1e-3, 1e5, 60)
    print(f"paper's pair: v_y = {pair.v_y:.6g} m/s, v_p = {pair.onset_speeds()[1]:.6g} m/s")

    with tempfile.TemporaryDirectory() as tmp:
        os.environ["COLLHEAT_CACHE"] = tmp
        fast.table.cache_clear()
        build = {}
        for model in sorted(MODELS):
            t = time.perf_counter()
            fast.table(model, pair.b1, pair.b2, float(pair.log_constant))
            build[model] = time.perf_counter() - t

    print(f"\n{'model':>5} | {'exact median':>12} {'p90':>8} | {'table build':>11} | "
          f"fast coll/s best (median, worst): {'e,Q':>24} {'e,t_coll,delta_max,Q':>24} {'all 15 outputs':>24}")
    for model in sorted(MODELS):
        med, p90 = exact_timing(pair, model, speeds)
        cells = []
        for outputs in (("e", "Q"), KEYS, fast.exact.OUTPUT_KEYS):
            best, median, worst = throughput(pair, model, args.n, outputs)
            cells.append(f"{best:9.3g} ({median:.3g}, {worst:.3g})")
        print(f"{model:>5} | {med * 1e3:9.2f} ms {p90 * 1e3:5.2f} ms | {build[model]:9.1f} s | "
              + " ".join(f"{c:>24}" for c in cells))

    print(f"\nmax relative error of the fast path against the exact path "
          f"({args.samples} collisions, v0/v_y in [1e-3, 1e5] log-uniform, plus the onsets):")
    for model in sorted(MODELS):
        worst = max_error(pair, model, args.samples)
        print(f"{model:>5} | " + "  ".join(f"{k} {v:.1e}" for k, v in worst.items()))


if __name__ == "__main__":
    main()
