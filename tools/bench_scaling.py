"""Scaling of the coupled host with LIGGGHTS' own MPI: the dry granular gas of
cases/hot-cold-box grown to N particles at its packing (as ``bench_host.py`` section 4),
heat A on the fast path, run serially and with ``mpirun -np R``.

For each N and R it prints: wall time per DEM step with heat on and plain (no contact
sampling at all), the heat-on / plain ratio, the cost per collision (extra wall time of heat
over plain / collisions), the peak resident memory (rank 0 and rank 1, and the sum over
ranks), and where the heat-on run's time went: LIGGGHTS (its run chunks, timed on rank 0,
which includes waiting for the other ranks), the host (the rest: the plugin, the
bookkeeping, output) and, of the host's, rank 0's collective exchanges ("comm": its gathers,
scatters and orders to the other ranks, including waiting for them to answer). A dry scene
has no OpenFOAM share. With ``--per-rank`` each rank's own times are printed too (inside
LIGGGHTS' runs, in collective exchanges, and the rest) as one JSON line per run.

``--outputs default`` keeps the case's own outputs (VTK frames at the start, every
output.every and at the end, history rows, the collision log); the default ``bench`` writes
no VTK (as before). Pictures are drawn by a process of their own after a run (``pyhost run``),
not by ``simulate``: they are not in these figures. Wall times
count the coupled run from its first DEM step, not the engines' set-up. Each (N, R, effect)
runs in a fresh process (a fresh ``mpirun``); the rows come from one run of this script.
Compare them as ratios: the machine may be shared.

With ``--case CASE`` (e.g. cases/bed-25k): that case as it is (fluid included) for ``--time``
s, heat as its scene says against none, with the share of OpenFOAM (collheatFoam's
exchanges and steps, timed on rank 0, including the wait for an advance that ran beside the
DEM) beside LIGGGHTS' and the host's; the fluid solver runs on as many ranks as LIGGGHTS
(``[fluid] ranks``). The serial run is measured twice: the engines taking turns (``[fluid]
overlap = "never"``: one process works at a time, the time of one core) and the fluid advancing
beside the DEM ("auto": two cores); the speed-up is against the first.

DEM steps per run: --time / 1e-6 s (the gas's step), so ``--time 1e-3`` is 1,000 steps.

Run: .venv/bin/python tools/bench_scaling.py [--particles 1000 10000 100000] [--ranks 1 2]
     [--time 2e-4] [--repeat 1] [--case cases/bed-25k] [--outputs bench|default] [--per-rank]
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_host import CASE, scaled, variant  # noqa: E402

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


class Timed:
    """The DEM as the loop sees it: when it first steps, and the time inside LIGGGHTS' runs."""

    def __init__(self, dem, clock=None):
        self.dem, self.started, self.in_dem, self.clock = dem, None, 0.0, clock
        self.comm_before = 0.0         # rank 0's time in collective exchanges before the first step

    def __getattr__(self, name):
        return getattr(self.dem, name)

    def run(self, steps: int) -> None:
        t = time.perf_counter()
        if self.started is None and self.clock is not None:
            self.comm_before = self.clock.spent["comm"]
        self.started = self.started or t
        self.dem.run(steps)
        self.in_dem += time.perf_counter() - t


class TimedFluid:
    """The fluid solver as the loop sees it: the time inside its exchanges and steps."""

    def __init__(self, fluid, counting):
        self.fluid, self.inside, self.counting = fluid, 0.0, counting

    def __getattr__(self, name):
        attr = getattr(self.fluid, name)
        if name not in ("particle_forces", "cell_fluid", "advance", "fields", "temperature"):
            return attr

        def timed(*args, **kwargs):
            t = time.perf_counter()
            try:
                return attr(*args, **kwargs)
            finally:
                if self.counting():             # from the first coupled DEM step, as the wall time
                    self.inside += time.perf_counter() - t
        return timed


class Clock:
    """Wall time [s] spent inside some functions of this process, patched in place."""

    def __init__(self):
        self.spent = dict(liggghts=0.0, comm=0.0)

    def patch(self, owner, name: str, key: str) -> None:
        inner = getattr(owner, name)

        def timed(*args, **kwargs):
            t = time.perf_counter()
            try:
                return inner(*args, **kwargs)
            finally:
                self.spent[key] += time.perf_counter() - t
        setattr(owner, name, timed)


def clock_rank() -> Clock:
    """This rank's times: LIGGGHTS' runs, and rank 0's collective exchanges with the others
    (the followers' own part of each is inside their order's handling, counted as the rest)."""
    import pyhost.engines.dem as dem_module
    import pyhost.engines.ranks as ranks
    from pyhost.engines.liggghts import Liggghts

    clock = Clock()
    clock.patch(Liggghts, "run", "liggghts")
    for owner in (ranks, dem_module):
        if hasattr(owner, "gather_arrays"):
            clock.patch(owner, "gather_arrays", "comm")
    for name in ("gather", "scatter", "order"):
        clock.patch(ranks.Link, name, "comm")
    return clock


