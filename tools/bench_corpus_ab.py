#!/usr/bin/env python3
"""Before and after on users' inputs in one run: tools/bench_corpus.py's inputs run by two
checkouts' ``python -m pyhost run`` (BASELINE's and this one's, each with its own .venv),
alternating which goes first, and plain ``liggghts -in`` after them, for a few rounds. Prints
each round and the medians: wall seconds, the goal of issue 47 (1.3 native + 0.5 s), and the
CPU seconds of each command (user + system of all its processes and threads: the picture
process and the output thread included), which a loaded machine moves much less than wall time.

    .venv/bin/python tools/bench_corpus_ab.py --baseline /path/to/old/checkout [--rounds 3]
        [--only silo-heat box-27k] [--cfdem CFDEMcoupling-PUBLIC checkout] [--work DIR]
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import bench_corpus as bc  # noqa: E402
import corpus  # noqa: E402


def inputs(only, cfdem: Path | None, work: Path) -> dict:
    """name -> (case folder, its script (None: a box scene), native variables, host options)."""
    jobs = {}
    for tut in corpus.TUTORIALS:
        if tut.name in bc.SCRIPTS and tut.name in only:
            jobs[tut.name] = (corpus.prepare(tut, None, work), bc.SCRIPTS[tut.name], [], [])
    for name, (folder, script, density) in bc.CFDEM.items():
        if name in only and cfdem is not None:
            copy = work / name
            shutil.rmtree(copy, ignore_errors=True)
            shutil.copytree(cfdem / folder, copy)
            (copy / "post").mkdir(exist_ok=True)
            (copy / "case.toml").write_text(corpus.liggghts_scene(script, density, types="[1, 2]"))
            jobs[name] = (copy, script, [], [])
    for name, (script, variables, options) in bc.OWN.items():
        if name in only:
            copy = work / name
            shutil.rmtree(copy, ignore_errors=True)
            shutil.copytree(ROOT / "cases" / name, copy, ignore=shutil.ignore_patterns("output", "post"))
            (copy / "post").mkdir()
            jobs[name] = (copy, script, variables, options)
    if bc.BOX in only:
        jobs[bc.BOX] = (bc.box_27k(work), None, [], [])
    return jobs


def timed(cmd, cwd) -> tuple[float, float]:
    """Wall and CPU seconds of a command (its children's rusage)."""
    before, t = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    wall, after = time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed (rc {r.returncode}): {r.stderr[-800:]}")
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", type=Path, required=True, help="the other checkout (its .venv set up)")
    ap.add_argument("--rounds", type=int, default=3)
    names = list(bc.SCRIPTS) + list(bc.CFDEM) + list(bc.OWN) + [bc.BOX]
    ap.add_argument("--only", nargs="+", choices=names, default=names)
    ap.add_argument("--cfdem", type=Path, help="a CFDEMcoupling-PUBLIC checkout, for fillCylinder")
    ap.add_argument("--work", type=Path, default=Path("/tmp/collheat-bench-corpus-ab"))
    args = ap.parse_args(argv)
    args.work.mkdir(parents=True, exist_ok=True)
    trees = {"baseline": args.baseline.resolve(), "this": ROOT}
    jobs = inputs(args.only, args.cfdem, args.work)
    got = {name: {k: [] for k in ("native", *trees)} for name in jobs}
    for rnd in range(args.rounds):
        for name, (copy, script, variables, options) in jobs.items():
            for tree in (list(trees) if rnd % 2 == 0 else list(trees)[::-1]):
                out = args.work / f"{name}-{tree}-output"
                got[name][tree].append(timed([str(trees[tree] / ".venv" / "bin" / "python"), "-m", "pyhost", "run",
                                              str(copy), "--out", str(out), "--overwrite", *options], trees[tree]))
            native = args.work / f"{name}-native"
            shutil.rmtree(native, ignore_errors=True)
            if script is None:          # a box scene: the input the host generated
                shutil.copytree(args.work / f"{name}-this-output" / "dem", native)
                script = "in.dem"
            else:
                shutil.copytree(copy, native)
            got[name]["native"].append(timed(["liggghts", "-in", script, "-log", "log.native", "-screen", "/dev/null",
                                              *variables], native))
            g = got[name]
            print(f"round {rnd + 1} {name:<15} wall native {g['native'][-1][0]:6.2f} baseline {g['baseline'][-1][0]:6.2f} "
                  f"this {g['this'][-1][0]:6.2f}; CPU {g['native'][-1][1]:6.2f} {g['baseline'][-1][1]:6.2f} "
                  f"{g['this'][-1][1]:6.2f}; load {os.getloadavg()[0]:.1f}", flush=True)
    print(f"\nmedians of {args.rounds}: {'input':<15} {'native':>7} {'baseline':>9} {'this':>7} {'goal':>7} | CPU s: "
          f"{'native':>7} {'baseline':>9} {'this':>7}")
    for name, g in got.items():
        wall = {k: statistics.median(w for w, _ in v) for k, v in g.items()}
        cpu = {k: statistics.median(c for _, c in v) for k, v in g.items()}
        print(f"{'':>18}{name:<15} {wall['native']:7.2f} {wall['baseline']:9.2f} {wall['this']:7.2f} "
              f"{1.3 * wall['native'] + 0.5:7.2f} |        {cpu['native']:7.2f} {cpu['baseline']:9.2f} {cpu['this']:7.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
