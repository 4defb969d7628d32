"""The scene: one declarative ``case.toml`` per case, every value given once, SI units.

Read here (the file's text, its tables' shapes, every number finite, even inside lists:
``gravity = [0, 0, nan]``), built key by key into the frozen dataclasses of ``pyhost.schema``
(re-exported here), then checked as a whole (``pyhost.validate``). A wrong key, a wrong type
or an impossible value is reported as ``SceneError`` naming the file and the key
(``case.toml: materials.glass.density: must be > 0, got -1``) before any engine starts.
``Scene.effects_summary()`` tells what the host will build: no fluid solver for a dry scene,
no contact extraction for an isothermal scene without restitution feedback.

Example::

    [effects]
    fluid = false                 # OpenFOAM solver process
    contact_heat = "A"            # none, A, B, C, or a comparison model (hertz, softened, ...);
                                  # or a list: ["A", "B", "C", "softened"], the first moves heat
    heat_path = "fast"            # exact, fast
    restitution_feedback = false  # e(v0) of the model applied at contact end
    enduring_conduction = false   # conduction through contacts that outlast a collision

    [materials.steel]             # the real material, for the contact models
    density = 7800.0
    youngs_modulus = 210e9
    poisson_ratio = 0.3
    yield_stress = 300e6
    heat_capacity = 470.0
    conductivity = 45.0
    dem = { youngs_modulus = 5e7, restitution = 0.9, friction = 0.3 }   # softened DEM contact

    [[particles]]
    material = "steel"
    count = 2
    radius = 2e-3
    temperature = 400.0
    region = [0.0, 0.01, 0.0, 0.01, 0.0, 0.01]

    [domain]
    box = [0.0, 0.1, 0.0, 0.01, 0.0, 0.2]

    [time]
    dem_step = 1e-6
    end = 0.01
"""
from __future__ import annotations

import dataclasses
import math
import os
import re
import tomllib
from pathlib import Path

from plugins.heat import MODELS
from pyhost.schema import (Conduction, Dem, Domain, Effects, Fluid, Frozen, Material, Output, Particles,  # noqa: F401
                           check_types, Scene, SceneError, Time, Wall, build)   # the schema's names, re-exported for the commands
from pyhost.validate import check_scene
from pyhost.engines.liggghts.names import CONDUCTION_FIX, COUPLING_FIX, WALL_FIX
from pyhost.walls import FACES


def _box(values, key, file, n=6):
    if len(values) != n or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        raise SceneError(f"{file}: {key}: must be {n} numbers, got {values!r}")
    if n == 6 and any(values[k] >= values[k + 1] for k in (0, 2, 4)):
        raise SceneError(f"{file}: {key}: each min must be below its max, got {values!r}")


def _inlet_table(fluid, file):
    key = f"{file}: fluid.inlet_table"
    if fluid.inlet_velocity:
        raise SceneError(f"{key}: give either inlet_table or inlet_velocity, not both")
    for row in fluid.inlet_table:
        if not isinstance(row, list):
            raise SceneError(f"{key}: each row must be [time, velocity], got {row!r}")
        _box(row, "fluid.inlet_table", file, 2)
        if row[0] < 0 or row[1] < 0:
            raise SceneError(f"{key}: times and velocities must be >= 0, got {row!r}")
    times = [row[0] for row in fluid.inlet_table]
    if any(b <= a for a, b in zip(times, times[1:])):
        raise SceneError(f"{key}: times must increase, got {times!r}")


SECTIONS = ("effects", "materials", "particles", "domain", "time", "walls", "fluid", "output", "dem", "conduction", "frozen")


def read_text(path) -> str:
    """The scene file's text; SceneError naming the file for a folder, bytes that are not
    UTF-8, or a file that cannot be read (a missing file is left to the caller)."""
    try:
        raw = path.read_bytes()
    except IsADirectoryError:
        raise SceneError(f"{path}: is a folder; give the case folder's case.toml") from None
    except PermissionError:
        raise SceneError(f"{path}: cannot be read (permission denied)") from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise SceneError(f"{path}: line {line}: not UTF-8 text (byte {raw[exc.start]:#04x})") from None