def worker(n: int, sim_time: float, heat: str, out: Path) -> None:
    """One run (under mpirun or not); rank 0 prints one JSON line. ``n`` > 0: the grown gas
    with ``n`` particles; ``n`` = 0: the case in the environment variable BENCH_CASE as it is,
    for ``sim_time`` s."""
    from pyhost.world import simulate
    from pyhost.engines.ranks import Follower, Link, world
    from pyhost.scene import load_scene

    comm = world()
    rank = comm.Get_rank() if comm is not None else 0
    clock = clock_rank()
    begun = time.perf_counter()
    if rank != 0:
        Follower(comm).serve()
        comm.gather((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, clock.spent,
                     time.perf_counter() - begun), root=0)
        return
    link = Link(comm) if comm is not None else None
    if n:
        scene = variant(scaled(load_scene(CASE), n), sim_time, contact_heat=heat, heat_path="fast")
        if os.environ.get("BENCH_OUTPUTS") == "default":        # the case's own VTK frames, every output.every
            scene = dataclasses.replace(scene, output=dataclasses.replace(
                scene.output, vtk=True, every=load_scene(CASE).output.every))
    else:
        base = load_scene(Path(os.environ["BENCH_CASE"]).resolve() / "case.toml")
        scene = variant(base, sim_time, contact_heat=heat)
        if scene.fluid is not None:     # the fluid on as many ranks as LIGGGHTS
            scene = dataclasses.replace(scene, fluid=dataclasses.replace(
                scene.fluid, ranks=comm.Get_size() if comm is not None else 1,
                overlap=os.environ.get("BENCH_OVERLAP", scene.fluid.overlap)))
    timed = {}

    def wrap(dem):
        timed["dem"] = Timed(dem, clock)
        return timed["dem"]

    def wrap_fluid(fluid):
        timed["fluid"] = TimedFluid(fluid, lambda: "dem" in timed and timed["dem"].started is not None)
        return timed["fluid"]

    try:
        summary = simulate(scene, out.resolve(), progress_every=1e9, wrap=wrap, wrap_fluid=wrap_fluid, link=link)
        end = time.perf_counter()
    finally:
        if link is not None:
            link.close()
    mine = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, clock.spent, time.perf_counter() - begun)
    every = [mine] if comm is None else comm.gather(mine, root=0)
    rss = [r for r, _, _ in every]
    d = timed["dem"]
    print(json.dumps(dict(particles=sum(g.count for g in scene.particles), ranks=len(rss),
                          steps=summary["steps"], wall=end - d.started, in_dem=d.in_dem,
                          in_fluid=timed["fluid"].inside if "fluid" in timed else 0.0,
                          in_comm=clock.spent["comm"] - d.comm_before,
                          collisions=summary["collisions"], rss_max_mb=max(rss) / 1024, rss_sum_mb=sum(rss) / 1024,
                          rss_mb=[r / 1024 for r in rss],
                          per_rank=[dict(liggghts=s["liggghts"], comm=s["comm"], process=w) for _, s, w in every],
                          balance=summary.get("energy_balance_error"))))


