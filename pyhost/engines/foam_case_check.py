"""Checks of a user's OpenFOAM case (``[fluid] case``) before any engine starts, so that a
mistake in it is bad input (exit 2) naming the file, the key and what to write, not a
solver that dies at its first step (exit 3).

``check_case(folder, file, ranks, energy)`` reads with foamlib: every file it needs parses;
``nu`` and, if given there, ``rho`` in constant/transportProperties are numbers (a density
kept in 0/rho is ``pyhost.engines.fluid_case.case_density``'s); a constant/polyMesh is
whole; the mesh's patches (constant/polyMesh/boundary, else system/blockMeshDict's
``boundary`` or old-style ``patches``) each have an entry in 0/U and 0/p (0/T with the gas
energy) by name, group or quoted regular expression; blocks and faces name existing
vertices; with ``ranks`` > 1, system/decomposeParDict cuts the mesh into that many
subdomains; no fvOptions entry is of a type only CFDEM's solvers have.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

from foamlib import FoamFile

from pyhost.schema import SceneError

#: patch types OpenFOAM also puts in a group of that name (#includeEtc setConstraintTypes
#: gives each of these its field entry)
GROUPED_TYPES = {"wall", "empty", "wedge", "symmetry", "symmetryPlane", "cyclic", "cyclicAMI",
                 "cyclicACMI", "cyclicSlip", "processor", "processorCyclic", "nonuniformTransformCyclic"}


def _read(folder: Path, rel: str, file: str) -> dict:
    """The whole file parsed; SceneError naming it and the line foamlib stopped at."""
    try:
        return FoamFile(folder / rel).as_dict()
    except ValueError as exc:       # foamlib's FoamFileDecodeError
        raise SceneError(f"{file}: fluid.case: {folder / rel}: not a valid OpenFOAM file: "
                         f"{str(exc).splitlines()[0].rstrip(':')}") from None


def _number(entry) -> float | None:
    value = getattr(entry, "value", entry)
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def mesh_patches(folder: Path, file: str) -> tuple[str, dict]:
    """The mesh's file and its patches {name: groups (its type, inGroups)}."""
    if (folder / "constant" / "polyMesh" / "owner").is_file():
        mesh = folder / "constant" / "polyMesh"
        lacking = [n for n in ("points", "faces", "neighbour", "boundary")
                   if not ((mesh / n).is_file() or (mesh / f"{n}.gz").is_file())]
        if lacking:
            raise SceneError(f"{file}: fluid.case: {mesh}: has owner but lacks {', '.join(lacking)}: give the "
                             "whole mesh, or remove constant/polyMesh to have it built from system/blockMeshDict")
        rel = "constant/polyMesh/boundary"
        entries = _read(folder, rel, file).get(None)
        if not isinstance(entries, list) or not all(isinstance(e, tuple) and len(e) == 2 for e in entries):
            raise SceneError(f"{file}: fluid.case: {folder / rel}: not a list of patches 'name {{ type ...; }}'")
        return rel, {name: _groups(d) for name, d in entries}
    rel = "system/blockMeshDict"
    mesh = _read(folder, rel, file)
    where = f"{file}: fluid.case: {folder / rel}"
    for key in ("vertices", "blocks"):
        if not isinstance(mesh.get(key), list) or not mesh[key]:
            raise SceneError(f"{where}: {key}: missing or empty")
    vertices = len(mesh["vertices"])
    patches, faces = {}, []
    if isinstance(mesh.get("boundary"), list):
        for item in mesh["boundary"]:
            if not (isinstance(item, tuple) and len(item) == 2 and isinstance(item[1], dict)):
                raise SceneError(f"{where}: boundary: each entry must be 'name {{ type patch; faces (...); }}', "
                                 f"got {item!r}")
            patches[item[0]] = _groups(item[1])
            faces += item[1].get("faces", [])
    elif isinstance(mesh.get("patches"), list):   # old style: type name (faces) ...
        flat = mesh["patches"]
        for k in range(0, len(flat) - 2, 3):
            patches[flat[k + 1]] = _groups({"type": flat[k]})
            faces += flat[k + 2] if isinstance(flat[k + 2], list) else []
    blocks = mesh["blocks"]
    hexes = [blocks[k + 1] for k in range(len(blocks) - 1) if blocks[k] == "hex"]
    if not hexes:
        raise SceneError(f"{where}: blocks: no 'hex (8 vertices) (cells) simpleGrading (...)' block")
    for what, shapes, n in (("blocks", hexes, 8), ("boundary", faces, 4)):
        for shape in shapes:
            ints = isinstance(shape, list) and all(isinstance(i, int) for i in shape)
            if ints and (len(shape) != n or not all(0 <= i < vertices for i in shape)):
                raise SceneError(f"{where}: {what}: {shape} must be {n} vertex numbers from 0 to {vertices - 1} "
                                 f"(there are {vertices} vertices)")
    return rel, patches


