"""A scene's script driven command by command, as LIGGGHTS' input loop runs it, with each of its
``run N`` commands N coupled steps of ``pyhost.loop.Coupling``: the script's own commands go to
the DEM (``Dem.commands``, ``Dem.branch``, ``Dem.jump_skipped``), the host's fixes go in before
the first run (``Dem.prepare``), a restart replays the commands the checkpoint's run had run
(``pyhost.engines.liggghts.script.replay``), the last run is extended (``--extend``) or driven by a CFD-DEM
coupling, and a run that stops still writes its summary and, at a signal, a checkpoint."""
from __future__ import annotations

from pathlib import Path

from pyhost import checkpoint, signals
from pyhost.engines.liggghts.box_input import script_dem_contacts
from pyhost.engines.cfdem_commands import couples_to_cfd
from pyhost.engines.dem import Dem
from pyhost.engines.liggghts import LiggghtsError
from pyhost.loop import Coupling
from pyhost.engines.liggghts.script import Program, ScriptError, if_branches, parse_run, replay


def run_scene(scene, dem: Dem, commands, out: Path, *, walls_of, script: Path, fluid=None, end: float | None = None,
              max_time: float | None = None, driven: float | None = None, extend: float = 0.0,
              progress_every: float = 5.0, log=print, inputs: dict | None = None, **particles) -> dict:
    """Run the script ``script`` on ``dem`` as LIGGGHTS' input loop runs it (``Program``: includes,
    labels and jumps, loops with ``next``, ``if`` branches and ``run ... every``, ``quit``);
    ``commands`` are its commands as read and checked (``read_script``). Each ``run N`` is N
    coupled steps (steps beyond ``max_time`` [s] of coupled time, for smoke runs, are cut).
    ``driven`` [s]: how long the script's last ``run`` lasts when it asks for 0 steps (a CFD-DEM
    script whose coupling drives the run, as CFDEM's end in ``run 0``); in a CFDEM script (``fix
    couple/cfd``) the last run's own steps come first, as CFDEM runs them before its coupling.
    ``extend`` [s]: how much longer than written the script's last run goes on (``run
    --extend``, a restart's; a box scene's end comes extended). The last run is the script's
    last ``run`` command when no ``jump`` follows it. With ``output.checkpoint`` a completed run
    ends in a checkpoint, from which ``--extend`` goes on. ``inputs``: the SHA-256 of each file
    the run reads, taken at its start (``checkpoint.fingerprints``), which its checkpoints keep.
    ``walls_of(dem)`` gives the HostWalls
    once the script's walls exist; ``particles``: type_material, known and resume of
    ``Coupling``. Returns the summary, also written when a step fails; a script whose runs
    simulate no step at all is refused (ScriptError) rather than ending as done."""
    coupling = None
    effects = scene.effects_summary()
    resume = particles.get("resume")
    # a script restarted: the commands it ran replayed up to the run the checkpoint interrupted (its
    # set-up), that run's steps to go, then the script on from where its input loop stood (a box
    # scene's generated script reads the restart itself)
    restarting = resume is not None and scene.scripted
    queue = []                          # (command, "replayed" | "interrupted") before the program's own
    if restarting:
        if "program" not in resume:
            raise ScriptError("--restart: the checkpoint was written by an older version of the host (it does not "
                              "say where the script's input loop stood): start the run anew")
        program = Program.restore(resume["program"], scene.folder)
        trace = program.trace
        if not trace or trace[-1].name != "run":
            raise ScriptError(f"--restart: the checkpoint's last command of {scene.path}'s script is not a run")
        queue = [(c, "replayed") for c in replay(trace, len(trace) - 1, resume["restart"])]
        queue.append((trace[-1], "interrupted"))
    else:
        program = Program(script, scene.folder)
    at = max((k for k, c in enumerate(commands) if c.name == "run"), default=-1)
    last_run = commands[at] if at >= 0 else None
    final_run = last_run if not any(c.name == "jump" for c in commands[at + 1:]) else None
    if extend and final_run is None and scene.scripted:
        raise ScriptError(f"--extend: {scene.path}'s script jumps back after its last run command, so the host "
                          "cannot tell which run is the last to extend")
    # CFDEM runs a script whole (its last run too: often 'run 1'), then its coupling drives the DEM
    cfdem = couples_to_cfd(commands)
    prepared = None
    held = []                           # the reset_timestep commands right before the first run

    def prepare(cmd):
        try:
            added = dem.prepare(heat=effects["particle_temperatures"], contacts=effects["contact_extraction"],
                                fluid_force=fluid is not None, then=held)
        except (LiggghtsError, ScriptError) as exc:
            raise type(exc)(f"{refused_at(cmd, exc)} (the first run): {exc}") from None
        log("host adds to the script: " + ("; ".join(added) if added else "nothing")
            + (f" (before {held[0].where()}'s reset_timestep: LIGGGHTS takes no new fix between a restart's "
               "reset_timestep and its run)" if added and held else ""))
        return added

    def refused_at(cmd, exc, when="set-up") -> str:
        """Where a run's error is: the script's fix that LIGGGHTS' message names, refused in
        this run's set-up or steps (LIGGGHTS checks a fix's values then, not at its line), else
        the run."""
        fix = dem.info.fix_named(str(exc))
        return cmd.where() if fix is None else f"{fix.where()} ('{fix.text[:80]}', refused at {cmd.where()}'s {when})"

    def take():
        """The next command and how it comes: replayed, the interrupted run, or the script's own (None)."""
        if queue:
            return queue.pop(0)
        return program.take(), None

    def plain(cmd, how) -> list:
        """``cmd`` and the plain commands that follow it (taken), up to the next run, if, jump or
        include; the reset_timesteps that end them before the first run held for ``prepare``."""
        if how is None:
            batch = [cmd] + program.plain_ahead()
            for _ in batch[1:]:
                program.take()
            after = program.peek()
        else:
            batch = [cmd]
            while queue and queue[0][0].name != "run":
                batch.append(queue.pop(0)[0])
            after = queue[0][0] if queue else None
        cut = len(batch)
        while prepared is None and after is not None and after.name == "run" and cut > 0 \
                and batch[cut - 1].name == "reset_timestep":
            cut -= 1                    # the host's fixes go in before them (prepare)
        held[:] = batch[cut:]
        return batch[:cut]

    try:
        while True:
            cmd, how = take()
            if cmd is None:
                break
            if cmd.name == "if":        # (the program's own only: a trace holds the branch taken)
                conditions, branches = if_branches(cmd)
                dem.context(cmd)
                try:
                    k = dem.branch(conditions)
                except LiggghtsError as exc:
                    raise LiggghtsError(f"{cmd.where()}: {exc}") from None
                program.push(cmd, branches[k])
                continue
            if cmd.name != "run":
                batch = plain(cmd, how)
                dem.commands(batch)
                if how is None:
                    program.trace += batch + held
                if any(c.name == "next" for c in batch):
                    skip = dem.jump_skipped()
                    if how is None:     # (replayed: the checkpoint says where the loop stood)
                        program.skip_jump = program.skip_jump or skip
                continue
            dem.context(cmd)
            run = parse_run(cmd)
            if not dem.dt > 0:
                raise ScriptError(f"{cmd.where()}: the time step is {dem.dt:g} s: give the script a positive "
                                  "'timestep' before its runs")
            if run.every is not None and how is None:    # chunks of M steps, the commands after each
                try:
                    n, m = dem.steps(run.steps, run.upto), dem.steps(run.every, False)
                except ScriptError as exc:
                    raise ScriptError(f"{cmd.where()}: {exc}") from None
                if m <= 0 or n % m:
                    raise ScriptError(f"{cmd.where()}: run {n} every {m}: {n} steps are not a whole number of "
                                      f"chunks of {m} (LIGGGHTS: 'Invalid run command N value')")
                program.push(cmd, [c for k in range(n // m)        # (pre no: LIGGGHTS sets up the first only)
                                   for c in [f"run {m}" + ("" if run.pre or k == 0 else " pre no"), *run.then]])
                continue
            if how == "replayed":       # a run before the restart's: the host's fixes come at the first
                if prepared is None:
                    prepared = prepare(cmd)
                continue
            if how is None:
                program.trace.append(cmd)
            if coupling is None:
                if prepared is None:
                    prepared = prepare(cmd)
                elif how == "interrupted":  # the replayed commands since the host's fixes: set up, then
                    dem.run(0)              # the checkpoint's forces go back (Coupling's restore)
                walls = walls_of(dem)       # (then the DEM's contacts of the script's materials)
                materials = script_dem_contacts(scene, dem) if scene.scripted else list(scene.materials.values())
                coupling = Coupling(scene, dem, out, walls=walls, fluid=fluid, end=end, materials=materials,
                                    progress_every=progress_every, driven=driven, **particles)
                coupling.inputs = inputs or {}
                coupling.extend = extend
                coupling.start()
            else:
                coupling.at_run(walls_of(dem))
            coupling.program = program
            if how == "interrupted":
                n = int(resume["run_left"])
                log(f"{cmd.where()}: restarted in this run, {n} steps to go")
            else:
                try:
                    n = dem.steps(run.steps, run.upto)
                except ScriptError as exc:
                    raise ScriptError(f"{cmd.where()}: {exc}") from None
            last = cmd == final_run and run.every is None
            if last and driven is not None and (n == 0 or cfdem) and how != "interrupted":
                more = round(driven / dem.dt)
                log(f"{cmd.where()}: " + ("the script ends in a run of 0 steps, which the coupling drives" if n == 0
                    else f"a CFDEM script (fix couple/cfd): its last run's {n} steps, then the coupling drives")
                    + f": {driven:g} s ({more} steps; [time] end, else the fluid case's controlDict endTime)")
                n += more
            if last and scene.scripted and extend:
                more = round((extend - resume["extend"] if how == "interrupted" else extend) / dem.dt)
                n += more
                if more:
                    log(f"{cmd.where()}: --extend {extend:g}: {more} steps more than the case asks")
            if max_time is not None:
                n = min(n, round((max_time - (coupling.t - coupling.t_begin)) / dem.dt))
            if run.pre and how != "interrupted" and not (resume is not None and not scene.scripted):
                dem.set_up_next()       # (not the run a restart continues: from the checkpoint's forces)
            if n > 0:
                try:
                    coupling.advance(n)
                except LiggghtsError as exc:      # e.g. "Lost atoms" in a chunk not tried first
                    raise type(exc)(f"{refused_at(cmd, exc, 'run')}: {exc}") from None
            dem.report_warnings(cmd)
        if coupling is not None and coupling.steps == 0:
            raise ScriptError(f"{scene.path}: the script's runs simulate no step (its last is "
                              f"{last_run.where()}: '{last_run.text}'); give the steps in "
                              f"the script" + (", or the coupled time as [time] end" if fluid is not None else ""))
        if coupling is not None and scene.output.checkpoint:    # a completed run ends in a checkpoint, marked
            if coupling.checkpoint_step != coupling.steps:       # so: --extend goes on from there
                coupling.settle()
                checkpoint.write(coupling)
            checkpoint.mark_complete(out)
    except BaseException as exc:          # keep what was computed: summary of the run so far
        if isinstance(exc, signals.Interrupted) and coupling is not None and coupling.ready \
                and coupling.checkpoint_step != coupling.steps:   # (not twice at one step)
            try:
                coupling.settle()
                checkpoint.write(coupling)
            except Exception as err:      # the stop goes on: summary, engines closed, exit 128 + n
                log(f"warning: no checkpoint at the stop ({type(err).__name__}: {err}); the last one stays")
        if coupling is not None:
            try:
                coupling.finish(status=f"stopped at t = {coupling.t:g} s by {type(exc).__name__}: {exc}")
            except Exception as err:      # the error that stopped the run is the one to report
                log(f"warning: no summary.json ({type(err).__name__}: {err}); collisions.csv and history.csv "
                    "hold the run so far")
        raise
    if coupling is None:
        raise ScriptError(f"{scene.path}: the script has no 'run' command: nothing to simulate")
    if scene.frozen.end > 0:                  # the bed frozen where the runs left it: heat alone
        from pyhost.frozen import frozen_stage
        try:
            frozen_stage(coupling, log=log)
        except BaseException as exc:          # what came before stays: its summary, then the error
            try:
                coupling.finish(status=f"stopped in the frozen stage at t = {coupling.t:g} s by "
                                       f"{type(exc).__name__}: {exc}")
            except Exception as err:
                log(f"warning: no summary.json ({type(err).__name__}: {err})")
            raise
    return coupling.finish()
