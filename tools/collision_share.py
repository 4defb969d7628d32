"""The share of the heat that collisions carry, against convection, in a bubbling bed:
cases/hot-cold-gas-bed scaled to particle diameters 0.5, 1 and 2 mm, made of aluminium,
steel or glass, with contact models A, B and C (27 short runs, one process each).

Each run is the case with its particles, box, plenum and DEM step scaled by the diameter,
fluidized at 2.6 times Wen & Yu's u_mf of that material and size; the share is
heat moved by collisions between particles / (that + heat convected, sum of magnitudes),
both from the run's history.csv over the second half of the run: the first tens of
milliseconds, before the bed bubbles, have few collisions and the largest convection (in
the case's full run the cumulative share is 6e-7 at 0.02 s and 1.3e-4 at 0.05 s). Writes docs/collision-share.md (the table) and
docs/figures/collision-share.png (share against diameter per material, the A-B-C spread as
a band).

Run: .venv/bin/python tools/collision_share.py [--end 0.08]  (about 10 min on one core)
"""
from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import tomli_w

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pyhost.engines.liggghts.box_input import dem_collision_time  # noqa: E402
from plugins.bed import wen_yu_umf  # noqa: E402
from pyhost.scene import load_scene  # noqa: E402

CASE = ROOT / "cases" / "hot-cold-gas-bed" / "case.toml"
MATERIALS = {   # real properties (as the repository's other cases)
    "aluminium": dict(density=2700.0, youngs_modulus=70e9, poisson_ratio=0.33, yield_stress=100e6,
                      heat_capacity=900.0, conductivity=200.0),
    "steel": dict(density=7800.0, youngs_modulus=210e9, poisson_ratio=0.3, yield_stress=300e6,
                  heat_capacity=470.0, conductivity=45.0),
    "glass": dict(density=2500.0, youngs_modulus=63e9, poisson_ratio=0.25, yield_stress=500e6,
                  heat_capacity=840.0, conductivity=1.0),
}
DIAMETERS = (0.5e-3, 1e-3, 2e-3)
MODELS = ("A", "B", "C")


def scene(material: str, d: float, model: str, end: float, folder: Path) -> Path:
    """The case scaled to diameter d, written to folder/case.toml."""
    data = tomllib.loads(CASE.read_text())
    s = d / (2 * data["particles"][0]["radius"])
    base = data["materials"].pop(next(iter(data["materials"])))
    data["materials"] = {material: dict(MATERIALS[material], dem=base["dem"])}
    for group in data["particles"]:
        group.update(material=material, radius=d / 2, region=[v * s for v in group["region"]])
    for wall in data["walls"]:
        wall["material"] = material
    data["domain"]["box"] = [v * s for v in data["domain"]["box"]]
    f = data["fluid"]
    f["plenum"] *= s
    f["inlet_velocity"] = 2.6 * float(wen_yu_umf(d, MATERIALS[material]["density"], f["density"], f["viscosity"]))
    data["effects"]["contact_heat"] = model
    data["time"].update(end=end, dem_step=1e-9)
    data["output"] = dict(every=end / 8, vtk=False, pictures=False)
    path = folder / "case.toml"
    folder.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(data))
    # the DEM step: 25 steps of a DEM collision at twice the inlet velocity
    data["time"]["dem_step"] = dem_collision_time(load_scene(path), 2 * f["inlet_velocity"]) / 25
    path.write_text(tomli_w.dumps(data))
    return path


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--end", type=float, default=0.08, help="simulated time of each run [s]")
    args = p.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for material in MATERIALS:
            for d in DIAMETERS:
                for model in MODELS:
                    folder = Path(tmp) / f"{material}-{d:g}-{model}"
                    scene(material, d, model, args.end, folder)
                    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder)], cwd=ROOT,
                                       capture_output=True, text=True)
                    if r.returncode != 0:
                        print(r.stdout[-2000:], r.stderr[-2000:])
                        return 1
                    with open(folder / "output" / "history.csv") as f:
                        history = list(csv.DictReader(f))
                    half, last = history[len(history) // 2], history[-1]
                    moved, convected, collisions = (float(last[k]) - float(half[k]) for k in
                                                    ("heat_moved", "heat_convected_gross", "collisions"))
                    share = moved / (moved + convected)
                    u = tomllib.loads((folder / "case.toml").read_text())["fluid"]["inlet_velocity"]
                    rows.append((material, d, model, u, int(collisions), moved, convected, share))
                    print(f"{material:9s} d = {d * 1e3:.1f} mm model {model}: u = {u:.3f} m/s, {int(collisions)} "
                          f"collisions, {moved:.3e} J by collisions, {convected:.3e} J by convection, "
                          f"share {share:.3e}", flush=True)
    write(rows, args.end)
    return 0


def write(rows, end: float) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines = ["# Share of the heat carried by collisions in a bubbling bed", "",
             f"Generated by `tools/collision_share.py --end {end:g}` (one run each, {end:g} s of bed time from the "
             f"start of fluidization, heat counted from {end / 2:g} s on, after the start-up): "
             "cases/hot-cold-gas-bed scaled to each diameter (box, plenum, DEM step), "
             "fluidized at 2.6 u_mf (Wen-Yu), lower half at 400 K, upper half at 300 K, air at 350 K, Gunn's "
             "convection. Share = heat moved by particle-particle collisions / (that + convected heat, both "
             "sums of magnitudes). Models A and C share their compression law, which sets the heat: "
             "their shares coincide.", "",
             "| material | d (mm) | model | u (m/s) | collisions | collisions (J) | convection (J) | share |",
             "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {m} | {d * 1e3:g} | {mod} | {u:.3f} | {n} | {qc:.3e} | {qv:.3e} | {sh:.2e} |"
              for m, d, mod, u, n, qc, qv, sh in rows]
    (ROOT / "docs" / "collision-share.md").write_text("\n".join(lines) + "\n\n![share](figures/collision-share.png)\n")
    fig, ax = plt.subplots(figsize=(6, 4))
    for material in MATERIALS:
        share = np.array([[r[7] for r in rows if r[0] == material and r[1] == d] for d in DIAMETERS])
        dmm = np.array(DIAMETERS) * 1e3
        line, = ax.plot(dmm, np.median(share, axis=1), "o-", label=material)
        ax.fill_between(dmm, share.min(axis=1), share.max(axis=1), color=line.get_color(), alpha=0.25)
    ax.set(xscale="log", yscale="log", xlabel="particle diameter (mm)", ylabel="collisional share of the heat",
           title="Collisions against convection (band: models A, B, C)")
    ax.set_xticks(np.array(DIAMETERS) * 1e3, [f"{d * 1e3:g}" for d in DIAMETERS])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.legend()
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / "figures" / "collision-share.png", dpi=120)


if __name__ == "__main__":
    sys.exit(main())
