"""``python -m pyhost compare``: every collision heat model side by side (docs/comparison.md).

(a) Q against impact speed for models A, B, C and every comparison model, for
    the hot-cold bed's aluminium beads (R = 0.5 mm, dT = 1 K), the DEM at --dem-modulus;
(b) softened/real against the DEM's Young's modulus from 1e6 Pa to the real one, for
    aluminium, steel and glass (R = 1 mm, v0 = --speed, DEM restitution 0.9, DEM Poisson
    ratio = the real one), real = model A and hertz; printed at 1e7 and 1e8 Pa;
(c) the total heat each model moves on the collisions of a hot-cold-bed run (--bed), each
    recomputed on the run's own collisions and temperature differences.
Writes comparison_speed.png, comparison_modulus.png, comparison_bed.png and the tables as
CSV into --out.
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

HELP = "compare every heat model (A, B, C and the comparison models): figures and tables"

MATERIALS = {
    # density kg/m^3, E Pa, nu, yield stress Pa, c J/(kg K), k W/(m K): the cases' aluminium
    # and steel (cases/hot-cold-bed, cases/two-particles); soda-lime glass, handbook values
    "aluminium": (2700.0, 70e9, 0.33, 100e6, 900.0, 200.0),
    "steel": (7800.0, 210e9, 0.30, 300e6, 470.0, 45.0),
    "glass": (2500.0, 63e9, 0.22, 1e9, 840.0, 1.0),
}
DEM_RESTITUTION = 0.9
TABLE_MODULI = (1e7, 1e8)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, default=Path("out/compare"), help="output folder")
    p.add_argument("--speed", type=float, default=0.5, help="impact speed of panel (b) [m/s]")
    p.add_argument("--dem-modulus", type=float, default=1e7, help="DEM Young's modulus of panel (a) [Pa]")
    p.add_argument("--bed", type=Path, default=Path("cases/hot-cold-bed/output"),
                   help="output folder of a hot-cold-bed run (panel c; skipped if it has no collisions.csv)")


def material(name: str, dem_modulus: float):
    from pyhost.schema import DemContact, Material
    rho, E, nu, Y, c, k = MATERIALS[name]
    return Material(rho, E, nu, Y, c, k, DemContact(youngs_modulus=float(dem_modulus),
                                                    restitution=DEM_RESTITUTION, poisson_ratio=nu))


def heat(model: str, mat, R: float, v0) -> np.ndarray:
    """Q [J] at dT = 1 K of head-on collisions of two equal spheres of radius R [m]."""
    from plugins.heat.batch import evaluate
    v0 = np.atleast_1d(np.asarray(v0, float))
    n = len(v0)
    zeros, radius = np.zeros(n, int), np.full(n, R)
    return evaluate(model, "fast", [mat], zeros, zeros, radius, radius, v0, np.ones(n))[0]


def run(args) -> int:
    from plugins.heat import MODEL_NAMES

    if not args.speed > 0 or not args.dem_modulus > 0:
        raise ValueError(f"--speed and --dem-modulus must be > 0, got {args.speed}, {args.dem_modulus}")
    args.out.mkdir(parents=True, exist_ok=True)

    v = np.geomspace(1e-3, 10.0, 120)
    alu = material("aluminium", args.dem_modulus)
    speed = {m: heat(m, alu, 0.5e-3, v) for m in MODEL_NAMES}
    write_csv(args.out / "comparison_speed.csv", {"v0": v, **{f"Q_{m}": q for m, q in speed.items()}})
    print(f"(a) aluminium, R = 0.5 mm, dT = 1 K, DEM modulus {args.dem_modulus:g} Pa: Q [J]")
    print(f"{'v0 [m/s]':>9} " + " ".join(f"{m:>18}" for m in MODEL_NAMES))
    for k in range(0, len(v), 20):
        print(f"{v[k]:9.3g} " + " ".join(f"{speed[m][k]:18.4g}" for m in MODEL_NAMES))

    ratios, table = {}, []
    for name, props in MATERIALS.items():
        E_dem = np.geomspace(1e6, props[1], 60)
        Q = {m: np.array([heat(m, material(name, E), 1e-3, args.speed)[0] for E in E_dem])
             for m in ("softened", "softened_corrected", "zhou")}
        Q_A, Q_h = (heat(m, material(name, 1e7), 1e-3, args.speed)[0] for m in ("A", "hertz"))
        ratios[name] = (E_dem, Q, Q_A, Q_h)
        for E in TABLE_MODULI:
            s, c, z = (heat(m, material(name, E), 1e-3, args.speed)[0]
                       for m in ("softened", "softened_corrected", "zhou"))
            table.append((name, E, s / Q_A, s / Q_h, c / Q_A, c / Q_h, z / Q_A, z / Q_h))
    write_csv(args.out / "comparison_modulus.csv",
              {k: [row[n] for row in table] for n, k in enumerate(
                  ("material", "E_dem", "softened/A", "softened/hertz", "corrected/A", "corrected/hertz",
                   "zhou/A", "zhou/hertz"))})
    print(f"(b) softened/real at v0 = {args.speed:g} m/s, R = 1 mm, DEM restitution {DEM_RESTITUTION}")
    print(f"{'material':>10} {'E_DEM [Pa]':>10} {'softened/A':>11} {'softened/hertz':>15} "
          f"{'corrected/A':>12} {'corrected/hertz':>16} {'zhou/A':>8} {'zhou/hertz':>11}")
    for name, E, *r in table:
        print(f"{name:>10} {E:10.0e} " + " ".join(f"{x:>{w}.3g}" for x, w in zip(r, (11, 15, 12, 16, 8, 11))))

    bed = None
    if has_collisions(args.bed):
        bed = bed_totals(args.bed, MODEL_NAMES)
        write_csv(args.out / "comparison_bed.csv", {"model": list(bed), "heat_J": list(bed.values())})
        print(f"(c) {args.bed}: heat between particles [J] on the run's {bed.pop('_collisions')} collisions")
        for m, q in bed.items():
            print(f"{m:>20} {q:12.4e} {q / bed['A']:8.3g} x A")
    else:
        print(f"(c) skipped: no {args.bed / 'collisions.csv'} (run cases/hot-cold-bed/Allrun -test first)")
    for path in plot(args, v, speed, ratios, bed):
        print(f"plot: {path}")
    return 0


def bed_totals(run_dir: Path, models) -> dict:
    """Heat between particles of each model on a run's collisions (its case.toml is the
    folder above its output folder)."""
    from pyhost.output import read_collisions
    from pyhost.scene import load_scene

    cols = read_collisions(run_dir)
    totals = heat_by_model_offline(load_scene(run_dir.parent / "case.toml"), cols, models)
    return dict(totals, _collisions=len(cols["i"]))


def heat_by_model_offline(scene, collisions, models) -> dict:
    """{model: heat between particles [J], sum of |Q|} of each model on the collisions of a
    finished run (``collisions``: the columns of its collisions.csv as arrays: i, j, wall
    (1-based, 0 for none), v0, Q, model). Each collision's dT is the one the run used,
    Q / (Q per kelvin of the run's own model), so a model's column is what a side column
    would have held (collisions with an adiabatic wall or capped ones carry no dT back).
    Box scenes only: particle ids are the order of ``place_particles``."""
    from plugins.heat.batch import evaluate
    from pyhost.engines.liggghts.box_input import material_index, place_particles

    p = place_particles(scene)
    materials = list(scene.materials.values())
    wall_mat = np.array([material_index(scene)[w.material] for w in scene.walls] or [0], int)
    i = np.asarray(collisions["i"], int) - 1
    w = np.asarray(collisions["wall"], int)
    wall = w > 0
    j = np.where(wall, 0, np.asarray(collisions["j"], int) - 1)
    mi, R_i = p.material[i], p.radius[i]
    mj = np.where(wall, wall_mat[np.maximum(w - 1, 0)], p.material[j])
    R_j = np.where(wall, np.inf, p.radius[j])
    v0, ones = np.asarray(collisions["v0"], float), np.ones(len(i))
    main = set(np.asarray(collisions["model"]).tolist())
    if len(main) != 1:
        raise ValueError(f"collisions.csv holds {len(main)} heat models ({sorted(main)}); expected one")
    G_main = evaluate(main.pop(), "fast", materials, mi, mj, R_i, R_j, v0, ones)[0]
    dT = np.asarray(collisions["Q"], float) / G_main
    return {m: float(np.abs(evaluate(m, "fast", materials, mi, mj, R_i, R_j, v0, ones)[0] * dT)[~wall].sum())
            for m in models}


def has_collisions(run_dir: Path) -> bool:
    """The run folder holds a collision log, CSV or binary (pyhost.output.read_collisions)."""
    from pyhost.output import SCHEMA

    return (run_dir / "collisions.csv").is_file() or (run_dir / "collisions" / SCHEMA).is_file()


def write_csv(path: Path, columns: dict) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        w.writerows(zip(*columns.values()))


def plot(args, v, speed, ratios, bed) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    fig, ax = plt.subplots(figsize=(7, 5))
    for m, q in speed.items():
        ax.plot(v, q, ls="--" if m.startswith("softened") else "-", label=m)
    ax.set(xscale="log", yscale="log", xlabel="impact speed $v_0$ [m/s]", ylabel="Q per kelvin [J/K]",
           title=f"aluminium beads, R = 0.5 mm; DEM modulus {args.dem_modulus:g} Pa, e = {DEM_RESTITUTION}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    paths.append(save(fig, args.out / "comparison_speed.png"))

    fig, ax = plt.subplots(figsize=(7, 5))
    for (name, (E_dem, Q, Q_A, Q_h)), colour in zip(ratios.items(), ("C0", "C1", "C2")):
        ax.plot(E_dem, Q["softened"] / Q_A, color=colour, label=f"{name}: softened / A")
        ax.plot(E_dem, Q["softened"] / Q_h, color=colour, ls="--", label=f"{name}: softened / hertz")
        ax.plot(E_dem, Q["softened_corrected"] / Q_A, color=colour, ls=":", label=f"{name}: corrected / A")
        ax.plot(E_dem, Q["zhou"] / Q_A, color=colour, ls="-.", label=f"{name}: zhou / A")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel="DEM Young's modulus [Pa]", ylabel="Q softened / Q real",
           title=f"head-on, R = 1 mm, $v_0$ = {args.speed:g} m/s, DEM e = {DEM_RESTITUTION}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    paths.append(save(fig, args.out / "comparison_modulus.png"))

    if bed:
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.bar(list(bed), [q * 1e3 for q in bed.values()])
        ax.set(yscale="log", ylabel="heat between particles [mJ]", title=f"hot-cold bed run {args.bed}")
        ax.tick_params(axis="x", labelrotation=20)
        paths.append(save(fig, args.out / "comparison_bed.png"))
    return paths


def save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt
    plt.close(fig)
    return path
