"""What accuracy costs in time: every way of evaluating a collision, its error against the
tightest exact result and its cost per collision, measured in one run on this machine.

Collisions: the paper's pair, models A, B, C, v0/v_y log-spaced over [1e-2, 1e5] (all three
regimes) plus both onsets at +-1e-6 (fixed set). Reference: the exact path at rtol 1e-12.
Paths:
- exact at rtol 1e-3 .. 1e-12 (one collision per call);
- fast tables at node spacings x0.25 .. x4 of the defaults (lookup of e, t_coll, Q);
- closed forms: eqs. (31)/(32) with Hertz a_max below v_y; above, eq. (33) with Johnson's
  closed-form a_max, t_max and t_r (eqs. 15, 29) and Johnson's e (eq. 28);
- fitted relations (plugins.heat.fit).
Errors: max and median relative error of e (physical collisions only), t_coll and Q.
Cost: seconds per collision, median and spread (min-max) over --repeats timings;
vectorised paths are timed on 1e6 collisions.

Run: .venv/bin/python tools/bench_accuracy.py [--out docs] [--repeats 5] [--n 40]
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from plugins.heat import Pair, exact, fast
from plugins.heat import fit as F

MODELS = F.FITTED
QUANT = ("e", "t_coll", "Q")
RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)
SPACING_FACTORS = (4.0, 2.0, 1.0, 0.5, 0.25)


def speeds(n):
    pair = Pair()
    v_y, v_p = pair.onset_speeds()
    v = np.geomspace(1e-2, 1e5, n)
    return np.concatenate([v, [f for x in (1.0, v_p / v_y) for f in (x * (1 - 1e-6), x * (1 + 1e-6))]])


def exact_dimless(model, v_hat, rtol, pair):
    b1, b2, c = float(pair.b1), float(pair.b2), float(pair.log_constant)
    out = {q: np.empty(v_hat.size) for q in QUANT}
    phys = np.empty(v_hat.size, bool)
    for j, v in enumerate(v_hat):
        d = exact.solve(model, float(v), b1, b2, c, rtol)
        out["e"][j], out["t_coll"][j], out["Q"][j] = d["v1"] / v, d["t_max"] + d["t_r"], d["Q"]
        phys[j] = not exact.flags_for(d["x_max"], d["s_r"], d["v1"] / v)
    return out, phys


def fast_dimless(model, v_hat, pair, spacing):
    tab = fast.table(model, float(pair.b1), float(pair.b2), float(pair.log_constant), spacing)
    L = tab.lookup(v_hat, [2, 3, 4])
    return {"t_coll": np.exp(L[2]), "e": np.exp(L[3]), "Q": np.exp(L[4])}


def closed_dimless(model, v_hat, pair):
    """Eqs. (31), (32) (Hertz, printed 0.87 and 2.86) below v_y; eq. (33) with Johnson's
    closed forms above (the model argument is ignored: one closed form for all)."""
    v = np.asarray(v_hat, float)
    # eq. (32) in units of t_y: 2.86 (m*^2/(E*^2 R* v0))^(1/5) = (2.86/2.8683) 2 K v_hat^(-1/5)
    t_el = (2.86 / 2.8683) * 2.0 * F.K_HERTZ * v**-0.2
    Q_el = 0.87 * 0.5 * math.sqrt(math.pi) * v**0.8 * np.sqrt(t_el)
    sk = F.skeleton("B", v, float(pair.b1), float(pair.b2), kappa=(0.88, 0.0, 0.0))
    el = v <= 1.0
    return {"e": np.where(el, 1.0, np.minimum(sk["e"], 1.0)), "t_coll": np.where(el, t_el, sk["t_coll"]),
            "Q": np.where(el, Q_el, sk["Q"])}


def fit_dimless(model, v_hat, pair):
    return F.dimensionless(model, v_hat, float(pair.b1), float(pair.b2), float(pair.log_constant))


def errors(got, ref, phys):
    out = {}
    for q in QUANT:
        r = np.concatenate([np.abs(got[m][q] / ref[m][q] - 1)[phys[m] if q == "e" else slice(None)]
                            for m in MODELS])
        out[q] = (float(r.max()), float(np.median(r)))
    return out


def timed(f, repeats):
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), float(min(ts)), float(max(ts))


def run(out: Path | None = None, repeats: int = 5, n: int = 40, n_vec: int = 1_000_000) -> list[dict]:
    pair = Pair()
    v_hat = speeds(n)
    ncoll = v_hat.size * len(MODELS)
    ref, phys = {}, {}
    for m in MODELS:
        ref[m], phys[m] = exact_dimless(m, v_hat, 1e-12, pair)
    rows = []
    print(f"{ncoll} collisions (paper's pair, models A, B, C, v0/v_y in [1e-2, 1e5] + onsets); "
          f"reference: exact at rtol 1e-12; {repeats} timings each")
    for rtol in RTOLS + (1e-12,):
        got = {m: exact_dimless(m, v_hat, rtol, pair)[0] for m in MODELS}
        reps = max(1, min(repeats, 3))
        med, lo, hi = timed(lambda: [exact_dimless(m, v_hat, rtol, pair) for m in MODELS], reps)
        rows.append(dict(path="exact", setting=f"rtol {rtol:.0e}", cost=med / ncoll, lo=lo / ncoll,
                         hi=hi / ncoll, **_flat(errors(got, ref, phys))))
    v_big = np.exp(np.random.default_rng(0).uniform(np.log(1e-2), np.log(1e5), n_vec))
    for factor in SPACING_FACTORS:
        sp = {m: (fast.H_SMOOTH if m == "B" else fast.H) * factor for m in MODELS}
        got = {m: fast_dimless(m, v_hat, pair, sp[m]) for m in MODELS}
        med, lo, hi = timed(lambda: [fast_dimless(m, v_big, pair, sp[m]) for m in MODELS], repeats)
        rows.append(dict(path="fast", setting=f"spacing x{factor:g} (h {fast.H * factor:g}, B {fast.H_SMOOTH * factor:g})",
                         cost=med / (3 * n_vec), lo=lo / (3 * n_vec), hi=hi / (3 * n_vec),
                         **_flat(errors(got, ref, phys))))
    for name, f in (("closed forms", closed_dimless), ("fit", fit_dimless)):
        got = {m: f(m, v_hat, pair) for m in MODELS}
        med, lo, hi = timed(lambda: [f(m, v_big, pair) for m in MODELS], repeats)
        rows.append(dict(path=name, setting="eqs. 31-33" if name != "fit" else "plugins.heat.fit",
                         cost=med / (3 * n_vec), lo=lo / (3 * n_vec), hi=hi / (3 * n_vec),
                         **_flat(errors(got, ref, phys))))
    print_table(rows)
    if out is not None:
        write(out, rows)
    return rows


def _flat(err):
    return {f"{q}_{s}": err[q][i] for q in QUANT for i, s in enumerate(("max", "median"))}


def print_table(rows):
    print("\n| path | setting | cost per collision [s] (min-max) | " +
          " | ".join(f"{q} max / median" for q in QUANT) + " |")
    print("|---|---|---|" + "---|" * len(QUANT))
    for r in rows:
        print(f"| {r['path']} | {r['setting']} | {r['cost']:.2e} ({r['lo']:.2e}-{r['hi']:.2e}) | " +
              " | ".join(f"{r[q + '_max']:.1e} / {r[q + '_median']:.1e}" for q in QUANT) + " |")


def write(out: Path, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    keys = ["path", "setting", "cost", "lo", "hi"] + [f"{q}_{s}" for q in QUANT for s in ("max", "median")]
    with open(out / "accuracy-cost.csv", "w") as fh:
        fh.write(",".join(keys) + "\n")
        for r in rows:
            fh.write(",".join(str(r[k]) for k in keys) + "\n")
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), sharey=True)
    marker = {"exact": "o", "fast": "s", "closed forms": "^", "fit": "D"}
    for ax, q in zip(axes, QUANT):
        for path in marker:
            sel = [r for r in rows if r["path"] == path]
            x = np.array([r["cost"] for r in sel])
            y = np.array([max(r[f"{q}_max"], 1e-17) for r in sel])
            xerr = np.array([[r["cost"] - r["lo"] for r in sel], [r["hi"] - r["cost"] for r in sel]])
            ax.errorbar(x, y, xerr=xerr, marker=marker[path], ls="-" if len(sel) > 1 else "none",
                        label=path, ms=5, capsize=2)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cost per collision [s] (one core)")
        ax.set_title(f"{q}: max relative error vs cost", fontsize=10)
        ax.grid(True, which="both", alpha=0.25)
    axes[0].set_ylabel("max relative error against exact (rtol 1e-12)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "accuracy-cost.png", dpi=80)
    plt.close(fig)
    print(f"\nwrote {out / 'accuracy-cost.csv'} and {out / 'accuracy-cost.png'}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("docs"), help="folder for the CSV and the PNG")
    ap.add_argument("--repeats", type=int, default=5, help="timings per path")
    ap.add_argument("--n", type=int, default=40, help="speeds per model in the fixed set")
    args = ap.parse_args()
    run(args.out, args.repeats, args.n)


if __name__ == "__main__":
    main()
