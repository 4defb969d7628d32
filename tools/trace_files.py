#!/usr/bin/env python3
"""How often following a run through its calls moves from file to file (issue 22's measure of
how hard the code is to read): ``python -m pyhost run CASE --test`` traced with
``sys.setprofile`` from the command's start (``run_case``, after the CLI's parser) to the loop's
first ``advance`` (the set-up: the
scene loaded and checked, the world assembled, the engines started, the effects built).

Read as a reader follows the calls: each function once, at its first call (a function called
again is not entered again, nor what it calls). Only the project's own files count (pyhost/,
plugins/), module-level code (imports) not. The current file is that of the innermost project
frame; each change of it is a stop. Printed: the stops, the files, the most entries into one
file, and the returns (entries into a file already left before); then the stops and returns of
each stage of the set-up (``STAGES``: the scene, the world, the script, the effects; the
command's own calls). Run it on another checkout to compare:

    .venv/bin/python tools/trace_files.py [--case cases/two-particles] [--tree PATH] [--list]

``--tree``: the checkout whose pyhost/ and plugins/ are traced (default this one); its
.setup/ (the compiled helper) must exist, or be a link to this one's.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


class Done(Exception):
    """The loop's first advance: the set-up is over."""


STAGES = (("scene", "pyhost/scene.py", "load_scene"), ("world", "pyhost/world.py", "simulate"),
          ("script", "pyhost/run_scene.py", "run_scene"), ("effects", "pyhost/loop.py", "__init__"),
          ("effects", "pyhost/loop.py", "start"))
"""The set-up's stages, each from a call of its function (innermost wins); the command's own
calls (output folder, pictures) are 'command'."""


def stage_of(frame, tree: Path) -> str:
    while frame is not None:
        for name, file, function in STAGES:
            if frame.f_code.co_name == function and frame.f_code.co_filename == str(tree / file):
                return name
        frame = frame.f_back
    return "command"


def trace(tree: Path, case: Path) -> list[tuple[str, str]]:
    """The sequence of project files the set-up of a run of ``case`` passes through, each with
    the stage it is in."""
    sys.path.insert(0, str(tree))
    from pyhost.cli import main

    roots = tuple(str(tree / p) + os.sep for p in ("pyhost", "plugins"))
    seq, done, read, skipping, started = [], [], set(), [], []

    def project(frame):
        while frame is not None:
            f = frame.f_code.co_filename
            if f.startswith(roots) and frame.f_code.co_name != "<module>":
                return f
            frame = frame.f_back
        return None

    def profile(frame, event, arg):
        if event not in ("call", "return") or done:
            return
        if not started:
            if event == "call" and frame.f_code.co_name == "run_case":
                started.append(True)
            else:
                return
        if skipping:                       # inside a function read before: not entered again
            if event == "return" and frame is skipping[-1]:
                skipping.pop()
            return
        code = frame.f_code
        if event == "call":
            if code.co_name == "advance" and code.co_filename.endswith(os.path.join("pyhost", "loop.py")):
                done.append(True)          # what follows (the CLI reporting the stop) is not the set-up
                raise Done
            if code in read:
                skipping.append(frame)
                return
            read.add(code)
        at = frame if event == "call" else frame.f_back
        here = project(at)
        if here is not None and (not seq or seq[-1][0] != here):
            seq.append((here, stage_of(at, tree)))

    with tempfile.TemporaryDirectory() as out:
        sys.setprofile(profile)
        try:
            main(["run", str(case), "--test", "--out", out, "--overwrite"])
        except Done:
            pass
        finally:
            sys.setprofile(None)
    return [(str(Path(f).relative_to(tree)), stage) for f, stage in seq]


def measure(seq: list[tuple[str, str]]) -> dict:
    """Stops, files, the file entered most, returns; and (stops, returns) by stage."""
    entries = Counter(f for f, _ in seq)
    seen, returns, stages = set(), 0, {}
    for f, stage in seq:
        stops, back = stages.get(stage, (0, 0))
        stages[stage] = (stops + 1, back + (f in seen))
        returns += f in seen
        seen.add(f)
    worst = entries.most_common(1)[0] if entries else ("", 0)
    return dict(stops=len(seq), files=len(entries), most_entries=worst, returns=returns, stages=stages)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", type=Path, default=ROOT / "cases" / "two-particles")
    ap.add_argument("--tree", type=Path, default=ROOT)
    ap.add_argument("--list", action="store_true", help="print the files in the order they are entered")
    args = ap.parse_args(argv)
    seq = trace(args.tree.resolve(), args.case.resolve())
    m = measure(seq)
    if args.list:
        print("\n".join(f"{stage:8s} {f}" for f, stage in seq))
    print(f"{args.tree}: {m['stops']} stops in {m['files']} files, {m['returns']} returns to a file already left; "
          f"most entries: {m['most_entries'][1]} into {m['most_entries'][0]}")
    print("by stage (stops, returns): " + ", ".join(f"{name} {s}, {r}" for name, (s, r) in m["stages"].items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