def _finite(value, key, file) -> None:
    if isinstance(value, float) and not math.isfinite(value):
        raise SceneError(f"{file}: {key}: must be finite, got {value!r}")
    if isinstance(value, list):
        for k, v in enumerate(value):
            _finite(v, f"{key}[{k}]", file)
    if isinstance(value, dict):
        for k, v in value.items():
            _finite(v, f"{key}.{k}", file)


def check_raw(data: dict, file: str) -> None:
    """Shapes the scene builder relies on, and finite numbers everywhere."""
    for key in ("materials", "domain", "time", "effects", "fluid", "output", "conduction", "frozen"):
        if key in data and not isinstance(data[key], dict):
            raise SceneError(f"{file}: {key}: must be a table [{key}], got {data[key]!r}")
    for name, m in data.get("materials", {}).items():
        if not isinstance(m, dict):
            raise SceneError(f"{file}: materials.{name}: must be a table [materials.{name}], got {m!r}")
    for key in ("particles", "walls"):
        items = data.get(key, [])
        if not isinstance(items, list) or not all(isinstance(x, dict) for x in items):
            raise SceneError(f"{file}: {key}: must be [[{key}]] tables, got {items!r}")
    for k, p in enumerate(data.get("particles", [])):
        positions = p.get("positions", [])
        if not isinstance(positions, list) or not all(isinstance(x, list) for x in positions):
            raise SceneError(f"{file}: particles[{k}].positions: must be a list of [x, y, z], "
                             f"got {positions!r}")
    periodic = data.get("domain", {}).get("periodic", [False] * 3)
    if not isinstance(periodic, list) or len(periodic) != 3 or not all(isinstance(p, bool) for p in periodic):
        raise SceneError(f"{file}: domain.periodic: must be three booleans (true/false), got {periodic!r}")
    for key, value in data.items():
        _finite(value, key, file)


def what_is_here(folder: Path) -> str:
    """What a folder without a scene file holds and how to make it a case of the host (a
    CFDEM tutorial, its OpenFOAM folder, a DPMFoam case, a LIGGGHTS script), as a hint
    appended to the missing file's error; "" if none of these."""
    if not folder.is_dir():
        return ""
    tutorial = "docs/tutorials.md, 'The case.toml a user writes'"
    if (folder / "CFD" / "constant" / "couplingProperties").is_file():
        return (f"; {folder} is a CFDEM tutorial: its case.toml goes into CFD/, and 'python -m pyhost run "
                f"{folder / 'CFD'}' runs it ({tutorial})")
    if (folder / "constant" / "couplingProperties").is_file():
        return (f"; {folder} is a CFDEM case's OpenFOAM folder: write case.toml here with [effects] fluid = true, "
                f"[fluid] case = \".\" and the particles' real material (the script is the one its "
                f"couplingProperties names; {tutorial})")
    if (folder / "constant" / "kinematicCloudProperties").is_file():
        return (f"; {folder} is an OpenFOAM particle case: 'python -m pyhost dpmfoam {folder} OUT' writes a "
                "DPMFoam case as a case of the host (docs/dpmfoam.md)")
    scripts = sorted(p.name for p in folder.glob("in.*") if p.is_file())
    if scripts:
        return (f"; {folder} holds the LIGGGHTS script{'s' if len(scripts) > 1 else ''} {', '.join(scripts)}: write "
                f"case.toml beside it with [dem] script = \"{scripts[0]}\", the collision heat ([effects] "
                f"contact_heat = \"A\") and the particles' real material ({tutorial})")
    return ""


def read_toml(path) -> dict:
    """The tables of a scene file; SceneError if it is missing, not text or not TOML."""
    try:
        return tomllib.loads(read_text(Path(path)))
    except FileNotFoundError:
        raise SceneError(f"{path}: no such scene file{what_is_here(Path(path).parent)}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML: {exc}") from None