def _groups(entry: dict) -> set:
    groups = entry.get("inGroups", [])
    groups = groups[1] if isinstance(groups, tuple) else groups     # List<word> 1(wall)
    return set(groups) | ({entry.get("type")} & GROUPED_TYPES)


def _covered(patch: str, groups: set, keys: list) -> bool:
    if "#includeEtc" in keys and groups & GROUPED_TYPES:
        return True
    for key in keys:
        if key == patch or key in groups:
            return True
        if key.startswith('"') and key.endswith('"'):
            try:
                if re.fullmatch(key[1:-1], patch) or key[1:-1] in groups:
                    return True
            except re.error:
                return True     # a pattern Python cannot read: left to OpenFOAM
    return False


def check_fields(folder: Path, file: str, fields) -> None:
    """Each patch of the mesh has its entry in each field's boundaryField."""
    source, patches = mesh_patches(folder, file)
    for field in fields:
        rel = f"0/{field}"
        entries = _read(folder, rel, file).get("boundaryField")
        where = f"{file}: fluid.case: {folder / rel}: boundaryField"
        if not isinstance(entries, dict):
            raise SceneError(f"{where}: missing or not a dictionary")
        keys = list(entries)
        if any(k.startswith("#include") and k != "#includeEtc" for k in keys):
            continue            # entries from another file: left to OpenFOAM
        for patch, groups in patches.items():
            if not _covered(patch, groups, keys):
                named = set(patches).union(*patches.values())
                unused = [k for k in keys if k not in named and not k.startswith(("#", '"'))]
                raise SceneError(f"{where}: no entry for the mesh's patch {patch!r} (patches of {source}: "
                                 f"{', '.join(patches)}; entries: {', '.join(keys) or 'none'}): name it "
                                 f"'{patch} {{ type ...; }}'"
                                 + (f" (instead of {', '.join(map(repr, unused))}?)" if unused else ""))


def solution_gaps(folder: Path, file: str, energy: bool) -> list[str]:
    """What collheatFoam asks of system/fvSolution and the case lacks: a linear solver for p and
    U (and T with the gas energy; their Final solvers the host adds in its copy), by name or a
    quoted regular expression, and a PIMPLE (or PISO) dictionary. A case written for a solver
    that moves no gas (icoUncoupledKinematicParcelFoam) has none of them."""
    rel = "system/fvSolution"
    if not (folder / rel).is_file():
        return []
    d = _read(folder, rel, file)
    solvers = d.get("solvers") if isinstance(d.get("solvers"), dict) else {}
    keys = [str(k) for k in solvers]

    def solved(name: str) -> bool:
        return name in keys or any(k.startswith('"') and _matches(k[1:-1], name) for k in keys)

    gaps = [f"{rel} solvers {name}" for name in ("p", "U") + (("T",) if energy else ()) if not solved(name)]
    if not any(isinstance(d.get(k), dict) for k in ("PIMPLE", "PISO")):
        gaps.append(f"{rel} PIMPLE (or PISO) dictionary")
    return gaps


def _matches(pattern: str, name: str) -> bool:
    try:
        return re.fullmatch(pattern, name) is not None
    except re.error:
        return True             # a pattern Python cannot read: left to OpenFOAM


def check_decomposition(folder: Path, file: str, ranks: int) -> None:
    """decomposeParDict cuts the mesh into ``ranks`` pieces (for a parallel fluid)."""
    rel = "system/decomposeParDict"
    where = f"{file}: fluid.case: {folder / rel}"
    if not (folder / rel).is_file():
        raise SceneError(f"{where}: missing; fluid.ranks = {ranks} needs it with numberOfSubdomains {ranks}")
    d = _read(folder, rel, file)
    n = d.get("numberOfSubdomains")
    if n != ranks:
        raise SceneError(f"{where}: numberOfSubdomains: {n}, but fluid.ranks = {ranks}: write "
                         f"'numberOfSubdomains {ranks};' there or set fluid.ranks = {n}")
    method = d.get("method")
    if method in ("simple", "hierarchical"):
        coeffs = d.get(f"{method}Coeffs", d.get("coeffs", {}))
        split = coeffs.get("n") if isinstance(coeffs, dict) else None
        if isinstance(split, list) and all(isinstance(i, int) for i in split) and math.prod(split) != ranks:
            raise SceneError(f"{where}: {method}Coeffs.n: {split} makes {math.prod(split)} subdomains, "
                             f"not numberOfSubdomains {ranks}")


