#!/usr/bin/env python3
"""What collision heat costs on users' inputs: each public tutorial of tools/corpus.py run
unchanged by plain LIGGGHTS (``liggghts -in``) and by the host with collision heat A and the
default outputs (``python -m pyhost run``), one after the other in one process, and the
ratio of their wall times. The host's time includes its start-up (Python, the plugin's tables,
LIGGGHTS set-up: about 2 s).

    .venv/bin/python tools/bench_corpus.py [--only packing conveyor] [--cfdem CFDEMcoupling-PUBLIC checkout]

Debian's tutorials: packing, heatTransfer_1, chute_wear, conveyor (liggghts-doc); CFDEM's
fillCylinder (tutorials/cfdemPostproc/fillCylinder/DEM/in.liggghts_init: 2,000 particles of two
types poured into a primitive cylinder; with --cfdem, a checkout of CFDEMcoupling-PUBLIC);
cases/silo-heat, a user's script (STL tube, shaken plate, fix heat/gran): its pour, the 16,000
steps of its ``--test`` run, natively with ``-var n_fill 16000 -var n_settle 0 -var n_shake 0``;
and box-27k, cases/hot-cold-box grown to 27,000 particles for 1,000 steps (a box scene: natively,
the LIGGGHTS input the host generated for it, run by ``liggghts -in``). The machine is shared:
compare the ratios, measured in one run, with nothing else running.
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import corpus  # noqa: E402

SCRIPTS = {"packing": "in.packing", "heatTransfer_1": "in.heatGran", "chute_wear": "in.chute_wear",
           "conveyor": "in.conveyor"}
OWN = {"silo-heat": ("in.liggghts", ["-var", "n_fill", "16000", "-var", "n_settle", "0", "-var", "n_shake", "0"],
                     ["--test"])}
"""Cases of cases/: the script, its native variables and the host's options for the same steps."""
CFDEM = {"fillCylinder": ("tutorials/cfdemPostproc/fillCylinder/DEM", "in.liggghts_init", 200.0)}
"""CFDEMcoupling-PUBLIC's DEM inputs: folder, script and the particles' density [kg/m^3]."""
BOX = "box-27k"
START = 2.0
"""Seconds of the host's start-up that issue 20's goal allows: its ratio is (host - START) / native."""


def box_27k(work: Path) -> Path:
    """cases/hot-cold-box with 27 times its particles (box and regions 3 times longer), run for
    1,000 steps with frames every 500."""
    text = (ROOT / "cases" / "hot-cold-box" / "case.toml").read_text()
    for old, new in (("count = 500", "count = 13500"), ("[0.0, 0.02, 0.0, 0.02, 0.0, 0.02]", "[0.0, 0.06, 0.0, 0.06, 0.0, 0.06]"),
                     ("[0.0, 0.02, 0.0, 0.02, 0.02, 0.04]", "[0.0, 0.06, 0.0, 0.06, 0.06, 0.12]"),
                     ("box = [0.0, 0.02, 0.0, 0.02, 0.0, 0.04]", "box = [0.0, 0.06, 0.0, 0.06, 0.0, 0.12]"),
                     ("end = 0.1\n", "end = 0.001\n"), ("test_end = 0.01\n", "test_end = 0.0005\n"),
                     ("every = 0.01\n", "every = 0.0005\n")):
        if old not in text:
            raise ValueError(f"cases/hot-cold-box/case.toml changed: no {old!r}")
        text = text.replace(old, new)
    copy = work / BOX
    shutil.rmtree(copy, ignore_errors=True)
    copy.mkdir(parents=True)
    (copy / "case.toml").write_text(text)
    return copy


def timed(cmd, cwd) -> tuple[float, subprocess.CompletedProcess]:
    start = time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    return time.perf_counter() - start, r


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", choices=list(SCRIPTS) + list(CFDEM) + list(OWN) + [BOX])
    ap.add_argument("--cfdem", type=Path, help="a CFDEMcoupling-PUBLIC checkout, for fillCylinder")
    ap.add_argument("--work", type=Path, default=Path("/tmp/collheat-bench-corpus"))
    args = ap.parse_args(argv)
    args.work.mkdir(parents=True, exist_ok=True)
    jobs = []                           # (name, case folder, script, its native variables, host options)
    for tut in corpus.TUTORIALS:
        if tut.name in SCRIPTS and (not args.only or tut.name in args.only):
            copy = corpus.prepare(tut, None, args.work)
            jobs.append((tut.name, copy, SCRIPTS[tut.name], [], []))
    for name, (folder, script, density) in CFDEM.items():
        if args.only and name not in args.only:
            continue
        if args.cfdem is None:
            print(f"{name}: skipped (give --cfdem, a CFDEMcoupling-PUBLIC checkout)")
            continue
        copy = args.work / name
        shutil.rmtree(copy, ignore_errors=True)
        shutil.copytree(args.cfdem / folder, copy)
        (copy / "post").mkdir(exist_ok=True)
        (copy / "case.toml").write_text(corpus.liggghts_scene(script, density, types="[1, 2]"))
        jobs.append((name, copy, script, [], []))
    for name, (script, variables, options) in OWN.items():
        if not args.only or name in args.only:
            copy = args.work / name
            shutil.rmtree(copy, ignore_errors=True)
            shutil.copytree(ROOT / "cases" / name, copy, ignore=shutil.ignore_patterns("output", "post"))
            (copy / "post").mkdir()
            jobs.append((name, copy, script, variables, options))
    if not args.only or BOX in args.only:
        copy = box_27k(args.work)
        jobs.append((BOX, copy, None, [], []))
    print(f"{'input':<16} {'native s':>9} {'host s':>8} {'ratio':>6} {'(host-2)/native':>16}  host: collisions")
    rows = []
    for name, copy, script, variables, options in jobs:
        out = copy / "host-output"
        native_copy = args.work / (name + "-native")
        shutil.rmtree(native_copy, ignore_errors=True)
        if script is not None:          # plain LIGGGHTS first, on a copy of the input as given
            shutil.copytree(copy, native_copy)
            native, n = timed(["liggghts", "-in", script, "-log", "log.native", "-screen", "/dev/null", *variables],
                              native_copy)
        host, r = timed([sys.executable, "-m", "pyhost", "run", str(copy), "--out", str(out), "--overwrite", *options],
                        ROOT)
        if r.returncode:
            print(f"{name:<16} host run failed (rc {r.returncode}): {r.stderr.strip().splitlines()[-1:]}")
            continue
        if script is None:              # a box scene: the input the host generated, as plain LIGGGHTS runs it
            shutil.copytree(out / "dem", native_copy)
            native, n = timed(["liggghts", "-in", "in.dem", "-log", "log.native", "-screen", "/dev/null"], native_copy)
        if n.returncode:
            print(f"{name:<16} native run failed (rc {n.returncode})")
            continue
        s = json.loads((out / "summary.json").read_text())
        rows.append((name, native, host))
        print(f"{name:<16} {native:9.2f} {host:8.2f} {host / native:6.2f} {(host - START) / native:16.2f}  "
              f"{s['collisions']}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
