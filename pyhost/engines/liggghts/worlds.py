"""How the host sees the particles and walls of a LIGGGHTS world: the generated box world of a
box scene (``box_world``: its input written by ``box_input``, one atom type per material, walls
``wall<k>``) or a user's script (``user_script``: atom types to materials by the scene's
``types``, the script's wall/gran fixes to the scene's [[walls]]). ``pyhost.world.simulate``
calls them. SI units.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pyhost.engines.liggghts.box_input import input_lines, place_particles, write_data


def box_world(scene, out: Path, start=None, restart: Path | None = None, pending: list | None = None):
    """The generated DEM of a box scene: its script (run for time.end) and how the host sees
    its particles: one atom type per material, groups = the [[particles]] tables, walls
    ``wall<k>`` = the scene's [[walls]]. ``start``: the particles (``pyhost.engines.liggghts.box_input.Particles``,
    e.g. a settled bed) to start from instead of the scene's placement; the contacts present
    then are not collisions of this run. ``restart``: LIGGGHTS' restart file of a checkpoint
    to read instead of the particles (the same commands re-issued, with the same ids).
    ``pending``: where given, the data file is written by the output thread, its future appended
    there (the caller waits for it before LIGGGHTS reads the file: box-27k's 27,000 lines take
    0.15-0.3 s, while LIGGGHTS' MPI start releases the GIL); else now."""
    from pyhost.tables import HostWall, Known

    folder = out / "dem"
    folder.mkdir(parents=True, exist_ok=True)
    particles = place_particles(scene) if start is None else start
    steps = round(scene.time.end / scene.time.dem_step)
    if restart is None:
        data = folder / "particles.data"
        if pending is None:
            write_data(data, scene, particles)
        else:
            from pyhost.output import later
            pending.append(later(write_data, data, scene, particles))
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
