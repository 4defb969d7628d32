"""``python -m pyhost run CASE``: run a case's scene (``CASE/case.toml``) with the engines."""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path

from pyhost.commands.pictures import draw, painter

HELP = "run a case: DEM (+ fluid) with collision heat as its case.toml asks"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("case", type=Path, help="case folder holding case.toml")
    p.add_argument("--out", type=Path, default=None, help="output folder (default CASE/output)")
    p.add_argument("--test", action="store_true", help="smoke run: only time.test_end (default end/10)")
    p.add_argument("--overwrite", action="store_true", help="replace the run already in the output folder")
    p.add_argument("--restart", action="store_true", help="continue the run in the output folder from its "
                   "checkpoint (output.checkpoint), appending to its output")
    p.add_argument("--extend", type=float, default=0.0, metavar="SECONDS",
                   help="with --restart: the run goes on SECONDS of simulated time longer than its case asks "
                   "(a box scene's time.end, a script's last run), e.g. a finished run from its last checkpoint")


def resolved(scene) -> dict:
    d = dataclasses.asdict(scene)
    d["path"] = str(scene.path)
    return d


def run(args) -> int:
    """Serial, or rank 0 under mpirun (the other ranks follow: ``pyhost.engines.ranks``)."""
    from pyhost.engines.ranks import Follower, Link, world

    comm = world()
    if comm is not None and comm.Get_rank() != 0:
        return Follower(comm).serve()
    if comm is None:
        return run_case(args, None)
    from pyhost import signals
    from pyhost.exitcodes import classify

    link = Link(comm)
    try:
        with signals.deferred():        # a signal stops rank 0 between collective calls, never inside one
            return run_case(args, link)
    except BaseException as exc:
        if link.broken:                 # the followers may wait in another call: end them all
            code, message = classify(exc)
            print(f"error: {message}", file=sys.stderr)
            link.abort(code)
        raise
    finally:
        link.close()


def run_case(args, link) -> int:
    # The picture process first, before the scene is read: a short run ends waiting for its
    # warm-up (1.3 s CPU of imports) and drawing. Ended at once where the scene asks for no
    # pictures, and when the run fails (no pictures of a failed run).
    pictures = painter((args.out or args.case / "output").resolve())
    try:
        return _run_case(args, link, pictures)
    except BaseException:
        pictures.kill()
        pictures.wait()
        raise


def _run_case(args, link, pictures) -> int:
    from pyhost.exitcodes import UserError
    from pyhost.outdir import prepare_output, write_atomic
    from pyhost.scene import load_scene
    from pyhost.world import simulate

    scene = load_scene((args.case / "case.toml").absolute())    # the run changes directory
    if args.test and not scene.scripted:
        end = scene.time.test_end or scene.time.end / 10
        scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, end=end))
    effects = scene.effects_summary()
    out = (args.out or args.case / "output").resolve()
    resume, extend = None, args.extend
    if not (math.isfinite(extend) and extend >= 0):
        raise UserError(f"--extend: simulated seconds >= 0, got {extend:g}")
    if extend and not args.restart:
        raise UserError("--extend continues a run from its checkpoint: give it with --restart (a new run: "
                        "time.end or the script's runs in the case)")
    if args.restart:
        from pyhost.checkpoint import load

        if args.overwrite:
            raise UserError("--restart continues the run in the output folder, --overwrite replaces it: give one")
        resume = load(out, scene, extend)
        if extend and not scene.scripted:
            scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, end=scene.time.end + extend))
    else:
        prepare_output(out, args.overwrite)
    # the resolved scene (about 150 lines) goes to its file; the screen names the file
    write_atomic(out / "scene.json", json.dumps(resolved(scene), indent=1, default=str))
    print(f"scene: {scene.path}, resolved in {out / 'scene.json'}")
    print("active effects:", ", ".join(k for k, on in effects.items() if on) or "none (plain DEM)")
    if link is not None:
        print(f"MPI: LIGGGHTS on {link.size} ranks; the host on rank 0")
    if not scene.output.pictures:
        pictures.kill()
        pictures.wait()
    if scene.output.vtk:
        from pyhost.output import preload
        preload()                       # the frames' writer, loaded while the engines start
    summary = simulate(scene, out, test=args.test, resume=resume, extend=extend, link=link)
    print("summary:", json.dumps(summary, indent=1))
    if scene.output.pictures:
        code = draw(pictures)
        if code != 0:
            print(f"warning: pictures failed (exit {code}); the run's data are in {out}")
    return 0
