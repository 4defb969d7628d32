"""``python -m pyhost paper``: the figures of Kosinski et al. (2014), sec. 6, and the ones
the text promises but does not show, as PNG plots and CSV tables.

For the paper's parameter set and impact speeds from --vmin to --vmax (log axis): Figs.
2-9 (t_max, delta_max, r1, delta_r, r2 and r3, R_bar, t_r, r4), then the coefficient of
restitution, the conducted heat Q of A, B and C, Q against the closed forms of eqs. (31) and
(33), and the same for a particle hitting a wall. Every plot marks v_y and v_p and shades
where a model is unphysical (e > 1 or negative residual indentation). Values come from the
fast path (relative error < 1e-8 against the exact path, see README).
"""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "regenerate the paper's figures and the missing ones (PNG + CSV)"

AC_NOTE = "A and C: same compression, a_max, t_coll and Q; they differ only in e"
FIGURES = {
    # name: (title, y label, [(series key, label)], log y, caption note)
    "fig02_compression_duration": ("Fig. 2: compression duration", "t_max [us]",
                                   [("t_max_A", "A (= C)"), ("t_max_B", "B")], True,
                                   "A and C share the compression; B's t_max is flat (eq. 15)"),
    "fig03_max_indentation": ("Fig. 3: maximum indentation", "delta_max [um]",
                              [("delta_max_A", "A (= C)"), ("delta_max_B", "B")], True,
                              "A and C share the compression"),
    "fig04_r1": ("Fig. 4: r1 = delta_max(B)/delta_max(A) (eq. 39)", "r1 [-]",
                 [("r1", "r1")], False, "tends to 1 at high speed"),
    "fig05_residual_deformation": ("Fig. 5: recovery indentation delta_r", "delta_r [um]",
                                   [("delta_r_A", "A (eq. 19)"), ("delta_r_B", "B (eq. 26)")], True,
                                   "C recovers as B (eqs. 34-37)"),
    "fig06_r2_r3": ("Fig. 6: r2 (eq. 41) and r3 (eq. 42 as printed)", "ratio [-]",
                    [("r2", "r2 = delta_r(A)/delta_r(B)"), ("r3", "r3 = R_bar(B)/R_bar(A)")], False,
                    "both tend to b1/b2 = 0.393"),
    "fig07_recovery_radii": ("Fig. 7: effective radius in recovery", "R_bar [mm]",
                             [("R_bar_A", "A (eq. 16)"), ("R_bar_B", "B (eq. 24)")], True, ""),
    "fig08_recovery_duration": ("Fig. 8: recovery duration", "t_r [us]",
                                [("t_r_A", "A (eq. 23)"), ("t_r_B", "B (eq. 29)")], True, ""),
    "fig09_r4": ("Fig. 9: r4 = t_r(A)/t_r(B)", "r4 [-]", [("r4", "r4")], False,
                 "tends to 1 at high speed"),
    "restitution": ("Coefficient of restitution", "e [-]",
                    [("e_A", "A"), ("e_B", "B"), ("e_C", "C"), ("e_johnson", "Johnson (v0/v_y)^-1/4"),
                     ("e_thornton", "Thornton (1997)")], True, "shaded: unphysical ranges"),
    "heat": ("Conducted heat (eq. 3)", "Q [uJ]", [("Q_A", "A (= C)"), ("Q_B", "B")], True, AC_NOTE),
    "heat_closed_forms": ("Q over pi a_max^2 dT t_coll^1/2 / sigma (eqs. 31, 33)", "prefactor [-]",
                          [("kappa_A", "A (= C)"), ("kappa_B", "B")], False,
                          "closed forms: 0.87 (eq. 31), 0.88 (eq. 33); " + AC_NOTE),
    "wall_restitution": ("Wall: coefficient of restitution", "e [-]",
                         [("wall_e_A", "A"), ("wall_e_B", "B"), ("wall_e_C", "C")], True, ""),
    "wall_heat": ("Wall: conducted heat", "Q [uJ]",
                  [("wall_Q_A", "A (= C)"), ("wall_Q_B", "B"), ("wall_Q31_A", "eq. 31, A's a_max, t_coll"),
                   ("wall_Q33_A", "eq. 33, A's a_max, t_coll")], True, AC_NOTE),
}
"""Every figure the command writes: docs/<name>.png and <name>.csv."""

SCALE = dict(t_max=1e6, delta_max=1e6, delta_r=1e6, R_bar=1e3, t_r=1e6, Q=1e6)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, default=Path("docs/figures"), help="output folder")
    p.add_argument("--vmin", type=float, default=1e-3, help="lowest impact speed [m/s]")
    p.add_argument("--vmax", type=float, default=20.0, help="highest impact speed [m/s]")
    p.add_argument("--points", type=int, default=400, help="speeds on a log scale")


