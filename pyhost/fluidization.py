"""The fluidization curve of a fluid run: pressure drop against superficial velocity.

A run whose ``fluid.inlet_table`` holds the velocity in steps (plateaus) writes, in
history.csv, the superficial inlet velocity, the pressure drop the particles cause and the
bed height (``pyhost.effects.fluid.FluidExchange.bed_state``). Here each plateau is averaged over the second half of
its hold, and compared with

- Ergun (1952) at the bed's own voidage and height, for the fixed bed;
- the bed's weight per area less buoyancy, which a fluidized bed's pressure drop carries;
- Wen & Yu (1966) for the minimum fluidization velocity u_mf.

The measured u_mf is where the fixed-bed curve, fitted as a u + b u^2 (Ergun's form), reaches
the bed weight per area (Kunii & Levenspiel, Fluidization Engineering, 2nd ed., ch. 3).
All quantities SI: m/s, Pa, m, kg/m^3, Pa s.
"""
from __future__ import annotations

import csv
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from plugins.bed import ergun_pressure_drop, ergun_umf, wen_yu_umf


@dataclass
class Curve:
    u: list             # plateau superficial velocities [m/s]
    dp: list            # mean pressure drop over the second half of each hold [Pa]
    dp_std: list        # its standard deviation [Pa]
    height: list        # mean bed height [m]
    voidage: list       # 1 - particle volume / (cross-section x height) [-]
    ergun: list         # Ergun's drop at that voidage and height [Pa]
    fixed: list         # whether the plateau is in the fixed-bed fit (dp < 0.85 weight)
    weight: float       # bed weight per area less buoyancy [Pa]
    u_mf: float         # measured minimum fluidization velocity [m/s]
    u_mf_wen_yu: float  # Wen & Yu [m/s]
    u_mf_ergun: float   # Ergun's at the settled bed's voidage [m/s]
    fluidized_dp: float  # mean drop of the plateaus above u_mf with the bed expanded [Pa]
    d: float            # particle (Sauter) diameter [m]
    rho: float          # fluid density [kg/m^3]
    mu: float           # fluid dynamic viscosity [Pa s]


def plateaus(table) -> list[tuple[float, float, float]]:
    """(velocity, start, end) of each hold of an inlet table with velocity > 0."""
    return [(u0, t0, t1) for (t0, u0), (t1, u1) in zip(table, table[1:]) if u0 == u1 and u0 > 0]


def measure(out: Path) -> Curve:
    """The fluidization curve of the run in folder ``out`` (scene.json, history.csv)."""
    out = Path(out)
    for name in ("scene.json", "history.csv"):
        if not (out / name).exists():
            raise ValueError(f"{out}: no {name}: not the output folder of a run")
    scene = json.loads((out / "scene.json").read_text())
    fluid = scene.get("fluid") or {}
    holds = plateaus(fluid.get("inlet_table") or [])
    if len(holds) < 3:
        raise ValueError(f"{out}: fluid.inlet_table needs at least 3 plateaus of velocity > 0, has {len(holds)}")
    rows = list(csv.DictReader(open(out / "history.csv")))
    if not rows or "pressure_drop" not in rows[0]:
        raise ValueError(f"{out}/history.csv: no pressure_drop column: not a fluid run")
    t, dp, h = (np.array([float(r[k]) for r in rows]) for k in ("time", "pressure_drop", "bed_height"))
    box = scene["domain"]["box"]
    area = (box[1] - box[0]) * (box[3] - box[2])
    g = abs(scene["domain"]["gravity"][2])
    rho, mu = fluid["density"], fluid["viscosity"]
    groups = scene["particles"]
    volume = sum(p["count"] * 4 / 3 * np.pi * p["radius"]**3 for p in groups)
    mass = sum(p["count"] * 4 / 3 * np.pi * p["radius"]**3 * scene["materials"][p["material"]]["density"]
               for p in groups)
    rho_p = mass / volume
    d = 6 * volume / sum(p["count"] * 4 * np.pi * p["radius"]**2 for p in groups)   # Sauter diameter
    weight = (mass - rho * volume) * g / area
    u, mean, std, height = [], [], [], []
    for u0, t0, t1 in holds:
        s = (t >= 0.5 * (t0 + t1)) & (t <= t1)
        if s.sum() < 2:
            continue                                # the run ended before this hold's second half
        u.append(u0)
        mean.append(float(dp[s].mean()))
        std.append(float(dp[s].std()))
        height.append(float(h[s].mean()))
    u, mean, height = np.array(u), np.array(mean), np.array(height)
    eps = 1 - volume / (area * height)
    ergun = ergun_pressure_drop(u, eps, d, height, rho, mu)
    fixed = mean < 0.85 * weight
    if fixed.sum() < 2:
        raise ValueError(f"{out}: fewer than 2 fixed-bed plateaus (pressure drop < 0.85 bed weight)")
    a, b = np.linalg.lstsq(np.stack([u[fixed], u[fixed]**2], 1), mean[fixed], rcond=None)[0]
    u_mf = float((-a + np.sqrt(a * a + 4 * b * weight)) / (2 * b))
    settled = height[fixed].mean()
    fluidized = (u > u_mf) & (height > 1.03 * settled)
    return Curve(u=u.tolist(), dp=mean.tolist(), dp_std=std, height=height.tolist(), voidage=eps.tolist(),
                 ergun=ergun.tolist(), fixed=fixed.tolist(), weight=float(weight), u_mf=u_mf,
                 u_mf_wen_yu=float(wen_yu_umf(d, rho_p, rho, mu, g)),
                 u_mf_ergun=float(ergun_umf(eps[fixed].mean(), d, rho_p, rho, mu, g)),
                 fluidized_dp=float(mean[fluidized].mean()) if fluidized.any() else float("nan"),
                 d=float(d), rho=rho, mu=mu)


