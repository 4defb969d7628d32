"""``python -m pyhost demo``: the three contact models compared over impact speed.

Prints a table and writes a PNG of restitution, collision duration and conducted heat
against impact speed for the paper's parameter set (particle-particle), with the regime
boundaries v_y and v_p marked and the unphysical ranges (e > 1 or delta_f < 0) shaded.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

HELP = "compare models A, B, C over impact speed (paper's parameter set): table and plot"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder")
    p.add_argument("--vmin", type=float, default=1e-3, help="lowest impact speed [m/s]")
    p.add_argument("--vmax", type=float, default=20.0, help="highest impact speed [m/s]")
    p.add_argument("--points", type=int, default=200, help="speeds on a log scale")


def run(args) -> int:
    from plugins.heat import MODELS, Pair, collide
    from plugins.heat.fast import collide_fast

    if not 0 < args.vmin < args.vmax:
        raise ValueError(f"need 0 < --vmin < --vmax, got {args.vmin}, {args.vmax}")
    pair = Pair()
    v_y, v_p = pair.onset_speeds()
    print(f"Paper's pair (R = 2 mm, E* = 100 GPa, Y = 300 MPa, b1 = 1.1, b2 = 2.8): "
          f"v_y = {v_y:.6g} m/s, v_p = {v_p:.6g} m/s")
    print(f"{'model':>5} {'v0 [m/s]':>9} {'regime':>16} {'e':>8} {'t_coll [us]':>11} "
          f"{'Q [mJ]':>9} {'Q eq31/33':>9}  flags")
    for model in sorted(MODELS):
        for v in (0.001, 0.01, 0.1, 1.0, 10.0):
            c = collide(v, pair, model)
            print(f"{model:>5} {v:9.3g} {c.regime:>16} {c.e:8.4f} {c.t_coll * 1e6:11.3f} "
                  f"{c.Q * 1e3:9.4g} {c.Q_closed_form * 1e3:9.4g}  {','.join(c.flags)}")

    v = np.geomspace(args.vmin, args.vmax, args.points)
    curves = {m: collide_fast(v, pair, m) for m in sorted(MODELS)}
    path = plot(v, curves, v_y, v_p, args.out)
    print(f"plot: {path}")
    return 0


def plot(v, curves, v_y, v_p, out: Path) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    panels = (("e", "coefficient of restitution e [-]", 1.0),
              ("t_coll", "collision duration [us]", 1e6),
              ("Q", "heat conducted Q [mJ]", 1e3))
    for ax, (key, label, scale) in zip(axes, panels):
        for model, c in curves.items():
            line, = ax.plot(v, c[key] * scale, label=f"model {model}")
            bad = c["flags"] != 0
            if bad.any():
                ax.plot(v[bad], c[key][bad] * scale, ls="none", marker=".", ms=3,
                        color=line.get_color())
                ax.axvspan(v[bad].min(), v[bad].max(), color=line.get_color(), alpha=0.08)
        for x, name in ((v_y, "$v_y$"), (v_p, "$v_p$")):
            ax.axvline(x, color="k", ls=":", lw=1)
            ax.text(x, 0.98, name, transform=ax.get_xaxis_transform(), ha="right", va="top")
        ax.set_xscale("log")
        if key != "e":
            ax.set_yscale("log")
        ax.set_xlabel("impact speed $v_0$ [m/s]")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(title="shaded/dotted: unphysical (e > 1 or $\\delta_f$ < 0)", fontsize=8,
                   title_fontsize=8)
    fig.suptitle("Kosinski et al. (2014) contact models, particle-particle, paper's parameter set")
    fig.tight_layout()
    path = out / "models.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
