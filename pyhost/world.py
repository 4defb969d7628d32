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

import numpy as np


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


def box_world(scene, out: Path, start=None, restart: Path | None = None):
    """The generated DEM of a box scene: its script (run for time.end) and how the host sees
    its particles: one atom type per material, groups = the [[particles]] tables, walls
    ``wall<k>`` = the scene's [[walls]]. ``start``: the particles (``pyhost.dem_input.Particles``,
    e.g. a settled bed) to start from instead of the scene's placement; the contacts present
    then are not collisions of this run. ``restart``: LIGGGHTS' restart file of a checkpoint
    to read instead of the particles (the same commands re-issued, with the same ids)."""
    from pyhost.dem_input import input_lines, place_particles, write_data
    from pyhost.tables import HostWall, Known

    folder = out / "dem"
    folder.mkdir(parents=True, exist_ok=True)
    particles = place_particles(scene) if start is None else start
    steps = round(scene.time.end / scene.time.dem_step)
    if restart is None:
        data = write_data(folder / "particles.data", scene, particles)
        script, lines, run = folder / "in.dem", input_lines(scene, data), f"run {steps}"
    else:
        script, run = folder / "in.restart", f"run {steps} upto"
        lines = [f"read_restart {restart}" if line.startswith("read_data ") else line
                 for line in input_lines(scene, Path("-"))]
    from pyhost.output import naming
    with naming(script):
        script.write_text("\n".join(["atom_modify sort 0 0"] + lines + [run]) + "\n")
    index = {name: k for k, name in enumerate(scene.materials)}
    known = Known("id", np.r_[-1, particles.group], np.r_[np.nan, particles.temperature],
                  tuple(f"{g.material} {g.temperature:g} K" for g in scene.particles))
    walls = [HostWall(f"wall{k}", index[w.material], w.temperature if w.temperature > 0 else np.nan)
             for k, w in enumerate(scene.walls)]
    return script, dict(type_material=[-1] + list(range(len(index))), known=known, walls_of=lambda dem: walls)


def user_script(scene):
    """How the host sees the particles of a user's script: each atom type's material from
    [materials.NAME] types; the history's temperature groups: one per material, or one per
    atom type of a material that gives a temperature per type (``NAME (type T)``: hot and
    cold beads of one material apart); walls = the scene's [[walls]] (by fix id) and every
    other wall/gran fix of the script as an adiabatic wall."""
    from pyhost.tables import HostWall, Known
    from pyhost.scene import SceneError

    materials = list(scene.materials)
    used = {w.material for w in scene.walls}
    for name, m in scene.materials.items():
        if not m.types and name not in used:
            raise SceneError(f"{scene.path}: materials.{name}.types: the material is used by no atom type "
                             "and no wall")
    top = max((t for m in scene.materials.values() for t in m.types), default=0)
    type_material = np.full(top + 1, -1)
    for k, m in enumerate(scene.materials.values()):
        type_material[m.types] = k
    T_of_type = np.full(top + 1, np.nan)
    type_group, names = np.full(top + 1, -1), []
    for name, m in scene.materials.items():
        for t in m.types:
            T_of_type[t] = m.temperature_of(t) if m.temperature_of(t) > 0 else np.nan
        apart = isinstance(m.temperature, list)
        for label, types in ([(f"{name} (type {t})", [t]) for t in m.types] if apart else [(name, m.types)]):
            type_group[types] = len(names)
            names.append(label)

    told = set()

    def walls_of(dem):
        info = dem.info
        known = info.walls
        named = {}
        for k, w in enumerate(scene.walls):
            if w.fix not in known:
                raise SceneError(f"{scene.path}: walls[{k}].fix: the script has no fix wall/gran {w.fix!r} "
                                 f"before its first run; its walls: {', '.join(known) or 'none'}")
            meshes = known[w.fix].meshes
            words = [info.conducting_temperature(w.fix, mesh) for mesh in range(max(len(meshes), 1))]
            # the script's, at which its heat/gran conducts (None: it does not)
            Ts = [dem.value(word) if word is not None and w.temperature > 0 else None for word in words]
            for mesh, T in enumerate(Ts):
                if T is not None and T != w.temperature:
                    fix = info.fixes.get(meshes[mesh] if meshes else w.fix)     # where the script gives it
                    each = ", ".join(f"{m} {'no temperature' if t is None else f'{t:g} K'}" for m, t in zip(meshes, Ts))
                    raise SceneError(f"{scene.path}: walls[{k}].temperature: {w.temperature:g} K, where the script "
                                     f"gives wall {w.fix!r} {T:g} K" + (f" ({fix.where()})" if fix is not None else "")
                                     + " (its fix heat/gran conducts at it): one wall, one temperature" + (
                                         f"; its meshes: {each} (one fix wall/gran holds all of a script's meshes "
                                         "in LIGGGHTS 3.8: give those with a temperature the entry's, or leave the "
                                         "wall out of [[walls]])" if len(meshes) > 1 else ""))
                named[w.fix, mesh] = (materials.index(w.material), w.temperature if w.temperature > 0 else np.nan)
            if w.temperature > 0 and info.heat_gran and any(T is not None for T in Ts) and None in Ts \
                    and (w.fix, "meshes") not in told:
                told.add((w.fix, "meshes"))
                print(f"LIGGGHTS wall {w.fix!r}: the script's fix heat/gran conducts through its meshes "
                      + ", ".join(m for m, T in zip(meshes, Ts) if T is not None) + f" at {w.temperature:g} K and "
                      "not through " + ", ".join(m for m, T in zip(meshes, Ts) if T is None) + " (no temperature "
                      f"in the script): collisions with every one get the models' heat from {w.temperature:g} K")
            for mesh, word in enumerate(words):
                if word is not None and w.temperature == 0 and (w.fix, mesh) not in told:
                    print(f"LIGGGHTS wall {w.fix!r}: adiabatic for collision heat, though the script's fix heat/gran "
                          f"conducts through it at {word} K: give its [[walls]] entry that temperature for the "
                          "models' collision heat")
        for fix in known:
            if fix not in {f for f, _ in named} and fix not in told:
                conducting = info.wall_temperatures(fix) if info.heat_gran else []
                print(f"LIGGGHTS wall {fix!r} has no [[walls]] entry: adiabatic for collision heat"
                      + (f" (the script's fix heat/gran conducts through its contacts at {' '.join(conducting)} K, "
                         "as LIGGGHTS does)" if conducting else ""))
        told.update(known)
        told.update(named)
        return [HostWall(f, *named.get((f, k), (-1, np.nan)), mesh=k)
                for f, wall in known.items() for k in range(max(len(wall.meshes), 1))]

    return dict(type_material=type_material, known=Known("type", type_group, T_of_type, tuple(names)),
                walls_of=walls_of)


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
    from pyhost.dem_input import dem_collision_time
    from pyhost.run_scene import run_scene
    from pyhost.script import check_types, read_script

    effects = scene.effects_summary()
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
        script, particles = box_world(scene, out, start, resume and resume["restart"])
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