def report(curve: Curve, out: Path) -> str:
    """Write fluidization.csv and fluidization.json in ``out``; return the printed table."""
    lines = [f"{'u [m/s]':>8} {'dP [Pa]':>9} {'std':>6} {'H [mm]':>7} {'voidage':>7} {'Ergun [Pa]':>10} "
             f"{'error':>7}  fixed-bed fit"]
    with open(out / "fluidization.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(("u", "pressure_drop", "pressure_drop_std", "bed_height", "voidage", "ergun", "fixed"))
        for row in zip(curve.u, curve.dp, curve.dp_std, curve.height, curve.voidage, curve.ergun, curve.fixed):
            w.writerow(row)
            u, dp, sd, h, eps, erg, fixed = row
            lines.append(f"{u:8.3f} {dp:9.2f} {sd:6.2f} {h * 1e3:7.2f} {eps:7.4f} {erg:10.2f} "
                         f"{dp / erg - 1:+7.2%}  {'yes' if fixed else 'no'}")
    (out / "fluidization.json").write_text(json.dumps(asdict(curve), indent=1))
    lines += [f"bed weight per area less buoyancy {curve.weight:.2f} Pa; fluidized plateaus carry "
              f"{curve.fluidized_dp:.2f} Pa ({curve.fluidized_dp / curve.weight - 1:+.2%})",
              f"u_mf measured {curve.u_mf:.4f} m/s; Wen-Yu {curve.u_mf_wen_yu:.4f} m/s "
              f"({curve.u_mf / curve.u_mf_wen_yu - 1:+.1%}); Ergun at the settled voidage "
              f"{curve.u_mf_ergun:.4f} m/s ({curve.u_mf / curve.u_mf_ergun - 1:+.1%})"]
    return "\n".join(lines)


def plot(curve: Curve, out: Path) -> Path:
    """fluidization.png: the measured curve, Ergun's at the settled bed's voidage and height,
    the bed weight per area and both u_mf."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fixed = np.array(curve.fixed)
    eps = float(np.mean(np.array(curve.voidage)[fixed]))
    h = float(np.mean(np.array(curve.height)[fixed]))
    uu = np.linspace(0, max(curve.u), 200)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.errorbar(curve.u, curve.dp, yerr=curve.dp_std, fmt="o", color="k", capsize=3,
                label="CFD-DEM (mean, std of each step)")
    ax.plot(uu, ergun_pressure_drop(uu, eps, curve.d, h, curve.rho, curve.mu), color="tab:blue",
            label="Ergun at the settled voidage")
    ax.axhline(curve.weight, color="tab:gray", ls="--", label="bed weight per area")
    ax.axvline(curve.u_mf_wen_yu, color="tab:red", ls=":", label=f"Wen-Yu u_mf {curve.u_mf_wen_yu:.3f} m/s")
    ax.axvline(curve.u_mf, color="k", ls="-.", lw=0.8, label=f"measured u_mf {curve.u_mf:.3f} m/s")
    ax.set_xlim(0, None)
    ax.set_ylim(0, 1.25 * max(max(curve.dp), curve.weight))
    ax.set_xlabel("superficial velocity [m/s]")
    ax.set_ylabel("pressure drop [Pa]")
    ax.set_title(f"settled bed: voidage {eps:.3f}, height {h * 1e3:.1f} mm, d {curve.d * 1e3:.2g} mm")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    path = out / "fluidization.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
