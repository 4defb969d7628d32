"""Benchmarks of the coupled host on a dry scene (cases/hot-cold-box, 1000 particles).
Wall times count the coupled run from its first DEM step (not starting LIGGGHTS and running
the script's set-up commands), except in section 2.

1. What each effect costs: wall time per simulated second with the plain DEM, collision
   heat (fast and exact paths), restitution feedback and enduring conduction.
2. The host's overhead: the same dry scene (no effects) through the host and through
   the native ``liggghts`` binary with the same input.
3. (Gone with the sampled contacts in session 33: what the sampling interval cost in
   accuracy. Collisions come from contact events recorded at every step.)
4. Heat against plain DEM by size: the scene grown to N particles at the same packing, wall
   time per DEM step without heat and with heat A (fast path), their ratio, and the cost
   per collision (extra wall time / collisions); with ``--baseline TREE`` the same on the
   code of another checkout (``tools/bench_host_baseline.py`` run with PYTHONPATH=TREE),
   so that before and after come from one run. ``--collisions csv binary``: section 4 with
   each form of the collision log (output.collisions); a baseline without that key is run
   with its CSV only.

Run (PYTHONPATH: the checkout to measure; the .venv's editable install points at /work/main):
     PYTHONPATH=. .venv/bin/python tools/bench_host.py [--time 0.01] [--sections 1 2 4]
     [--particles 1000 8000 27000] [--size-time 0.002] [--repeat 1] [--collisions csv binary]
     [--baseline /path/to/old/checkout]
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


from pyhost.engines.liggghts.box_input import input_lines, place_particles, write_data
from pyhost.scene import load_scene

CASE = Path(__file__).resolve().parents[1] / "cases" / "hot-cold-box" / "case.toml"


def variant(scene, end, collisions: str = "csv", **effects):
    """The scene to ``end`` [s] with these effects, no VTK or pictures; ``collisions``: the
    form of the collision log (left out for "csv", so that older checkouts run it too)."""
    form = {} if collisions == "csv" else dict(collisions=collisions)
    return dataclasses.replace(
        scene, effects=dataclasses.replace(scene.effects, **effects),
        time=dataclasses.replace(scene.time, end=end),
        output=dataclasses.replace(scene.output, vtk=False, pictures=False, every=end, **form))


def scaled(scene, n: int):
    """The scene with n particles at its packing: box and regions grown about the box's low
    corner by (n / N)^(1/3), each group's count by n / N; periodicity as it is."""
    total = sum(g.count for g in scene.particles)
    k = (n / total) ** (1 / 3)
    lo = scene.domain.box[0::2]

    def grow(b):
        return [lo[a // 2] + (v - lo[a // 2]) * k for a, v in enumerate(b)]

    groups = [dataclasses.replace(g, count=round(g.count * n / total), region=grow(g.region)) for g in scene.particles]
    return dataclasses.replace(scene, particles=groups, domain=dataclasses.replace(scene.domain, box=grow(scene.domain.box)))


def heat_by_size(run_host, sizes, sim_time: float, tmp: Path, repeat: int = 1, forms=("csv",)) -> list[dict]:
    """For each size: wall time per DEM step [s] plain and with heat A (fast) with each form
    of the collision log in ``forms``, best of ``repeat`` runs of each taken in turns, and the
    collisions. A short run of each first, so that no row pays for loading libraries."""
    base = load_scene(CASE)
    for heat in ("none", "A"):
        run_host(variant(base, 10 * base.time.dem_step, contact_heat=heat), tmp / f"warm-{heat}")
    rows = []
    for n in sizes:
        sc = scaled(base, n)
        steps = round(sim_time / sc.time.dem_step)
        walls = {("none", "csv"): []} | {("A", form): [] for form in forms}
        for r in range(repeat):
            for heat, form in walls:
                wall, summary = run_host(variant(sc, sim_time, form, contact_heat=heat, heat_path="fast"),
                                         tmp / f"{heat}{n}-{form}-{r}")
                shutil.rmtree(tmp / f"{heat}{n}-{form}-{r}", ignore_errors=True)
                walls[heat, form].append(wall)
        for form in forms:
            rows.append(dict(particles=sum(g.count for g in sc.particles), steps=steps, form=form,
                             plain=min(walls["none", "csv"]) / steps, heat=min(walls["A", form]) / steps,
                             collisions=summary["collisions"]))
    return rows


def size_table(rows: list[dict], label: str) -> None:
    for r in rows:
        extra = (r["heat"] - r["plain"]) * r["steps"]
        print(f"{label:>8} | {r.get('form', 'csv'):>6} | {r['particles']:>9} | {1e3 * r['plain']:11.3f} | {1e3 * r['heat']:11.3f} | "
              f"{r['heat'] / r['plain']:5.2f} | {r['collisions']:>10} | {1e6 * extra / max(r['collisions'], 1):8.1f}")


class Clocked:
    """The DEM as the loop sees it, noting when it first steps."""

    def __init__(self, dem):
        self.dem, self.started = dem, None

    def __getattr__(self, name):
        return getattr(self.dem, name)

    def run(self, steps: int) -> None:
        self.started = self.started or time.perf_counter()
        self.dem.run(steps)


def run_host(scene, out: Path, whole: bool = False):
    """Wall time [s] of the coupled run from its first DEM step to its summary (``whole``:
    with the engines' set-up), and the summary."""
    try:                                      # here: bench_host_baseline imports this file
        from pyhost.world import simulate
    except ImportError:                       # a checkout before pyhost/world.py
        from pyhost.commands.run import simulate

    clocked = {}

    def wrap(dem):
        clocked["dem"] = Clocked(dem)
        return clocked["dem"]

    t = time.perf_counter()
    summary = simulate(scene, out.resolve(), progress_every=1e9, wrap=wrap)
    return time.perf_counter() - (t if whole else clocked["dem"].started), summary


def run_native(scene, out: Path) -> float:
    out.mkdir(parents=True, exist_ok=True)
    data = write_data(out / "particles.data", scene, place_particles(scene))
    steps = round(scene.time.end / scene.time.dem_step)
    (out / "in.native").write_text("\n".join(input_lines(scene, data.name) + ["run 0", f"run {steps}"]) + "\n")
    t = time.perf_counter()
    subprocess.run([shutil.which("liggghts"), "-in", "in.native", "-log", "log.native", "-screen", "/dev/null"],
                   cwd=out, check=True)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--time", type=float, default=0.01, help="simulated time per run of sections 1-2 [s]")
    ap.add_argument("--sections", type=int, nargs="+", default=[1, 2, 4], choices=[1, 2, 4])
    ap.add_argument("--particles", type=int, nargs="+", default=[1000, 8000, 27000], metavar="N",
                    help="section 4: particle counts (the scene grown at its packing)")
    ap.add_argument("--size-time", type=float, default=0.002, help="section 4: simulated time per run [s]")
    ap.add_argument("--repeat", type=int, default=1, help="section 4: runs of each (best of)")
    ap.add_argument("--collisions", nargs="+", default=["csv"], choices=["csv", "binary"],
                    help="section 4: forms of the collision log with heat on")
    ap.add_argument("--baseline", type=Path, help="section 4 also on this checkout's code (before/after)")
    ap.add_argument("--rows-json", action="store_true", help=argparse.SUPPRESS)   # the baseline's own process
    args = ap.parse_args()
    if args.rows_json:
        with tempfile.TemporaryDirectory() as tmp:
            print(json.dumps(heat_by_size(run_host, args.particles, args.size_time, Path(tmp), args.repeat,
                                          args.collisions)))
        return
    base = load_scene(CASE)
    n = len(place_particles(base).radius)
    print(f"scene: {CASE.parent.name}, {n} particles, DEM step {base.time.dem_step:g} s, "
          f"{args.time:g} s simulated per run")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if 1 in args.sections:
            effect_costs(base, args.time, tmp)
        if 2 in args.sections:
            host_overhead(base, args.time, tmp)
        if 4 in args.sections:
            print(f"\n4. heat A (fast path) against plain DEM, {args.size_time:g} s simulated "
                  f"({round(args.size_time / base.time.dem_step)} steps) per run, engines' set-up not counted, "
                  f"best of {args.repeat}")
            print(f"{'code':>8} | {'log':>6} | {'particles':>9} | {'plain ms/st':>11} | {'heat ms/st':>11} | ratio | "
                  f"{'collisions':>10} | {'us/coll':>8}")
            if args.baseline:
                size_table(baseline_sizes(args.baseline, args.particles, args.size_time, args.repeat), "baseline")
            size_table(heat_by_size(run_host, args.particles, args.size_time, tmp, args.repeat, args.collisions),
                       "this")


def baseline_sizes(tree: Path, sizes, sim_time: float, repeat: int) -> list[dict]:
    """Section 4 on the code of another checkout (CSV log), in a process of its own: this
    script itself for a checkout with ``simulate`` (``pyhost.world``, earlier
    ``pyhost.commands.run``), else ``bench_host_baseline.py`` (the code before the
    LIGGGHTS-script rewrite)."""
    env = dict(os.environ, PYTHONPATH=str(tree.resolve()))
    current = any("def simulate(" in f.read_text() for f in (tree / "pyhost" / "world.py",
                                                               tree / "pyhost" / "commands" / "run.py") if f.is_file())
    cmd = ([sys.executable, __file__, "--rows-json", "--size-time", str(sim_time), "--repeat", str(repeat),
            "--particles"] + [str(n) for n in sizes] if current else
           [sys.executable, str(Path(__file__).with_name("bench_host_baseline.py")), str(sim_time), str(repeat)]
           + [str(n) for n in sizes])
    done = subprocess.run(cmd, env=env, check=True, stdout=subprocess.PIPE, text=True)
    return json.loads(done.stdout.splitlines()[-1])


def effect_costs(base, sim_time: float, tmp: Path) -> None:
    print("\n1. cost of each effect")
    print(f"{'effects':>44} | {'wall s per simulated s':>22} | collisions")
    rows = (("plain DEM (isothermal)", dict(contact_heat="none")),
            ("collision heat A, fast path", dict(contact_heat="A", heat_path="fast")),
            ("collision heat A, exact path", dict(contact_heat="A", heat_path="exact")),
            ("+ restitution feedback", dict(contact_heat="A", heat_path="fast", restitution_feedback=True)),
            ("+ enduring conduction", dict(contact_heat="A", heat_path="fast", restitution_feedback=True,
                                           enduring_conduction=True)))
    for k, (name, eff) in enumerate(rows):
        wall, summary = run_host(variant(base, sim_time, **eff), tmp / f"effects{k}")
        print(f"{name:>44} | {wall / sim_time:22.1f} | {summary['collisions']}")


def host_overhead(base, sim_time: float, tmp: Path) -> None:
    print("\n2. host overhead on the dry scene without effects")
    dry = variant(base, sim_time, contact_heat="none")
    native = min(run_native(dry, tmp / f"native{k}") for k in range(2))
    host = min(run_host(dry, tmp / f"host{k}", whole=True)[0] for k in range(2))
    print(f"native liggghts {native:.2f} s, host {host:.2f} s: overhead {100 * (host / native - 1):+.1f} % "
          f"(best of 2; both with their start-up)")


if __name__ == "__main__":
    main()