def load_scene(path) -> Scene:
    """Read and validate a scene file; raises SceneError naming the file and the key."""
    path = Path(path)
    file = str(path)
    data = read_toml(path)
    for key in data:
        if key not in SECTIONS:
            raise SceneError(f"{file}: {key}: unknown section; known: {', '.join(SECTIONS)}")
    dem = _cfdem_script(build(Dem, data.get("dem", {}), "dem", file), data, path, file)
    scripted = bool(dem.script)
    required = ("materials",) if scripted else ("materials", "particles", "domain", "time")
    for key in required:
        if key not in data:
            raise SceneError(f"{file}: {key}: missing section")
    if scripted:
        for key in ("particles", "domain"):
            if key in data:
                raise SceneError(f"{file}: {key}: not used with dem.script (the script places the particles "
                                 "and sets the domain): remove it")
        _script_keys(dem, path, file)
    check_raw(data, file)
    effects = build(Effects, data.get("effects", {}), "effects", file)
    materials, walls = materials_and_walls(data, file)
    if scripted:
        particles, domain = [], None
        _types(materials, walls, file)
    else:
        for name, m in materials.items():
            if m.dem is None:
                raise SceneError(f"{file}: materials.{name}.dem: missing (the DEM's softened contact; a box scene "
                                 "has no script to read it from)")
        particles, domain = _box_world(data, materials, walls, file)
    check_wall_materials(walls, materials, file)
    time = build(Time, data.get("time", {}), "time", file)
    if not scripted:
        for key in ("dem_step", "end"):
            if not getattr(time, key) > 0:
                raise SceneError(f"{file}: time.{key}: must be > 0, got {getattr(time, key)!r}")
        if time.dem_step >= time.end:
            raise SceneError(f"{file}: time.dem_step: must be below time.end ({time.end}), got {time.dem_step}")
    fluid = build(Fluid, data["fluid"], "fluid", file) if "fluid" in data else None
    if effects.restitution_feedback and (not effects.heat_models or effects.heat_models[0] not in MODELS):
        raise SceneError(f"{file}: effects.restitution_feedback: needs a contact model ({', '.join(sorted(MODELS))}) "
                         f"first in effects.contact_heat; comparison models give no restitution")
    if effects.fluid and fluid is None:
        raise SceneError(f"{file}: fluid: missing section, but effects.fluid = true")
    if effects.convection != "none" and not effects.fluid:
        raise SceneError(f"{file}: effects.convection: needs the gas (effects.fluid = true)")
    if fluid is not None and fluid.case:
        effects, fluid, time = _cfdem_settings(effects, fluid, time, dem, data, path, file)
        _user_fluid_case(fluid, path, file, effects.convection != "none")
    elif effects.fluid and scripted:
        raise SceneError(f"{file}: fluid.case: a script scene needs its OpenFOAM case (the host generates "
                         "a fluid only for the box world)")
    if fluid is not None and (len(fluid.cells) != 3 or not all(isinstance(n, int) and n > 0 for n in fluid.cells)):
        raise SceneError(f"{file}: fluid.cells: must be 3 positive integers, got {fluid.cells!r}")
    if fluid is not None and fluid.inlet_table:
        _inlet_table(fluid, file)
    output = build(Output, data.get("output", {}), "output", file)
    conduction = _conduction(effects, build(Conduction, data.get("conduction", {}), "conduction", file), fluid, file)
    for name, region in output.probes.items():
        _box(region if isinstance(region, list) else [region], f"output.probes.{name}", file)
    if output.probes and not (effects.heat_models or effects.convection != "none"
                              or effects.contact_conduction != "none" or effects.gap_conduction != "none"):
        raise SceneError(f"{file}: output.probes: the particles have no temperatures in this scene (no contact "
                         "heat, convection or conduction): nothing to probe")
    frozen = build(Frozen, data.get("frozen", {}), "frozen", file)
    if frozen.end > 0 and effects.contact_conduction == "none" and effects.gap_conduction == "none":
        raise SceneError(f"{file}: frozen.end: a frozen stage moves heat through lasting conduction only: give "
                         "effects.contact_conduction or effects.gap_conduction")
    scene = Scene(path, effects, materials, particles, domain, time, walls, fluid, output, dem, conduction, frozen)
    check_scene(scene)
    return scene