def measure(n: int, ranks: int, sim_time: float, heat: str, tmp: Path, case: Path | None = None,
            overlap: str = "auto", outputs: str = "bench") -> dict:
    cmd = [sys.executable, __file__, "--worker", str(n), str(sim_time), heat, str(tmp / f"{heat}-{n}-{ranks}")]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd
    env = dict(ENV, BENCH_CASE=str(case), BENCH_OVERLAP=overlap) if case else dict(ENV, BENCH_OUTPUTS=outputs)
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"run failed: {' '.join(cmd)}\n{done.stdout[-2000:]}{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--particles", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--time", type=float, default=2e-4, help="simulated time per run [s] (DEM step 1e-6 s)")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each (best of)")
    ap.add_argument("--case", type=Path, help="instead of the gas: this box case (e.g. cases/bed-25k) for --time s, "
                                              "heat as its scene says, against the same without heat")
    ap.add_argument("--outputs", choices=("bench", "default"), default="bench",
                    help="bench: no VTK frames (as before); default: the case's own (frames at the start, every "
                         "output.every and at the end)")
    ap.add_argument("--per-rank", action="store_true", help="also each run's per-rank times and memory (JSON)")
    ap.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        n, t, heat, out = args.worker
        worker(int(n), float(t), heat, Path(out))
        return
    if args.case:
        return bench_case(args)
    print(f"dry granular gas (hot-cold-box grown at its packing), {args.time:g} s simulated per run "
          f"({round(args.time / 1e-6)} steps), heat A fast path, outputs '{args.outputs}'; best of {args.repeat}; "
          "one run of this script")
    print(f"{'particles':>9} | {'ranks':>5} | {'plain ms/st':>11} | {'heat ms/st':>10} | {'ratio':>5} | "
          f"{'collisions':>10} | {'us/coll':>7} | {'RSS r0/r1/sum MB':>16} | {'LIGGGHTS':>8} | {'host':>5} | "
          f"{'comm':>5} | {'speed-up':>8}")
    with tempfile.TemporaryDirectory() as tmp:
        first = {}
        for n in args.particles:
            for ranks in args.ranks:
                runs = {h: min((measure(n, ranks, args.time, h, Path(tmp), outputs=args.outputs)
                                for _ in range(args.repeat)), key=lambda r: r["wall"]) for h in ("none", "A")}
                p, h = runs["none"], runs["A"]
                per_step = {k: r["wall"] / r["steps"] for k, r in runs.items()}
                extra = (h["wall"] - p["wall"] * h["steps"] / p["steps"]) / max(h["collisions"], 1)
                first.setdefault(n, per_step["A"])
                print(f"{h['particles']:>9} | {ranks:>5} | {1e3 * per_step['none']:11.3f} | "
                      f"{1e3 * per_step['A']:10.3f} | {per_step['A'] / per_step['none']:5.2f} | "
                      f"{h['collisions']:>10} | {1e6 * extra:7.1f} | {rss_text(h):>16} | "
                      f"{h['in_dem'] / h['wall']:8.0%} | {1 - h['in_dem'] / h['wall']:5.0%} | "
                      f"{h['in_comm'] / h['wall']:5.0%} | {first[n] / per_step['A']:8.2f}", flush=True)
                if args.per_rank:
                    for heat, r in runs.items():
                        print("  " + json.dumps(dict(heat=heat, particles=n, ranks=ranks, wall=round(r["wall"], 3),
                                                     balance=r["balance"], rss_mb=[round(x) for x in r["rss_mb"]],
                                                     per_rank=[{k: round(v, 3) for k, v in p.items()}
                                                               for p in r["per_rank"]])), flush=True)


def rss_text(run: dict) -> str:
    """Peak resident memory [MB]: rank 0's, rank 1's (if any) and the sum over ranks."""
    rss = run["rss_mb"]
    return "/".join(f"{x:.0f}" for x in rss[:2]) + f"/{run['rss_sum_mb']:.0f}"


def bench_case(args) -> None:
    """A whole case (with its fluid) on each rank count: wall s per simulated s with heat and
    without, and where the heat-on run's time went."""
    from pyhost.scene import load_scene

    scene = load_scene(args.case.resolve() / "case.toml")
    heat = scene.effects.contact_heat
    print(f"{args.case}: {args.time:g} s simulated per run from its initial state, heat {heat} against none; "
          f"best of {args.repeat}; one run of this script")
    runs_of = [(r, o) for r in args.ranks for o in (("never", "auto") if r == 1 and scene.fluid is not None else ("auto",))]
    print(f"{'ranks':>12} | {'plain wall s/s':>14} | {'heat wall s/s':>13} | {'ratio':>5} | {'collisions':>10} | "
          f"{'RSS max/sum MB':>14} | {'LIGGGHTS':>8} | {'OpenFOAM':>8} | {'host':>5} | {'speed-up':>8}")
    with tempfile.TemporaryDirectory() as tmp:
        first = None
        for ranks, overlap in runs_of:
            runs = {h: min((measure(0, ranks, args.time, h, Path(tmp), args.case, overlap) for _ in range(args.repeat)),
                           key=lambda r: r["wall"]) for h in ("none", heat)}
            p, h = runs["none"], runs[heat]
            first = first or h["wall"]
            label = f"{ranks}" + {"never": " (turns)", "auto": " (beside)" if ranks == 1 and scene.fluid else ""}[overlap]
            print(f"{label:>12} | {p['wall'] / args.time:14.0f} | {h['wall'] / args.time:13.0f} | "
                  f"{h['wall'] / p['wall']:5.2f} | {h['collisions']:>10} | "
                  f"{h['rss_max_mb']:6.0f}/{h['rss_sum_mb']:<7.0f} | {h['in_dem'] / h['wall']:8.0%} | "
                  f"{h['in_fluid'] / h['wall']:8.0%} | {1 - (h['in_dem'] + h['in_fluid']) / h['wall']:5.0%} | "
                  f"{first / h['wall']:8.2f}", flush=True)


if __name__ == "__main__":
    main()
