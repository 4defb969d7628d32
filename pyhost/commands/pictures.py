"""``python -m pyhost pictures OUT``: pictures of a finished (or interrupted) run's output.

A separate process on purpose: Debian's libliggghts loads Debian's VTK 9.1, which clashes
with the VTK that pyvista brings (a segfault when both are in one process). ``run`` starts it
with the run (``painter``), so that its imports (about 1 s) overlap the simulation.
"""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "draw a run's pictures: temperatures.png and particles.png in its output folder"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", type=Path, help="output folder of a run (holds history.csv, vtk/)")


def run(args) -> int:
    from pyhost.cli import UserError
    from pyhost.pictures import plot_history, render_particles

    if not (args.out / "history.csv").exists():
        raise UserError(f"{args.out}: no history.csv: not the output folder of a run")
    made = [plot_history(args.out)]
    if (args.out / "vtk" / "particles.pvd").exists():
        made.append(render_particles(args.out))
    print("pictures:", *made)
    return 0


def draw_both(out: Path) -> int:
    """What a ``painter`` draws when told: the history's plot in a forked copy of this process
    while this one renders the particles (0.25-0.35 s and 0.5-1 s, each on its core: the run is
    over, its process waits for these). The copy only draws with matplotlib (VTK's context stays
    this process's) and ends with ``os._exit``; its exit code is the pictures' if it fails."""
    import os
    import sys

    from pyhost.cli import UserError
    from pyhost.pictures import plot_history, render_particles

    if not (out / "history.csv").exists():
        raise UserError(f"{out}: no history.csv: not the output folder of a run")
    if not (out / "vtk" / "particles.pvd").exists():
        print("pictures:", plot_history(out))
        return 0
    sys.stdout.flush()
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            made = plot_history(out)
            print("pictures:", made)
            code = 0
        except (UserError, OSError) as exc:
            from pyhost.exitcodes import classify
            print(f"error: {classify(exc)[1]}", file=sys.stderr)
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
    try:
        made = render_particles(out)
    finally:
        status = os.waitpid(pid, 0)[1]
    print("pictures:", made)
    return os.waitstatus_to_exitcode(status)


def painter(out: Path):
    """A picture process for the run writing into ``out``, started now: it imports the drawing
    libraries while the run goes on (on another core) and draws when ``draw(painter)`` is
    called; closing its input without that (a failed run) ends it without drawing."""
    import subprocess
    import sys
    return subprocess.Popen([sys.executable, "-m", "pyhost.commands.pictures", str(out), "--when-told"],
                            stdin=subprocess.PIPE)


def draw(p) -> int:
    """Tell a ``painter`` to draw now; its exit code once done."""
    try:
        p.stdin.write(b"draw\n")
        p.stdin.close()
    except BrokenPipeError:               # it died early: its exit code says how
        pass
    return p.wait()


if __name__ == "__main__":      # what `run` starts: the same, without building every command's parser
    import os
    import sys
    from pyhost.cli import UserError
    if sys.argv[2:] == ["--when-told"]:
        import signal
        signal.signal(signal.SIGINT, signal.SIG_IGN)   # a Ctrl-C is the run's to handle: it ends this process
        from pyhost.pictures import warm_up
        warm_up()
        if sys.stdin.readline().strip() != "draw":
            sys.exit(0)                  # the run failed: no pictures
    try:
        out = Path(sys.argv[1])
        code = draw_both(out) if sys.argv[2:] == ["--when-told"] else run(argparse.Namespace(out=out))
    except (UserError, OSError) as exc:      # (a full disk: the picture's file named, no traceback)
        from pyhost.exitcodes import classify
        sys.exit(f"error: {classify(exc)[1]}")
    sys.stdout.flush()
    os._exit(code)       # the pictures are written: skip tearing down VTK and matplotlib (0.2 s)