def materials_and_walls(data: dict, file: str) -> tuple[dict, list]:
    """The ``[materials.NAME]`` tables (name -> Material) and ``[[walls]]`` (Wall) of a scene's
    data: a run's scene and post's read them alike."""
    if not isinstance(data.get("materials"), dict) or not data["materials"]:
        raise SceneError(f"{file}: materials: must be one or more [materials.NAME] tables")
    materials = {name: build(Material, m, f"materials.{name}", file) for name, m in data["materials"].items()}
    for name, m in materials.items():
        if m.b2 <= m.b1:
            raise SceneError(f"{file}: materials.{name}.b2: must exceed b1 ({m.b1}), got {m.b2}")
    if not isinstance(data.get("walls", []), list):
        raise SceneError(f"{file}: walls: must be [[walls]] tables")
    return materials, [build(Wall, w, f"walls[{k}]", file) for k, w in enumerate(data.get("walls", []))]


def check_wall_materials(walls: list, materials: dict, file: str) -> None:
    """Each wall's material is one of the scene's."""
    for k, item in enumerate(walls):
        if item.material not in materials:
            raise SceneError(f"{file}: walls[{k}].material: unknown material {item.material!r}; "
                             f"known: {', '.join(materials)}")


@dataclasses.dataclass(frozen=True)
class PostScene:
    """What ``pyhost post`` reads of a scene file (``load_post_scene``)."""

    path: Path
    materials: dict                 # name -> Material (real and DEM values, types, temperature)
    types: dict                     # LIGGGHTS atom type -> material index
    temperature: dict               # initial temperature per atom type [K]; 0: from the dumps
    walls: list                     # pyhost.scene.Wall


def load_post_scene(path) -> PostScene:
    """The ``[materials.NAME]`` (with ``types`` and an optional ``temperature``) and ``[[walls]]``
    (``fix`` or ``plane``, ``material``, ``temperature``) of a scene file, read as a run reads
    them (``pyhost.scene``); its other sections belong to runs and are not read here, so a
    case.toml serves both."""
    path, file = Path(path), str(path)
    materials, walls = materials_and_walls(read_toml(path), file)
    names = list(materials)
    types = {t: names.index(name) for t, name in check_types(materials, file).items()}
    if not types:
        raise SceneError(f"{file}: materials: no material names its LIGGGHTS atom types (types = [1, 2])")
    check_wall_materials(walls, materials, file)
    for k, wall in enumerate(walls):
        if bool(wall.fix) == bool(wall.plane):
            raise SceneError(f"{file}: walls[{k}]: give either fix, the id of a LIGGGHTS {WALL_FIX}, or plane "
                             f"({', '.join(FACES)})")
    return PostScene(path, materials, types, {t: materials[names[k]].temperature_of(t) for t, k in types.items()},
                     walls)


def _conduction(effects, conduction, fluid, file):
    """The lasting conduction's settings, checked against the effects: a contact model does not
    go with enduring_conduction (LIGGGHTS' heat/gran would conduct through the same contacts); a
    gap model needs the gas conductivity (the scene's fluid's when not given) and Lethe's its
    gas parameter."""
    if effects.contact_conduction != "none" and effects.enduring_conduction:
        raise SceneError(f"{file}: effects.contact_conduction: {effects.contact_conduction!r} and "
                         "effects.enduring_conduction both conduct through lasting contacts (the second through "
                         f"LIGGGHTS' {CONDUCTION_FIX}): choose one")
    if effects.gap_conduction == "none":
        return conduction
    if conduction.gas_conductivity == 0:
        if fluid is None:
            raise SceneError(f"{file}: conduction.gas_conductivity: missing (effects.gap_conduction = "
                             f"{effects.gap_conduction!r} conducts through the gas, and the scene has no [fluid] to "
                             "take it from) [W/(m K)]")
        conduction = dataclasses.replace(conduction, gas_conductivity=fluid.conductivity)
    if effects.gap_conduction == "lethe" and conduction.gas_parameter == 0:
        raise SceneError(f"{file}: conduction.gas_parameter: must be > 0 with effects.gap_conduction = \"lethe\" "
                         "(Lethe's gas parameter M [m]: without it the gas resistance of a point contact vanishes)")
    return conduction