def series(v, pair=None, wall=None) -> dict:
    """Every curve of FIGURES at impact speeds v [m/s] (SI, then scaled to the plot units)
    and the bit masks of unphysical collisions (flags_<model>)."""
    import numpy as np

    from plugins.heat import Pair
    from plugins.heat.fast import collide_fast
    from plugins.heat.fit import johnson_e, thornton_e

    pair = Pair() if pair is None else pair
    wall = Pair.wall() if wall is None else wall
    c = {m: collide_fast(v, pair, m) for m in "ABC"}
    w = {m: collide_fast(v, wall, m) for m in "ABC"}
    s = {"v0": v}
    for m in "ABC":
        for k, f in SCALE.items():
            s[f"{k}_{m}"] = c[m][k] * f
        s[f"e_{m}"] = c[m]["e"]
        s[f"flags_{m}"] = c[m]["flags"]
        s[f"kappa_{m}"] = c[m]["Q"] / (np.pi * c[m]["a_max"] ** 2 * pair.dT * np.sqrt(c[m]["t_coll"]) / pair.sigma)
        s[f"wall_e_{m}"] = w[m]["e"]
        s[f"wall_Q_{m}"] = w[m]["Q"] * 1e6
        s[f"wall_flags_{m}"] = w[m]["flags"]
        base = np.pi * w[m]["a_max"] ** 2 * wall.dT * np.sqrt(w[m]["t_coll"]) / wall.sigma * 1e6
        s[f"wall_Q31_{m}"], s[f"wall_Q33_{m}"] = 0.87 * base, 0.88 * base
    A, B = c["A"], c["B"]
    s["r1"] = B["delta_max"] / A["delta_max"]                       # eq. (39)
    s["r2"] = A["delta_r"] / B["delta_r"]                           # eq. (41)
    s["r3"] = B["R_bar"] / A["R_bar"]                               # eq. (42) as printed
    s["r4"] = A["t_r"] / B["t_r"]
    v_hat = v / pair.v_y
    s["e_johnson"], s["e_thornton"] = johnson_e(v_hat), thornton_e(v_hat)
    return s


def write_csv(path: Path, s: dict, keys) -> None:
    import numpy as np

    cols = ["v0"] + list(keys)
    np.savetxt(path, np.column_stack([s[k] for k in cols]), delimiter=",", fmt="%.10g",
               header=",".join(cols), comments="")


def plot(path: Path, name: str, s: dict, onsets) -> None:
    import matplotlib.pyplot as plt

    title, ylabel, curves, logy, note = FIGURES[name]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    v = s["v0"]
    prefix = "wall_" if name.startswith("wall") else ""
    for key, label in curves:
        line, = ax.plot(v, s[key], label=label, lw=1.6 if key[-2:] in ("_A", "_B", "_C") else 1.0,
                        ls="-" if not key.startswith(("e_j", "e_t", "wall_Q3")) else "--")
    colors = dict(A="C0", B="C1", C="C2")
    for m in "ABC":
        bad = s[f"{prefix}flags_{m}"] != 0
        if bad.any() and any(k.endswith(m) or m == "A" and k in ("r1", "r2", "r3", "r4") for k, _ in curves):
            ax.axvspan(v[bad].min(), v[bad].max(), color=colors[m], alpha=0.10,
                       label=f"{m} unphysical (e > 1 or delta_f < 0)")
    if name == "heat_closed_forms":
        for y, lab in ((0.87, "eq. 31: 0.87"), (0.88, "eq. 33: 0.88")):
            ax.axhline(y, color="k", lw=0.8, ls=":")
            ax.text(v[0], y, lab, va="bottom", fontsize=7)
    if name in ("fig06_r2_r3",):
        ax.axhline(1.1 / 2.8, color="k", lw=0.8, ls=":")
    for x, lab in zip(onsets, ("$v_y$", "$v_p$")):
        ax.axvline(x, color="k", ls=":", lw=1)
        ax.text(x, 0.98, lab, transform=ax.get_xaxis_transform(), ha="right", va="top")
    ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel("impact speed $v_0$ [m/s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title + (f"\n({note})" if note else ""), fontsize=9)
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def run(args) -> int:
    import time

    import matplotlib
    matplotlib.use("Agg")
    import numpy as np

    from plugins.heat import Pair

    if not 0 < args.vmin < args.vmax:
        raise ValueError(f"need 0 < --vmin < --vmax, got {args.vmin}, {args.vmax}")
    if args.points < 2:
        raise ValueError(f"--points must be at least 2, got {args.points}")
    t0 = time.perf_counter()
    pair = Pair()
    onsets = pair.onset_speeds()
    v = np.geomspace(args.vmin, args.vmax, args.points)
    s = series(v, pair)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, (_, _, curves, _, _) in FIGURES.items():
        write_csv(args.out / f"{name}.csv", s, [k for k, _ in curves])
        plot(args.out / f"{name}.png", name, s, onsets)
    print(f"paper's pair: v_y = {onsets[0]:.6g} m/s, v_p = {onsets[1]:.6g} m/s (printed 0.0055, 1.123)")
    j = -1
    print(f"at v0 = {v[j]:g} m/s: r1 = {s['r1'][j]:.4f}, r2 = {s['r2'][j]:.4f}, r3 = {s['r3'][j]:.4f}, "
          f"r4 = {s['r4'][j]:.4f} (b1/b2 = {pair.b1 / pair.b2:.4f})")
    for m in "ABC":
        bad = s[f"flags_{m}"] != 0
        rng = f"{v[bad].min():.3g}-{v[bad].max():.3g} m/s" if bad.any() else "none"
        print(f"model {m}: unphysical in {rng}; e at {v[j]:g} m/s = {s[f'e_{m}'][j]:.4f}, "
              f"Q = {s[f'Q_{m}'][j]:.4g} uJ, Q/(pi a^2 dT t^1/2/sigma) = {s[f'kappa_{m}'][j]:.4f}")
    print(f"wrote {2 * len(FIGURES)} files to {args.out} in {time.perf_counter() - t0:.1f} s")
    return 0
