"""Checkpoints of a run and the restart from one (docs/checkpoint.md).

Every ``output.checkpoint`` seconds of simulated time, and when a signal stops the run, the
coupling loop calls :func:`write` at the end of a step. It writes OUT/.checkpoint.new/:

- ``dem.restart``: LIGGGHTS' ``write_restart`` (atoms, the per-atom ``Temp`` of ``fix
  property/atom Temp ... restart yes``, the tangential contact history of ``fix
  contacthistory`` and of the primitive walls);
- ``host.npz``: the host's arrays (the separation speeds handed to the contact recorder and
  not imposed yet, with restitution feedback; m c T by id; the ids seen) and each atom's
  force and torque of the last step (the recorder's own open contacts are primed again from
  the restart: contacts present then are open, not collisions);
- ``host.json``: the host's values (totals, CT0, steps, warnings given, the byte size of
  collisions.csv, or the rows of the binary collision log, and of history.csv, and the VTK
  frames at this step);
- ``fluid/`` (scenes with a fluid): the solver's fields at this time, written with 17 digits
  (``FluidSolver.save``: the time folder, or each rank's, and the host's last exchange);
- ``manifest.json`` last: the scene file's SHA-256, the code version (SHA-256 of pyhost/ and
  plugins/ sources), step, time, the run's end and its ``--extend``, the SHA-256 of each file
  above, and ``complete`` once the run ended there (``mark_complete``);

then renames it to OUT/checkpoint (the previous one is moved aside first and removed after),
so a failed or interrupted write never destroys the last good checkpoint.

Why the forces. ``write_restart`` re-initialises LIGGGHTS (wraps periodic positions, rebuilds
ghost atoms), and a restart's first run sets up again, which recomputes the forces with the
full-step velocities where the step computed them with half-step ones (velocity Verlet; the
Hertz damping depends on velocity). Both the continuing run (after writing) and the
restarted run (after reading) set up and then put the step's own forces and torques back;
the contact history is not advanced by a set-up (LIGGGHTS' ``shearupdate`` is off then). So a
restart continues exactly as the run that wrote the checkpoint.
"""
from __future__ import annotations

import hashlib
import json
import shutil
import time
from functools import lru_cache
from pathlib import Path

import numpy as np

from pyhost.cli import UserError
from pyhost.outdir import write_atomic
from pyhost.output import check_logs, naming

FOLDER, RESTART, FLUID, FORMAT = "checkpoint", "dem.restart", "fluid", 1
FILES = (RESTART, "host.npz", "host.json")
ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("*.py", "*.C", "*.H", "*.cpp", "*.h")


