#!/usr/bin/env python3
"""What collision heat costs on users' inputs: each public tutorial of tools/corpus.py run
unchanged by plain LIGGGHTS (``liggghts -in``) and by the host with collision heat A and the
default outputs (``python -m pyhost run``), one after the other in one process, and the
ratio of their wall times. The host's time includes its start-up (Python, the plugin's tables,
LIGGGHTS set-up: about 2 s).

    .venv/bin/python tools/bench_corpus.py [--only packing conveyor] [--contacts samples]

Debian's tutorials: packing, heatTransfer_1, chute_wear, conveyor (liggghts-doc); and cases/silo-heat,
a user's script (STL tube, shaken plate, fix heat/gran): its pour, the 16,000 steps of its
``--test`` run, natively with ``-var n_fill 16000 -var n_settle 0 -var n_shake 0``. The machine
is shared: compare the ratios, measured in one run, with nothing else running.
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


def timed(cmd, cwd) -> tuple[float, subprocess.CompletedProcess]:
    start = time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    return time.perf_counter() - start, r


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", choices=list(SCRIPTS) + list(OWN))
    ap.add_argument("--work", type=Path, default=Path("/tmp/collheat-bench-corpus"))
    ap.add_argument("--contacts", choices=("events", "samples"), default="events",
                    help="[time] contacts of the host's runs (samples: as before contact events)")
    args = ap.parse_args(argv)
    args.work.mkdir(parents=True, exist_ok=True)
    jobs = []                           # (name, case folder, script, its native variables, host options)
    for tut in corpus.TUTORIALS:
        if tut.name in SCRIPTS and (not args.only or tut.name in args.only):
            copy = corpus.prepare(tut, None, args.work)
            toml = copy / tut.case_dir / "case.toml"
            toml.write_text(toml.read_text() + f'\n[time]\ncontacts = "{args.contacts}"\n')
            jobs.append((tut.name, copy, SCRIPTS[tut.name], [], []))
    for name, (script, variables, options) in OWN.items():
        if not args.only or name in args.only:
            copy = args.work / name
            shutil.rmtree(copy, ignore_errors=True)
            shutil.copytree(ROOT / "cases" / name, copy, ignore=shutil.ignore_patterns("output", "post"))
            (copy / "post").mkdir()
            toml = copy / "case.toml"
            toml.write_text(toml.read_text().replace("[time]\n", f'[time]\ncontacts = "{args.contacts}"\n', 1))
            jobs.append((name, copy, script, variables, options))
    print(f"{'input':<16} {'native s':>9} {'host s':>8} {'ratio':>6}  host: collisions, contacts")
    rows = []
    for name, copy, script, variables, options in jobs:
        native_copy = args.work / (name + "-native")
        shutil.rmtree(native_copy, ignore_errors=True)
        shutil.copytree(copy, native_copy)
        native, r = timed(["liggghts", "-in", script, "-log", "log.native", "-screen", "/dev/null", *variables],
                          native_copy)
        if r.returncode:
            print(f"{name:<16} native run failed (rc {r.returncode})")
            continue
        out = copy / "host-output"
        host, r = timed([sys.executable, "-m", "pyhost", "run", str(copy), "--out", str(out), "--overwrite", *options],
                        ROOT)
        if r.returncode:
            print(f"{name:<16} host run failed (rc {r.returncode}): {r.stderr.strip().splitlines()[-1:]}")
            continue
        s = json.loads((out / "summary.json").read_text())
        added = next((ln for ln in r.stdout.splitlines() if ln.startswith("host adds to the script")), "")
        mode = "events" if "collheat_events" in added else "samples"
        rows.append((name, native, host))
        print(f"{name:<16} {native:9.1f} {host:8.1f} {host / native:6.2f}  {s['collisions']}, {mode}",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