def check_fv_options(folder: Path, file: str) -> None:
    """An fvOptions entry (system/ or constant/) of CFDEM's meanSupVelocityForce for two fluid
    phases (twoPhase true: an alphaField the host does not have). The mean velocity forces
    themselves run as collheatFoam's own (``fluid_case.adopt_mean_velocity_force``)."""
    for rel in ("system/fvOptions", "constant/fvOptions"):
        if not (folder / rel).is_file():
            continue
        for name, entry in _read(folder, rel, file).items():
            kind = entry.get("type") if isinstance(entry, dict) else None
            coeffs = entry.get(f"{kind}Coeffs", {}) if isinstance(entry, dict) else {}
            two_phase = str(coeffs.get("twoPhase", "false")).lower() in ("true", "yes", "on", "1")
            if kind == "meanSupVelocityForce" and two_phase:
                raise SceneError(f"{file}: fluid.case: {folder / rel}: {name}: meanSupVelocityForce with twoPhase "
                                 "true weights the mean by a second fluid phase, which the host does not have: "
                                 "set twoPhase false")


def check_start(folder: Path, file: str) -> None:
    """A controlDict that starts at another time than 0 (a CFDEM restart stage: ErgunTestMPI_restart's
    controlDict_restart, startTime 0.05) needs the case's time folder of that time, with U and p:
    the fluid's state to go on from. A host run writes its fluid's times into its output
    (OUT/fluid), not into the case: where an output folder in the case has that time, the
    message says what to copy (output folders in the case and beside it)."""
    from pyhost.engines.fluid_case import is_time_name, start_time

    t, name = start_time(folder)
    control = folder / "system" / "controlDict"
    if name is None and t != 0.0:
        found = sorted(p for where in (folder, folder.parent) for p in where.glob("*/fluid/*")
                       if (p.parent.parent / "scene.json").is_file() and is_time_name(p.name)
                       and math.isclose(float(p.name), t, rel_tol=1e-9))
        hint = (f": a run of the host wrote it in {found[-1]}: copy it into the case "
                f"(cp -r {found[-1]} {folder}/), then run with --overwrite or another --out" if found else
                ": give the case the fluid's fields at that time (a CFDEM stage before this one writes them), "
                "or start at 0")
        raise SceneError(f"{file}: fluid.case: {control} starts at t = {t:g} s, and {folder} has no time folder of "
                         f"that time{hint}")
    if name is not None and name != "0":
        missing = [f for f in ("U", "p") if not (folder / name / f).is_file()]
        if missing:
            raise SceneError(f"{file}: fluid.case: {control} starts at t = {t:g} s, and {folder / name} lacks "
                             f"{', '.join(missing)}")


def check_dictionaries(folder: Path, file: str) -> None:
    """Every dictionary of the case's system/, constant/ (not its polyMesh or surfaces) and 0/
    reads as OpenFOAM reads it: one foamlib cannot parse is given to OpenFOAM's own
    foamDictionary, and refused (SceneError) with OpenFOAM's words, file and line if it fails
    there too (a '{' too many in fvSchemes stopped the solver at its start, exit 3; a file
    foamlib alone cannot read is left to OpenFOAM)."""
    import subprocess

    from pyhost.engines.openfoam import foam_env

    for sub in ("system", "constant", "0"):
        for path in sorted((folder / sub).glob("*") if (folder / sub).is_dir() else []):
            if not path.is_file() or path.suffix in (".gz", ".stl", ".obj"):
                continue
            try:
                FoamFile(path).as_dict()
                continue
            except ValueError:
                pass                # foamlib's FoamFileDecodeError: OpenFOAM decides
            r = subprocess.run(["foamDictionary", str(path.relative_to(folder))], cwd=folder, capture_output=True,
                               text=True, errors="replace", env=foam_env(), timeout=60)
            if r.returncode != 0:
                said = [ln.strip() for ln in r.stderr.splitlines() if ln.strip()]
                start = next((k for k, ln in enumerate(said) if "FOAM FATAL" in ln), 0)
                words = " ".join(ln for ln in said[start + 1:start + 3] if not ln.startswith("From "))
                raise SceneError(f"{file}: fluid.case: {path}: OpenFOAM cannot read it: {words}")


def check_case(folder: Path, file: str, ranks: int, energy: bool) -> None:
    """All the checks of the module doc (the files' presence is checked by the caller)."""
    check_dictionaries(folder, file)
    props = _read(folder, "constant/transportProperties", file)
    where = f"{file}: fluid.case: {folder / 'constant/transportProperties'}"
    if _number(props.get("nu")) is None:
        raise SceneError(f"{where}: nu: missing or not a number: write the kinematic viscosity, e.g. "
                         "'nu 1.5e-05;' (m^2/s)")
    if "rho" in props and _number(props["rho"]) is None:
        raise SceneError(f"{where}: rho: must be a number, the gas density in kg/m^3 (e.g. 'rho 1.2;'), "
                         f"got {props['rho']!r}")
    check_start(folder, file)
    check_fields(folder, file, ("U", "p", "T") if energy else ("U", "p"))
    check_fv_options(folder, file)
    if ranks > 1:
        check_decomposition(folder, file, ranks)
