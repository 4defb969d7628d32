"""``python -m pyhost post DUMP... --scene SCENE.toml``: collision heat of a finished LIGGGHTS
run from its dump files, by the Kosinski et al. models (pyhost/post.py)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from plugins.heat import MODELS
from pyhost.engines.liggghts.names import PAIR_CONTACTS, TEMPERATURE, WALL_CONTACTS

HEAT_PATHS = ("fast", "exact")          # (pyhost.schema.Effects.heat_path)
HELP = "collision heat of a finished LIGGGHTS run from its dump files (models A, B, C)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dumps", nargs="+", help="particle dumps (dump custom, gzipped or not, or custom/vtk); "
                                            "wildcards such as 'post/dump.*' are expanded")
    p.add_argument("--scene", type=Path, required=True,
                   help="TOML with [materials.NAME] (types = [...], temperature) and [[walls]] (fix or plane)")
    p.add_argument("--contacts", nargs="+", default=[], metavar="DUMP",
                   help=f"dump local files of compute {PAIR_CONTACTS} and {WALL_CONTACTS}")
    p.add_argument("--script", type=Path, help="the LIGGGHTS input that wrote the dumps (timestep, computes, "
                                               "mesh wall fixes)")
    p.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                   help="a variable the script takes from LIGGGHTS' command line (liggghts -var NAME VALUE), "
                        "for the script's $NAME in the values post reads")
    p.add_argument("--compute", action="append", default=[], metavar="'ID STYLE KEYWORDS'",
                   help="a contact compute's keywords when there is no script, e.g. 'cp pair/gran/local pos vel id'")
    p.add_argument("--model", choices=(*MODELS, "all"), default="all", help="contact heat model")
    p.add_argument("--heat-path", choices=HEAT_PATHS, default="fast",
                   help="the plugin's evaluation path, as a run's effects.heat_path (fast: tables; exact: the ODE)")
    p.add_argument("--out", type=Path, default=Path("collheat-post"), help="output folder")
    p.add_argument("--dt", type=float, help="DEM time step [s] (default: the script's timestep)")
    p.add_argument("--skip-bad-frames", action="store_true", help="warn about a bad frame, skip it and go on")
    p.add_argument("--temperatures", choices=("own", "dumps"), default="own",
                   help="own: each particle from its first temperature, changed by the models' collision heat (and "
                        f"the script's Temp sets); dumps: the dumped temperature ({TEMPERATURE}) at every frame, as the run's "
                        "own conduction and sources left it, the collisions until the next frame moving heat from there")


def run(args) -> int:
    from pyhost.engines.liggghts.computes import parse_compute
    from pyhost.engines.liggghts.dump_script import read_script
    from pyhost.post import Post
    from pyhost.scene import load_post_scene

    if args.var and not args.script:
        raise ValueError("--var: give --script, the LIGGGHTS input whose variables they are")
    scene = load_post_scene(args.scene)
    script = read_script(args.script, dict(args.var)) if args.script else None
    computes = {c.id: c for c in (parse_compute(text, "--compute: ") for text in args.compute)}
    if args.dt is not None and not args.dt > 0:
        raise ValueError(f"--dt: must be > 0, got {args.dt}")
    post = Post(args.dumps, scene, args.out, contacts=args.contacts, script=script, computes=computes,
                models=tuple(MODELS) if args.model == "all" else (args.model,), dt=args.dt,
                skip_bad_frames=args.skip_bad_frames, temperatures=args.temperatures, heat_path=args.heat_path)
    summary = post.run()
    for w in summary["warnings"]:
        print("warning:", w)
    print("summary:", json.dumps({k: v for k, v in summary.items() if k != "warnings"}, indent=1))
    return 0