def _cfdem_script(dem, data, path, file):
    """A CFDEM case names the LIGGGHTS script its coupling runs (``coupling_script``): the
    scene's dem.script when the scene gives none and places no particles of its own; a
    dem.script that names another file is refused, as a disagreeing drag law is."""
    fluid = data.get("fluid")
    case = fluid.get("case") if isinstance(fluid, dict) else None
    if "particles" in data or not isinstance(case, str) or not case:
        return dem
    from pyhost.engines.fluid_case import coupling_script

    try:
        found = coupling_script(path.resolve().parent / case)
    except ValueError as exc:
        raise SceneError(f"{file}: fluid.case: {exc}") from None
    if found is None:
        return dem
    script, where = found
    if dem.script:
        given = path.resolve().parent / dem.script
        if given.resolve() != script.resolve():
            raise SceneError(f"{file}: dem.script: {dem.script!r} ({given.resolve()}), but {where} names "
                             f"{script.resolve()}, which CFDEM's coupling runs: remove dem.script to take the "
                             "case's, or make them agree")
        return dem
    if not script.is_file():
        raise SceneError(f"{file}: dem.script: not given, and {where} names {script}, which does not exist")
    return dataclasses.replace(dem, script=os.path.relpath(script, path.resolve().parent))


def _script_keys(dem, path, file):
    script = path.resolve().parent / dem.script
    if not script.is_file():
        raise SceneError(f"{file}: dem.script: no such file {str(script)!r}")
    for where in ("variables", "test_variables"):
        for name, value in getattr(dem, where).items():
            if not re.fullmatch(r"[A-Za-z0-9_]+", name):       # LIGGGHTS' own rule (variable.cpp)
                raise SceneError(f"{file}: dem.{where}: {name!r} is not a LIGGGHTS variable name (letters, digits "
                                 "and underscores only)")
            if isinstance(value, bool) or not isinstance(value, (str, int, float)) or not str(value).strip():
                raise SceneError(f"{file}: dem.{where}.{name}: must be a number or a word, got {value!r}")


FLUID_CASE_FILES = ("system/controlDict", "system/fvSchemes", "system/fvSolution", "0/U", "0/p",
                    "constant/transportProperties")


def _user_fluid_case(fluid, path, file, energy: bool):
    """A user's OpenFOAM case: the files collheatFoam reads (0/T for the gas energy), a mesh or
    a blockMeshDict, and no scene key that the case itself decides. A case written for another
    solver (``fluid_case.adopt_other_solver``: a phase's suffix, 0.orig, no turbulenceProperties)
    is checked as the host will run it: adapted in a scratch copy, the messages naming the
    case's folder."""
    import shutil
    import tempfile

    from pyhost.engines.fluid_case import adopt_other_solver, case_phase

    folder = path.resolve().parent / fluid.case
    if not folder.is_dir():
        raise SceneError(f"{file}: fluid.case: no such folder {str(folder)!r}")
    if not (case_phase(folder) or not (folder / "0").is_dir() or not (folder / "constant/turbulenceProperties").is_file()):
        return _check_fluid_case(fluid, folder, file, energy)
    with tempfile.TemporaryDirectory(prefix="collheat-case-") as tmp:
        copy = Path(tmp) / folder.name
        shutil.copytree(folder, copy, ignore=lambda d, names: [n for n in names if n.startswith(("processor", "log."))
                                                                or (Path(d) == folder and n not in ("0", "0.orig",
                                                                    "constant", "system"))])
        try:
            try:
                adopt_other_solver(copy)
            except ValueError:          # a dictionary foamlib cannot read: the check names it, OpenFOAM's words
                from pyhost.engines.foam_case_check import check_dictionaries
                check_dictionaries(copy, file)
                raise
            return _check_fluid_case(fluid, copy, file, energy)
        except (SceneError, ValueError) as exc:
            raise SceneError(str(exc).replace(str(copy), f"{folder} (as the host adapts it)")) from None


