"""World assembly: from a loaded scene to running engines and the loop that couples them.

``simulate`` is the one entry: it builds the DEM (the user's LIGGGHTS script, or the box
world a box scene describes: particles placed, walls, the LIGGGHTS input written), starts the
fluid solver only when the scene has a fluid (a box case, or the user's OpenFOAM case copied
and meshed), and hands both to ``pyhost.run_scene.run_scene``. The ``run`` command, the tests and
the benchmarks call it; it prints nothing of its own but warnings.
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path


def _case_copy_filter(target: Path, source: Path, start: str | None = None):
    """What a copy of a user's OpenFOAM case ``source`` leaves out: earlier solver output (time
    folders other than 0 and ``start``, the one its controlDict starts from, processor folders,
    logs, the pipes) and the run's own output folder, which lies inside the case when case.toml
    sits in it (``case = "."``, CFDEM's layout), as do earlier runs' output folders (holding
    scene.json) written with another --out."""
    target, source = Path(target).resolve(), Path(source).resolve()
    solver_output = shutil.ignore_patterns("processor*", ".link", "log.*", "[1-9]*", "0.[0-9]*")

    def ignore(folder, names):
        here = Path(folder).resolve()
        kept = {start} if here == source else set()
        return (set(solver_output(folder, names)) - kept) | {n for n in names if target.is_relative_to(here / n)
                                                             or (here / n / "scene.json").is_file()}
    return ignore


def _set_aside_writes(folder: Path, restart: Path | None) -> list[Path]:
    """A restart's copy of the user's case replaces ``folder``: the time folders the solver
    wrote there of its own (its controlDict's writeControl) up to the checkpoint's time, moved
    aside to OUT/.fluid-earlier to go back into the new copy (those after it are written again).
    Returns where they are."""
    from pyhost.engines.fluid_case import is_time_name

    if restart is None or not Path(folder).is_dir():
        return []
    saved = [float(p.name) for p in Path(restart).rglob("*") if p.is_dir() and is_time_name(p.name)]
    if not saved:
        return []
    aside = Path(folder).parent / ".fluid-earlier"
    shutil.rmtree(aside, ignore_errors=True)
    aside.mkdir()
    moved = []
    for p in sorted(Path(folder).iterdir()):
        if p.is_dir() and is_time_name(p.name) and p.name != "0" and float(p.name) <= saved[0] * (1 + 1e-9):
            moved.append(Path(shutil.move(str(p), aside / p.name)))
    if not moved:
        aside.rmdir()
    return moved


def start_fluid(scene, folder: Path, restart: Path | None = None):
    """The scene's fluid (``restart``: a checkpoint's saved fluid to continue from): a box case (pyhost.engines.fluid_case) over the domain and the plenum below
    it, inlet at its z lo, outlet at z hi, solved by collheatFoam every time.couple_every DEM
    steps. The inlet value is the fluid velocity there, so the superficial velocity asked for
    needs a particle-free inlet (a plenum) to be met. With convection the gas has a
    temperature: the scene's initial and inlet temperatures, walls of the scene's [[walls]]
    on the box's sides at their fixed temperature, the other walls adiabatic."""
    from foamlib import FoamFile

    from pyhost.engines.fluid_case import (add_final_solvers, adopt_mean_velocity_force, adopt_other_solver,
                                           adopt_piso, adopt_void_fraction, box_case, case_density, start_time)
    from pyhost.engines.openfoam import FluidSolver

    f = scene.fluid
    energy = scene.effects.convection != "none"
    solver = dict(drag=f.drag, alpha_min=f.alpha_min, energy=energy, nprocs=f.ranks, void_fraction=f.void_fraction,
                  restart=restart, ddt_alpha=f.ddt_alpha)     # the same for the user's case and the box
    if f.case:                          # the user's own case, copied: the host never writes into it
        source = (scene.folder / f.case).resolve()
        earlier = _set_aside_writes(folder, restart)
        shutil.rmtree(folder, ignore_errors=True)
        shutil.copytree(source, folder, symlinks=True,
                        ignore=_case_copy_filter(folder, source, None if restart else start_time(source)[1]))
        for p in earlier:
            shutil.move(str(p), folder / p.name)
        if earlier:
            earlier[0].parent.rmdir()
        for note in adopt_other_solver(folder):
            print(f"fluid case: {note}")
        adopt_void_fraction(folder)
        add_final_solvers(folder)
        if adopt_piso(folder):
            print("fluid case: fvSolution's PISO settings run as collheatFoam's PIMPLE (one outer corrector)")
        for entry in adopt_mean_velocity_force(folder):
            print(f"fluid case: fvOptions {entry} runs as collheatFoam's collheatMeanVelocityForce")
        props = FoamFile(folder / "constant" / "transportProperties")
        rho, where = case_density(folder)
        if where.startswith("0/rho"):   # collheatFoam reads rho beside nu
            props["rho"] = FoamFile.Dimensioned(name="rho", value=rho, dimensions=[1, -3, 0, 0, 0, 0, 0])
        if energy:                      # the gas's properties are the scene's, given once
            props.update({"Cp": f.heat_capacity, "kappa": f.conductivity})
        _mesh(folder, source, str(scene.path))
        return FluidSolver(folder, **solver).start()
    box = scene.domain.box
    boundaries = {face: f.sides for face in ("xlo", "xhi", "ylo", "yhi")}
    inlet = (("inlet_table", [(t, (0.0, 0.0, u)) for t, u in f.inlet_table]) if f.inlet_table
             else ("inlet", (0.0, 0.0, f.inlet_velocity)))
    boundaries.update(zlo=inlet, zhi="outlet")
    lo = [box[0], box[2], box[4] - f.plenum]
    sides = {w.plane: w.temperature for w in scene.walls if w.plane in boundaries and w.temperature > 0}
    case = box_case(folder, lo=lo, hi=box[1::2], cells=f.cells, boundaries=boundaries, rho=f.density,
                    nu=f.viscosity / f.density, gravity=scene.domain.gravity,
                    dt=scene.time.couple_every * scene.time.dem_step,
                    T0=f.temperature if energy else None, cp=f.heat_capacity, kappa=f.conductivity,
                    T_inlet=f.inlet_temperature or f.temperature, T_walls=sides, nprocs=f.ranks)
    return FluidSolver(case, **solver).start()


def _mesh(case: Path, source: Path, file: str) -> None:
    """blockMesh on the copied case unless it has a mesh: a blockMeshDict that blockMesh
    refuses is bad input (SceneError) with blockMesh's own words."""
    from pyhost.engines.openfoam import FluidError, run_utility
    from pyhost.scene import SceneError

    if (case / "constant" / "polyMesh" / "owner").is_file():
        return
    try:
        run_utility(case, "blockMesh")
    except FluidError:
        log = [line.strip() for line in (case / "log.blockMesh").read_text(errors="replace").splitlines()]
        fatal = next((k for k, line in enumerate(log) if "FOAM FATAL" in line), len(log) - 2)
        said = []
        for line in log[fatal + 1:]:
            if line.startswith(("From ", "FOAM aborting", "FOAM exiting", "#0")):
                break
            said += [line] if line else []
        words = "; ".join(said)
        raise SceneError(f"{file}: fluid.case: {source / 'system/blockMeshDict'}: blockMesh refuses it: "
                         f"{words}") from None


def driven_time(scene) -> float:
    """How long [s] a CFD-DEM script's final ``run 0`` lasts (the coupling drives it, as in
    CFDEM's scripts): [time] end if the scene gives it, else the fluid case's controlDict
    endTime less its startTime."""
    from foamlib import FoamFile

    if scene.time.end > 0:
        return scene.time.end
    control = FoamFile(scene.folder / scene.fluid.case / "system" / "controlDict")
    return float(control["endTime"]) - float(control.get("startTime", 0.0))


def simulate(scene, out: Path, *, test: bool = False, progress_every: float = 5.0, wrap=None, wrap_fluid=None,
             start=None, resume: dict | None = None, extend: float = 0.0, link=None) -> dict:
    """Run a loaded scene into ``out`` (absolute): the user's script or the generated box
    world, with the fluid if the scene has one. ``wrap(dem)`` and ``wrap_fluid(fluid)`` may
    stand in front of the engines (tests inject faults, benchmarks record with them);
    ``start``: the particles a box scene starts from (see ``box_world``); ``resume``: the state of
    a checkpoint to continue from (``pyhost.checkpoint.load``); ``extend`` [s]: how much longer
    than the scene asks a script's last run goes on (``run --extend``; a box scene comes with its
    end extended); ``link``: the other MPI ranks' LIGGGHTS (``pyhost.engines.ranks``), None when
    serial. Returns the summary."""
    from pyhost.checkpoint import fingerprints
    from pyhost.engines.dem import Dem
    from pyhost.engines.liggghts.box_input import dem_collision_time
    from pyhost.engines.liggghts.worlds import box_world, user_script
    from pyhost.run_scene import run_scene
    from pyhost.engines.liggghts.script import check_types, read_script

    effects = scene.effects_summary()
    pending = []                        # a box scene's data file, being written while LIGGGHTS starts
    driven = driven_time(scene) if scene.scripted and effects["fluid_solver"] else None
    max_time = (scene.time.test_end or (driven / 10 if driven else None)) if (test and scene.scripted) else None
    if max_time is not None:            # a smoke run extended: its cut as much later
        max_time += extend
    if scene.scripted:
        script, particles = scene.folder / scene.dem.script, user_script(scene)
        variables = dict(scene.dem.variables, **(scene.dem.test_variables if test else {}))
    else:
        t_c = dem_collision_time(scene, 1.0)
        if scene.time.dem_step > t_c / 20:
            print(f"warning: time.dem_step = {scene.time.dem_step:g} s resolves a 1 m/s DEM collision "
                  f"({t_c:.3g} s) with fewer than 20 steps")
        script, particles = box_world(scene, out, start, resume and resume["restart"], pending)
        variables = {}
    particles["resume"] = resume
    commands = read_script(script, scene.folder, effects["particle_temperatures"])
    if scene.scripted:
        check_types(commands, scene.materials, str(scene.path))
    inputs = fingerprints(scene, commands)      # at the start: a restart checks that none changed since
    fluid = start_fluid(scene, out / "fluid", resume and resume["fluid"]) if effects["fluid_solver"] else None
    cwd = os.getcwd()
    try:
        os.chdir(scene.folder)          # the script's relative paths, as with 'liggghts -in' there
        dem = Dem(out / "dem", variables=variables, link=link)
        try:
            for written in pending:
                written.result()
            return run_scene(scene, wrap(dem) if wrap else dem, commands, out, script=script, max_time=max_time,
                             fluid=wrap_fluid(fluid) if wrap_fluid and fluid is not None else fluid,
                             end=None if scene.scripted else scene.time.end, driven=driven, extend=extend,
                             progress_every=progress_every, inputs=inputs,
                             **particles)
        finally:
            dem.close()
    finally:
        os.chdir(cwd)
        if fluid is not None:
            fluid.stop()
