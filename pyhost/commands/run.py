"""``python -m pyhost run CASE``: run a case's scene (``CASE/case.toml``) with the engines."""
from __future__ import annotations

import argparse
import dataclasses
import json
import subprocess
import sys
from pathlib import Path

HELP = "run a case: DEM (+ fluid) with collision heat as its case.toml asks"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("case", type=Path, help="case folder holding case.toml")
    p.add_argument("--out", type=Path, default=None, help="output folder (default CASE/output)")
    p.add_argument("--test", action="store_true", help="smoke run: only time.test_end (default end/10)")
    p.add_argument("--overwrite", action="store_true", help="replace the run already in the output folder")


def resolved(scene) -> dict:
    d = dataclasses.asdict(scene)
    d["path"] = str(scene.path)
    return d


def start_fluid(scene, folder: Path):
    """The scene's fluid: a box case (pyhost.fluid_case) over the domain and the plenum below
    it, inlet at its z lo, outlet at z hi, solved by collheatFoam every time.couple_every DEM
    steps. The inlet value is the fluid velocity there, so the superficial velocity asked for
    needs a particle-free inlet (a plenum) to be met."""
    from pyhost.fluid_case import box_case
    from pyhost.openfoam import FluidSolver

    f, box = scene.fluid, scene.domain.box
    boundaries = {face: f.sides for face in ("xlo", "xhi", "ylo", "yhi")}
    inlet = (("inlet_table", [(t, (0.0, 0.0, u)) for t, u in f.inlet_table]) if f.inlet_table
             else ("inlet", (0.0, 0.0, f.inlet_velocity)))
    boundaries.update(zlo=inlet, zhi="outlet")
    lo = [box[0], box[2], box[4] - f.plenum]
    case = box_case(folder, lo=lo, hi=box[1::2], cells=f.cells, boundaries=boundaries, rho=f.density,
                    nu=f.viscosity / f.density, gravity=scene.domain.gravity,
                    dt=scene.time.couple_every * scene.time.dem_step)
    return FluidSolver(case, drag=f.drag, alpha_min=f.alpha_min).start()


def run(args) -> int:
    from pyhost.dem import SceneDem
    from pyhost.dem_input import dem_collision_time, place_particles
    from pyhost.loop import Coupling
    from pyhost.outdir import prepare_output, write_atomic
    from pyhost.scene import load_scene

    scene = load_scene(args.case / "case.toml")
    if args.test:
        end = scene.time.test_end or scene.time.end / 10
        scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, end=end))
    effects = scene.effects_summary()
    out = args.out or args.case / "output"
    prepare_output(out, args.overwrite)
    print("scene:", json.dumps(resolved(scene), indent=1, default=str))
    print("active effects:", ", ".join(k for k, on in effects.items() if on) or "none (plain DEM)")
    write_atomic(out / "scene.json", json.dumps(resolved(scene), indent=1, default=str))
    particles = place_particles(scene)
    t_c = dem_collision_time(scene, 1.0)
    if scene.time.dem_step > t_c / 20:
        print(f"warning: time.dem_step = {scene.time.dem_step:g} s resolves a 1 m/s DEM collision "
              f"({t_c:.3g} s) with fewer than 20 steps")
    fluid = start_fluid(scene, out / "fluid") if effects["fluid_solver"] else None
    try:
        dem = SceneDem(scene, particles, out / "dem", fluid_force=fluid is not None)
        try:
            summary = Coupling(scene, dem, particles, out, fluid=fluid).run()
        finally:
            dem.close()
    finally:
        if fluid is not None:
            fluid.stop()
    print("summary:", json.dumps(summary, indent=1))
    if scene.output.pictures:        # own process: see pyhost/commands/pictures.py
        drawn = subprocess.run([sys.executable, "-m", "pyhost", "pictures", str(out)])
        if drawn.returncode != 0:
            print(f"warning: pictures failed (exit {drawn.returncode}); the run's data are in {out}")
    return 0