@lru_cache(maxsize=1)
def code_version() -> str:
    """SHA-256 of the host's and the plugins' sources (paths and contents)."""
    h = hashlib.sha256()
    files = sorted({p for d in ("pyhost", "plugins") for pat in SOURCES for p in (ROOT / d).rglob(pat)
                    if "__pycache__" not in p.parts})
    for p in files:
        h.update(str(p.relative_to(ROOT)).encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def fingerprints(scene, commands) -> dict:
    """SHA-256 of every file the run reads, by absolute path, taken when it starts: a user's
    script, the files it includes and those its commands read (STL meshes, data and restart
    files: ``pyhost.engines.liggghts.script.input_files``), and the dictionaries, mesh and starting fields of
    the user's OpenFOAM case (its system/, constant/ and start time folder). A restart refuses
    to go on if one changed since (``load``). A box scene's generated script is the host's own:
    its case.toml has its fingerprint of its own."""
    from pyhost.engines.liggghts.script import input_files

    files = []
    if scene.scripted:
        files += [Path(f).resolve() for f in dict.fromkeys(c.file for c in commands if c.file != "(host)")]
        files += input_files(commands, scene.folder)
    if scene.effects.fluid and scene.fluid.case:
        from pyhost.engines.fluid_case import start_time

        case = (scene.folder / scene.fluid.case).resolve()
        start = start_time(case)[1]
        for sub in ("system", "constant", *([start] if start else [])):
            files += sorted(p for p in (case / sub).rglob("*") if p.is_file())
    return {str(p): _sha256(p) for p in dict.fromkeys(files)}


def write(coupling) -> Path:
    """A checkpoint of ``coupling`` (a ``pyhost.loop.Coupling`` at the end of a step) into
    OUT/checkpoint; returns its folder."""
    start = time.perf_counter()
    out, dem, scene = coupling.out, coupling.dem, coupling.scene
    final, new, old = out / FOLDER, out / ".checkpoint.new", out / ".checkpoint.old"
    shutil.rmtree(new, ignore_errors=True)
    new.mkdir()
    try:
        _write_into(coupling, new)
    except BaseException:               # a full disk, a stop: no half checkpoint left beside the last good one
        shutil.rmtree(new, ignore_errors=True)
        raise
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        final.rename(old)
    new.rename(final)
    coupling.checkpoint_step = coupling.steps
    shutil.rmtree(old, ignore_errors=True)
    size = sum(p.stat().st_size for p in final.rglob("*") if p.is_file())     # the fluid's fields included
    print(f"checkpoint at t = {coupling.t:.6g} s (step {dem.step}): {final}, {size / 1e6:.3g} MB, "
          f"{time.perf_counter() - start:.2f} s", flush=True)
    return final


def _past_the_box(dem, x) -> bool:
    """Whether a particle at ``x`` [m] lies beyond the box in a direction that is not periodic."""
    lo, hi, periodic = dem.box()
    out = (x < lo) | (x > hi)
    return bool(out[:, ~np.asarray(periodic, bool)].any())


def _write_into(coupling, new: Path) -> None:
    """The checkpoint's files into the folder ``new``, its manifest last."""
    dem, scene = coupling.dem, coupling.scene
    # with fix insert/stream, the step each atom is released at: LIGGGHTS recomputes it on
    # reading a restart from the atom's path (for a changed time step), which can give the
    # step before (measured: the second lot of a stream released early, impact speeds 1e-4
    # apart after); it goes back by id with the forces
    streams = ("release_step",) if dem.info.streams else ()
    ids, f, torque, x, *release = dem.per_atom(("id", "f", "torque", "x") + streams)
    ids = ids.astype(np.int64)
    if _past_the_box(dem, x):
        # particles past a fixed face of the box ('thermo_modify lost ignore'): LIGGGHTS drops
        # them at its next re-neighbouring, which the set-up after write_restart is; a set-up
        # first drops them from the restart file too (they used to stay in it and not in
        # host.npz: "corrupt checkpoint", exit 2, at the checkpoint after a box emptied)
        dem.drop_lost()
        kept = np.isin(ids, dem.per_atom(("id",))[0])
        ids, f, torque, release = ids[kept], f[kept], torque[kept], [r[kept] for r in release]
    dem.write_restart(new / RESTART)
    dem.check_restart(new / RESTART)
    dem.run(0)                                   # set up again, then the step's own forces back
    _put_forces(dem, ids, f, torque)
    values, arrays = state(coupling)
    with naming(new / "host.npz"):
        np.savez(new / "host.npz", ids=ids, f=f, torque=torque, **dict(zip(streams, release)), **arrays)
    write_atomic(new / "host.json", json.dumps(values, indent=1))
    if coupling.fluid is not None:
        coupling.fluid.save(new / FLUID)
    files = sorted(str(p.relative_to(new)) for p in new.rglob("*") if p.is_file())
    manifest = dict(format=FORMAT, scene=str(scene.path), scene_sha256=_sha256(Path(scene.path)),
                    code_version=code_version(), step=dem.step, time=coupling.t, end=scene.time.end,
                    extend=coupling.extend,
                    files={name: _sha256(new / name) for name in files},
                    inputs=coupling.inputs)
    write_atomic(new / "manifest.json", json.dumps(manifest, indent=1))


def mark_complete(out: Path) -> None:
    """The checkpoint in OUT/checkpoint, written at the last step of a completed run, marked so
    (``complete`` in its manifest): a restart from it needs ``--extend``."""
    path = Path(out) / FOLDER / "manifest.json"
    manifest = json.loads(path.read_text())
    manifest["complete"] = True
    write_atomic(path, json.dumps(manifest, indent=1))


def _put_forces(dem, ids, f, torque, **more) -> None:
    """Forces [N] and torques [N m] of the atoms with these ids into LIGGGHTS (on every rank),
    and ``more`` per-atom values by name (``release_step``)."""
    if dem.count() != len(ids):
        raise UserError("checkpoint: the restart file's atoms are not those of host.npz (corrupt checkpoint)")
    try:
        dem.put_per_atom(ids, f=f, torque=torque, **more)
    except ValueError as exc:
        raise UserError(f"checkpoint: the restart file's atoms are not those of host.npz (corrupt checkpoint): "
                        f"{exc}") from None


def state(coupling) -> tuple[dict, dict]:
    """The host's state at the end of a step: (JSON values, arrays), the loop's (its clock,
    totals, the script's input loop, the DEM's mesh motion, random states and insertions) and
    each effect's, their files flushed first (every frame a log names is on disk)."""
    for effect in coupling.effect_list:
        effect.flush()
    dem, ctx = coupling.dem, coupling.ctx
    values = dict(clock=coupling.clock, t_step=coupling.t_step, t_begin=coupling.t_begin, steps=coupling.steps,
                  t=coupling.t, totals=ctx.totals, warned=sorted(ctx.warned), run_left=coupling.run_left,
                  program=coupling.program.state() if coupling.program else {},
                  mesh_motion=dem.mesh_motion_times(), randoms=dem.random_states(),
                  insertions=dem.insertion_progress())
    arrays, logs = {}, {}
    for effect in coupling.effect_list:
        v, a = effect.state()
        logs.update(v.pop("logs", {}))
        values.update(v)
        arrays.update(a)
    values["frame_step"] = coupling.frame_step
    values["logs"] = logs
    return values, arrays


def restore(coupling, state: dict) -> None:
    """``coupling`` (just built) continued from ``state`` (values and arrays of :func:`state` in
    one dict, ``load``'s): the loop's clock and totals, the DEM's forces, mesh motion, random
    states and insertions, each effect's state."""
    from pyhost.effects import totals

    coupling.steps, coupling.t = state["steps"], state["t"]
    coupling.clock = tuple(state["clock"])
    coupling.t_step, coupling.t_begin = state["t_step"], state["t_begin"]
    coupling.ctx.totals = dict(totals(), **state["totals"])    # (a total newer than the checkpoint starts at 0)
    coupling.ctx.warned = set(state["warned"])
    coupling.frame_step = state.get("frame_step")
    dem = coupling.dem
    restore_forces(dem, state)
    dem.set_mesh_motion_times(state.get("mesh_motion", {}))
    dem.set_random_states(state.get("randoms", {}))
    dem.set_insertion_progress(state.get("insertions", {}))
    for effect in coupling.effect_list:
        effect.restore(state)


def restore_forces(dem, state: dict) -> None:
    """After the restarted DEM's set-up: the forces and torques of the checkpoint's step, and
    the release steps of fix insert/stream's atoms."""
    _put_forces(dem, state["ids"], state["f"], state["torque"],
                **{k: state[k] for k in ("release_step",) if k in state})


def load(out: Path, scene, extend: float = 0.0) -> dict:
    """The checkpoint in OUT/checkpoint checked against this scene and this code: its host
    state (values and arrays in one dict), ``restart``, the path of LIGGGHTS' restart file,
    and ``extend``, the checkpoint's run's own ``--extend`` [s], which ``extend`` (this run's)
    may not be below. UserError (exit 2) saying why if there is none, it belongs to another case or
    another code version, or it is damaged; nothing is written. (Every scene restarts; a
    script's commands that a restart cannot replay are refused by ``pyhost.engines.liggghts.script.replay``.)"""
    folder = Path(out) / FOLDER
    if not folder.is_dir() and (Path(out) / ".checkpoint.old").is_dir():
        folder = Path(out) / ".checkpoint.old"    # a write was cut between its two renames
    if not folder.is_dir():
        raise UserError(f"--restart: no checkpoint in {Path(out) / FOLDER} (a run writes one every output.checkpoint s, and "
                        "when a signal stops it after its start; a SIGKILL or a lost node leaves only periodic ones)")
    try:
        manifest = json.loads((folder / "manifest.json").read_text())
        if not isinstance(manifest, dict) or not isinstance(manifest.get("files"), dict):
            raise ValueError("not a manifest")
    except (OSError, ValueError) as exc:
        raise UserError(f"--restart: corrupt checkpoint: {folder / 'manifest.json'}: {exc}") from None
    if manifest.get("format") != FORMAT:
        raise UserError(f"--restart: {folder}: checkpoint format {manifest.get('format')!r}, this code reads {FORMAT}")
    if manifest.get("scene_sha256") != _sha256(Path(scene.path)):
        raise UserError(f"--restart: {folder} is the checkpoint of another case or of another version of "
                        f"{scene.path} (written for {manifest.get('scene')}; the scene file's SHA-256 differs)")
    if manifest.get("code_version") != code_version():
        raise UserError(f"--restart: {folder} was written by another code version ({str(manifest.get('code_version'))[:12]}"
                        f", this is {code_version()[:12]}: SHA-256 of pyhost/ and plugins/); restart it with that code")
    extended = float(manifest.get("extend", 0.0))
    if extend < extended:
        raise UserError(f"--restart: {folder} is of a run given --extend {extended:g}: give at least that")
    end = scene.time.end + extended if extended and not scene.scripted else scene.time.end
    if manifest.get("end") != end:
        raise UserError(f"--restart: {folder} is of a run to t = {manifest.get('end')} s, this one goes to "
                        f"{end} s (--test given to one of them only?)")
    needed = set(FILES) | ({f"{FLUID}/host.npz"} if scene.effects.fluid else set())
    for name, sha in (manifest.get("inputs") or {}).items():
        if not Path(name).is_file() or _sha256(Path(name)) != sha:
            raise UserError(f"--restart: {name} is not the file the checkpoint's run read ("
                            f"{'changed' if Path(name).is_file() else 'gone'} since it started: its SHA-256 then is "
                            "in the checkpoint's manifest.json): a restart continues the run with the inputs it "
                            "read; put the file back, or start the run anew with --overwrite")
    for name in sorted(needed | set(manifest["files"])):
        path = folder / name
        if not path.is_file():
            raise UserError(f"--restart: corrupt checkpoint: {path} is missing")
        if _sha256(path) != manifest["files"].get(name):
            raise UserError(f"--restart: corrupt checkpoint: {path} is not the file written (SHA-256 differs: "
                            "truncated or changed)")
    try:
        state = json.loads((folder / "host.json").read_text())
        with np.load(folder / "host.npz") as arrays:
            state.update({k: arrays[k] for k in arrays.files})
    except (OSError, ValueError) as exc:
        raise UserError(f"--restart: corrupt checkpoint in {folder}: {exc}") from None
    try:
        check_logs(out, state["logs"])
    except (OSError, ValueError) as exc:
        raise UserError(f"--restart: {exc}") from None
    if manifest.get("complete") and extend <= extended:
        raise UserError(f"--restart: the run in {out} is complete (t = {manifest.get('time'):.6g} s): nothing to go "
                        f"on with; --extend SECONDS{f' (above {extended:g})' if extended else ''} runs it longer")
    # what a write cut short by a kill left (a stop or a full disk removes its own): the next
    # checkpoint writes there anew
    shutil.rmtree(Path(out) / ".checkpoint.new", ignore_errors=True)
    state["restart"] = folder / RESTART
    state["extend"] = extended
    state["fluid"] = folder / FLUID if scene.effects.fluid else None
    print(f"restart from {folder}: t = {manifest['time']:.6g} s (step {manifest['step']})")
    return state