def _check_fluid_case(fluid, folder, file, energy: bool):
    """``_user_fluid_case``'s checks on ``folder``, the user's case or its adapted copy."""
    from pyhost.engines.foam_case_check import check_case, solution_gaps

    missing = [f for f in FLUID_CASE_FILES + (("0/T",) if energy else ()) if not (folder / f).is_file()]
    if not (folder / "constant" / "polyMesh" / "owner").is_file() and not (folder / "system" / "blockMeshDict").is_file():
        missing.append("constant/polyMesh or system/blockMeshDict")
    if (folder / "system" / "snappyHexMeshDict").is_file() and not (folder / "constant/polyMesh/owner").is_file():
        missing.append("constant/polyMesh: the case's mesh is snappyHexMesh's (system/snappyHexMeshDict), which the "
                       "host does not run (it runs blockMesh only): run blockMesh and snappyHexMesh in the case first")
    missing += solution_gaps(folder, file, energy)
    if missing:
        raise SceneError(f"{file}: fluid.case: {folder} lacks what collheatFoam needs: {'; '.join(missing)}")
    check_case(folder, file, fluid.ranks, energy)
    from pyhost.engines.fluid_case import case_density
    try:
        case_density(folder)
    except ValueError as exc:
        raise SceneError(f"{file}: fluid.case: {exc}") from None
    default = Fluid()
    for key in ("density", "viscosity", "inlet_velocity", "inlet_table", "plenum", "cells", "sides",
                "temperature", "inlet_temperature"):
        if getattr(fluid, key) != getattr(default, key):
            raise SceneError(f"{file}: fluid.{key}: comes from the OpenFOAM case {fluid.case!r}, not from the scene")


def _cfdem_settings(effects, fluid, time, dem, data, path, file):
    """A CFDEM case says its drag law, void fraction model and gas-particle heat transfer (with
    the gas's conductivity and heat capacity) in constant/couplingProperties, and how often it
    couples there too (couplingInterval, with CFDEM's in-memory exchange) or in its script
    (``fix ... couple/cfd couple_every N``, with a file exchange): taken where the scene does not
    give the key (fluid.drag, fluid.void_fraction, fluid.alpha_min, fluid.ddt_alpha,
    effects.convection, fluid.conductivity, fluid.heat_capacity, time.couple_every); a scene
    value that disagrees, or a model the host does not have with no scene value to choose one,
    is refused. So is a case the host cannot run as written (``cfdem_unsupported``: resolved
    particles, species, a flow not solved). Returns (effects, fluid, time)."""
    from pyhost.engines.fluid_case import CFDEM_KNOWN, cfdem_unsupported, coupling_properties

    folder = path.resolve().parent / fluid.case
    why = cfdem_unsupported(folder)
    if why:
        raise SceneError(f"{file}: fluid.case: {why}")
    _case_commands(folder, file)
    where = folder / "constant" / "couplingProperties"
    tables = {"effects": effects, "fluid": fluid, "time": time}
    taken = {"effects": {}, "fluid": {}, "time": {}}
    found = coupling_properties(folder)
    for scene_key, (entry, theirs, ours) in found.items():
        table, key = scene_key.split(".")
        value = getattr(tables[table], key)
        given = key in data.get(table, {})
        agree = (math.isclose(value, ours, rel_tol=1e-12) if isinstance(ours, float) else value == ours)
        said = f"{where}{' ' + entry if entry else ''} has {theirs}"
        if given and ours is not None and not agree:
            raise SceneError(f"{file}: {scene_key}: {value!r}, but {said} ({ours!r}): remove {scene_key} to take the "
                             "case's, or make them agree")
        if not given and ours is None:
            known = CFDEM_KNOWN[scene_key]
            raise SceneError(f"{file}: {scene_key}: {said}, which the host does not have "
                             f"(it has {', '.join(f'{a} as {b!r}' for a, b in known.items())}): give {scene_key} "
                             "to choose")
        if not given:
            taken[table][key] = ours
    if dem.script and "time.couple_every" not in found:       # (a file exchange: the script's interval)
        from pyhost.engines.liggghts.script import script_couple_every
        every = script_couple_every(path.resolve().parent / dem.script)
        if every is not None:
            number, line = every
            if "couple_every" in data.get("time", {}) and time.couple_every != number:
                raise SceneError(f"{file}: time.couple_every: {time.couple_every}, but {line} couples every "
                                 f"{number} DEM steps ({COUPLING_FIX}): remove time.couple_every to take the "
                                 "script's, or make them agree")
            taken["time"]["couple_every"] = number
    return tuple(dataclasses.replace(tables[k], **taken[k]) for k in ("effects", "fluid", "time"))


