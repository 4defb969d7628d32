"""Benchmarks of the coupled host on a dry scene (cases/hot-cold-box, 1000 particles).

1. What each effect costs: wall time per simulated second with the plain DEM, collision
   heat (fast and exact paths), restitution feedback and enduring conduction.
2. The host's overhead: the same dry scene (no effects) through the host and through
   the native ``liggghts`` binary with the same input.
3. What the sampling interval costs in accuracy: impact speeds and total heat against
   sampling every DEM step (median and 90th percentile of the per-collision error of v0,
   error of the total heat moved, collisions missed).

Run: .venv/bin/python tools/bench_host.py [--time 0.01]
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from pyhost.commands.run import simulate
from pyhost.dem_input import input_lines, place_particles, write_data
from pyhost.scene import load_scene

CASE = Path(__file__).resolve().parents[1] / "cases" / "hot-cold-box" / "case.toml"


def variant(scene, end, **effects):
    return dataclasses.replace(
        scene, effects=dataclasses.replace(scene.effects, **effects),
        time=dataclasses.replace(scene.time, end=end),
        output=dataclasses.replace(scene.output, vtk=False, pictures=False, every=end))


def run_host(scene, out: Path):
    t = time.perf_counter()
    summary = simulate(scene, out.resolve(), progress_every=1e9)
    return time.perf_counter() - t, summary


def run_native(scene, out: Path) -> float:
    out.mkdir(parents=True, exist_ok=True)
    data = write_data(out / "particles.data", scene, place_particles(scene))
    steps = round(scene.time.end / scene.time.dem_step)
    (out / "in.native").write_text("\n".join(input_lines(scene, data.name) + ["run 0", f"run {steps}"]) + "\n")
    t = time.perf_counter()
    subprocess.run([shutil.which("liggghts"), "-in", "in.native", "-log", "log.native", "-screen", "/dev/null"],
                   cwd=out, check=True)
    return time.perf_counter() - t


def collisions(out: Path) -> dict:
    """Collisions by partners: {(i, j, wall): [(start time, v0), ...]}."""
    found = {}
    for r in csv.DictReader(open(out / "collisions.csv")):
        found.setdefault((int(r["i"]), int(r["j"]), int(r["wall"])), []).append((float(r["time"]), float(r["v0"])))
    return found


def matched_errors(ref: dict, got: dict, window: float):
    """Relative v0 errors of the reference collisions found again within ``window`` [s] of
    their start, and how many were not found."""
    errors, missed = [], 0
    for key, events in ref.items():
        candidates = got.get(key, [])
        for t, v0 in events:
            near = [v for s, v in candidates if abs(s - t) <= window]
            if near:
                errors.append(abs(near[0] / v0 - 1))
            else:
                missed += 1
    return np.array(errors), missed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--time", type=float, default=0.01, help="simulated time per run [s]")
    args = ap.parse_args()
    base = load_scene(CASE)
    n = len(place_particles(base).radius)
    print(f"scene: {CASE.parent.name}, {n} particles, DEM step {base.time.dem_step:g} s, "
          f"{args.time:g} s simulated per run")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        print("\n1. cost of each effect (sampling every", base.time.sample_every, "steps)")
        print(f"{'effects':>44} | {'wall s per simulated s':>22} | collisions")
        rows = (("plain DEM (isothermal)", dict(contact_heat="none")),
                ("collision heat A, fast path", dict(contact_heat="A", heat_path="fast")),
                ("collision heat A, exact path", dict(contact_heat="A", heat_path="exact")),
                ("+ restitution feedback", dict(contact_heat="A", heat_path="fast", restitution_feedback=True)),
                ("+ enduring conduction", dict(contact_heat="A", heat_path="fast", restitution_feedback=True,
                                               enduring_conduction=True)))
        for k, (name, eff) in enumerate(rows):
            wall, summary = run_host(variant(base, args.time, **eff), tmp / f"effects{k}")
            print(f"{name:>44} | {wall / args.time:22.1f} | {summary['collisions']}")

        print("\n2. host overhead on the dry scene without effects")
        dry = variant(base, args.time, contact_heat="none")
        native = min(run_native(dry, tmp / f"native{k}") for k in range(2))
        host = min(run_host(dry, tmp / f"host{k}")[0] for k in range(2))
        print(f"native liggghts {native:.2f} s, host {host:.2f} s: overhead {100 * (host / native - 1):+.1f} % "
              f"(best of 2; the native time includes its start-up)")

        print("\n3. sampling interval: accuracy against sampling every step")
        ref_scene = dataclasses.replace(variant(base, args.time, contact_heat="A", heat_path="fast"),
                                        time=dataclasses.replace(base.time, end=args.time, sample_every=1))
        wall_ref, ref_summary = run_host(ref_scene, tmp / "sample1")
        ref = collisions(tmp / "sample1")
        print(f"{'every k steps':>13} | {'wall s/sim s':>12} | {'v0 err median':>13} {'p90':>9} | "
              f"{'total Q err':>11} | missed")
        print(f"{1:>13} | {wall_ref / args.time:12.1f} | {'(reference)':>13} {'':>9} | {'':>11} | "
              f"of {ref_summary['collisions']}")
        for k in (2, 5, 10, 20, 50):
            sc = dataclasses.replace(ref_scene, time=dataclasses.replace(ref_scene.time, sample_every=k))
            wall, summary = run_host(sc, tmp / f"sample{k}")
            err, missed = matched_errors(ref, collisions(tmp / f"sample{k}"), 1.01 * k * base.time.dem_step)
            dq = summary["heat_moved"] / ref_summary["heat_moved"] - 1
            print(f"{k:>13} | {wall / args.time:12.1f} | {np.median(err):13.2e} {np.percentile(err, 90):9.2e} | "
                  f"{dq:+11.2e} | {missed}")


if __name__ == "__main__":
    main()