def _case_commands(folder: Path, file: str) -> None:
    """A CFDEM case's liggghtsCommands checked before any engine starts: every model one the
    host runs (pyhost.effects.case_commands), and fluid write times it can follow if one asks
    for them."""
    from foamlib import FoamFile

    from pyhost.engines.cfdem_commands import CaseCommandsError, read_commands, write_times

    try:
        commands = read_commands(folder, 1)
        if any(c.when == "write" for c in commands):
            write_times(FoamFile(folder / "system" / "controlDict").as_dict(), 0.0, 0.0, 1.0)
    except (CaseCommandsError, KeyError, TypeError, ValueError) as exc:
        raise SceneError(f"{file}: fluid.case: {exc}") from None


def _types(materials, walls, file):
    """Script scenes: each material names its atom types, no type twice (a list of temperatures
    one per type); walls name a fix."""
    check_types(materials, file)
    for k, w in enumerate(walls):
        if not w.fix or w.plane:
            raise SceneError(f"{file}: walls[{k}]: a script scene names a LIGGGHTS wall by \"fix\", the id of its "
                             f"{WALL_FIX}, not by plane")


def _box_world(data, materials, walls, file):
    """The [[particles]] groups and the [domain] of a scene whose DEM the host generates."""
    for name, m in materials.items():
        if m.types or m.temperature:
            raise SceneError(f"{file}: materials.{name}: 'types' and 'temperature' belong to script scenes "
                             "(dem.script); here [[particles]] give them")
    if not isinstance(data["particles"], list) or not data["particles"]:
        raise SceneError(f"{file}: particles: must be one or more [[particles]] tables")
    particles = [build(Particles, p, f"particles[{k}]", file) for k, p in enumerate(data["particles"])]
    for k, w in enumerate(walls):
        if not w.plane or w.fix:
            raise SceneError(f"{file}: walls[{k}]: a box scene names its wall by plane = \"zlo\" (etc.), "
                             "not by fix")
    for k, item in enumerate(particles):
        if item.material not in materials:
            raise SceneError(f"{file}: particles[{k}].material: unknown material {item.material!r}; "
                             f"known: {', '.join(materials)}")
    for k, p in enumerate(particles):
        if bool(p.region) == bool(p.positions):
            raise SceneError(f"{file}: particles[{k}]: give either region or positions")
        if p.region:
            _box(p.region, f"particles[{k}].region", file)
        for x in p.positions:
            _box(x, f"particles[{k}].positions", file, 3)
        if p.positions and len(p.positions) != p.count:
            raise SceneError(f"{file}: particles[{k}].positions: {len(p.positions)} given, count = {p.count}")
        _box(p.velocity, f"particles[{k}].velocity", file, 3)
    domain = build(Domain, data["domain"], "domain", file)
    _box(domain.box, "domain.box", file)
    _box(domain.gravity, "domain.gravity", file, 3)
    return particles, domain
