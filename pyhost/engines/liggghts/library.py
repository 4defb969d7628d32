"""LIGGGHTS 3.8 (Debian's ``libliggghts.so.3``) driven in process through ctypes.

One ctypes declaration per C function (``_declare``); per-atom data as zero-copy numpy
views of LIGGGHTS' own arrays, valid until the next command or run (take them again after
each :meth:`Liggghts.run`); contact lists of ``compute pair/gran/local`` and
``compute wall/gran/local`` read through the project's helper library
(``plugins/liggghts``, built by ``tools/setup.sh --engines``), which also exposes the force
array of a ``fix external pf/array`` for per-atom forces set from Python.

LIGGGHTS ends its process on any error (``exit(1)``). So every command, input file and the
first run after a change is tried first in a forked copy of this process: when the copy
dies, :class:`LiggghtsError` carries LIGGGHTS' own ``ERROR`` line and this process goes on
unharmed. A command run before without error is not tried again, nor the run after only such
repeats (a CFDEM case's ``set`` at every coupling step: two forks a step otherwise). Later run
chunks are not tried (a fork costs milliseconds, a chunk microseconds):
the helper turns LIGGGHTS' errors into a return with the message (``collheat_command``), so
a chunk that fails ("Lost atoms", on any rank together) raises :class:`LiggghtsFailed` and
the caller can still read the atoms and write its summary; the instance then runs nothing
more. An error raised by one rank alone under MPI still ends the job through MPI_Abort,
with LIGGGHTS' message on stderr. Units are whatever the input sets; the project uses ``units si`` (m, kg, s, K, N).
"""
from __future__ import annotations

import atexit
import ctypes
import faulthandler
import os
import re
import select
import signal
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

import numpy as np

from pyhost.exitcodes import SimulationFailed
from pyhost.walls import primitive_overlap

LIB = "libliggghts.so.3"
_ISOLATED = "OMPI_MCA_ess_singleton_isolated"
_disarm_registered = False
HELPER = Path(__file__).resolve().parents[3] / ".setup" / "lib" / "libcollheat_liggghts.so"

_c = ctypes
_vp, _cp, _int = _c.c_void_p, _c.c_char_p, _c.c_int
_DECLARATIONS = {
    # name: (restype, argtypes) -- the 2013 LAMMPS C API that LIGGGHTS 3.8 exports
    "lammps_open_no_mpi": (None, [_int, _c.POINTER(_cp), _c.POINTER(_vp)]),
    "lammps_open": (None, [_int, _c.POINTER(_cp), _vp, _c.POINTER(_vp)]),
    "lammps_close": (None, [_vp]),
    "lammps_file": (None, [_vp, _cp]),
    "lammps_command": (_cp, [_vp, _cp]),
    "lammps_extract_global": (_vp, [_vp, _cp]),
    "lammps_extract_atom": (_vp, [_vp, _cp]),
    "lammps_extract_compute": (_vp, [_vp, _cp, _int, _int]),
    "lammps_extract_fix": (_vp, [_vp, _cp, _int, _int, _int, _int]),
    "lammps_get_natoms": (_int, [_vp]),
    "lammps_extract_variable": (_vp, [_vp, _cp, _cp]),
}
_HELPER_DECLARATIONS = {
    "collheat_watch_exit": (None, [_vp, _cp]),
    "collheat_command": (_int, [_vp, _cp, _int]),
    "collheat_failure": (_cp, []),
    "collheat_context": (None, [_cp]),
    "collheat_flush": (None, [_vp]),
    "collheat_trial_output": (_int, [_vp, _cp]),
    "collheat_take_jump_skip": (_int, [_vp]),
    "collheat_compute_local": (_int, [_vp, _cp, _c.POINTER(_int), _c.POINTER(_int),
                                      _c.POINTER(_c.POINTER(_c.c_double))]),
    "collheat_fix_external_force": (_c.POINTER(_c.c_double), [_vp, _cp]),
    "collheat_move_mesh_time": (_int, [_vp, _cp, _c.POINTER(_c.c_double), _int]),
    "collheat_random_state": (_int, [_vp, _cp, _cp, _c.POINTER(_int), _int]),
    "collheat_insert_progress": (_int, [_vp, _cp, _c.POINTER(_c.c_double), _int]),
    "collheat_keep_mesh_bins": (_int, [_vp]),
    "collheat_dump_every": (_int, [_vp]),
    "collheat_unit_style": (_cp, [_vp]),
    "collheat_atom_style": (_cp, [_vp]),
    "collheat_sphere_atoms": (_int, [_vp]),
}

# Per-atom arrays: name -> (ctype, columns; 0 for a vector).
_ATOM = {
    "x": (_c.c_double, 3), "v": (_c.c_double, 3), "f": (_c.c_double, 3),
    "omega": (_c.c_double, 3), "torque": (_c.c_double, 3), "radius": (_c.c_double, 0), "rmass": (_c.c_double, 0),
    "id": (_c.c_int, 0), "type": (_c.c_int, 0),
}


WARNING_LINES = 30     # the most lines a LIGGGHTS warning is looked for in before its location
_LOCATION = re.compile(r"\([^()\s]+:\d+\)\s*$")


class LiggghtsError(RuntimeError):
    """A LIGGGHTS error, with LIGGGHTS' own message."""


class LiggghtsFailed(LiggghtsError, SimulationFailed):
    """LIGGGHTS stopped with an error during a run chunk that had started (e.g. "Lost atoms"):
    a failed simulation (exit 3), not bad input."""


def _declare(lib: ctypes.CDLL, table: dict) -> None:
    for name, (restype, argtypes) in table.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, argtypes


@dataclass(frozen=True)
class ComputeRows:
    """A contact compute's rows now, one contact each (all SI): the raw probe of LIGGGHTS'
    ``pair/gran/local`` and ``wall/gran/local`` that the engine tests and benchmarks read (runs
    take contacts from the event recorder, ``pyhost.engines.events``).

    ``i``, ``j``: atom ids (for a wall contact ``j`` is the wall's index); ``delta``: normal
    overlap (m); ``vi``, ``vj``: velocities of the two (m/s; ``vj`` is the wall's), so the
    relative velocity is ``vi - vj``; ``area``: contact area (m^2) as LIGGGHTS computes it.
    """

    i: np.ndarray
    j: np.ndarray
    delta: np.ndarray
    vi: np.ndarray
    vj: np.ndarray
    area: np.ndarray

    def __len__(self) -> int:
        return len(self.i)


# compute pair/gran/local with these columns, in LIGGGHTS' own column order:
# vel (6), id (3: i, j, periodic), contactArea (1), delta (1).
_PAIR_KEYWORDS = "vel id contactArea delta"


def granular_box(lo, hi, *, youngs: float, poisson: float, restitution: float,
                 friction: float, skin: float, dt: float) -> list[str]:
    """Commands opening a one-material granular SI simulation in the box ``lo``-``hi`` (m)
    with fixed boundaries, with the settings this bridge relies on (atom map, newton off,
    ghost velocities): Hertz contacts of Young's modulus ``youngs`` (Pa), Poisson ratio,
    restitution and friction coefficients, neighbour ``skin`` (m) and time step ``dt`` (s)."""
    num = lambda x: repr(float(x))  # every digit of the double
    box = " ".join(f"{num(a)} {num(b)}" for a, b in zip(lo, hi))
    return [
        "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
        "communicate single vel yes", "units si",
        *(["hard_particles yes"] if youngs > 1e9 else []),
        f"region box block {box} units box", "create_box 1 box",
        f"neighbor {num(skin)} bin", "neigh_modify delay 0",
        f"fix m1 all property/global youngsModulus peratomtype {num(youngs)}",
        f"fix m2 all property/global poissonsRatio peratomtype {num(poisson)}",
        f"fix m3 all property/global coefficientRestitution peratomtypepair 1 {num(restitution)}",
        f"fix m4 all property/global coefficientFriction peratomtypepair 1 {num(friction)}",
        "pair_style gran model hertz tangential history", "pair_coeff * *",
        f"timestep {num(dt)}",
    ]


class Liggghts:
    """One LIGGGHTS instance in this process: serial, or one rank of a LIGGGHTS that
    decomposes its domain over the ranks of ``comm`` (an mpi4py communicator; every rank
    must then make the same collective calls: commands, runs, variables).

    ``workdir``: where LIGGGHTS writes its screen log (``log.liggghts``; rank 0's only); a
    temporary directory if None. ``check``: try commands in a forked copy first (see the
    module doc; never on several ranks, where a forked copy cannot take part in MPI: there a
    LIGGGHTS error ends the job through MPI_Abort, with its message on stderr).
    """

    def __init__(self, workdir: str | os.PathLike | None = None, *, check: bool = True,
                 variables: dict | None = None, comm=None):
        if not HELPER.is_file():
            raise LiggghtsError(f"{HELPER} is missing: run tools/setup.sh --engines")
        self._tmp = None if workdir else tempfile.TemporaryDirectory(prefix="liggghts-")
        self.workdir = Path(workdir or self._tmp.name)
        self.workdir.mkdir(parents=True, exist_ok=True)
        self.log = self.workdir / "log.liggghts"
        self.comm = comm if comm is not None and comm.Get_size() > 1 else None
        self.check = check and self.comm is None
        # The helper first: its MPI_Abort must come before OpenMPI's (see plugins/liggghts).
        self.helper = ctypes.CDLL(str(HELPER), mode=ctypes.RTLD_GLOBAL)
        self.lib = ctypes.CDLL(LIB, mode=ctypes.RTLD_GLOBAL)
        _declare(self.lib, _DECLARATIONS)
        _declare(self.helper, _HELPER_DECLARATIONS)
        args = [b"liggghts", b"-screen", str(self.log).encode(), b"-log", b"none"]
        for name, value in (variables or {}).items():      # as 'liggghts -var NAME VALUE'
            args += [b"-var", str(name).encode(), str(value).encode()]
        argv = (_cp * len(args))(*args)
        self.ptr = _vp()
        self.failed: str | None = None   # LIGGGHTS' error that left this instance mid-command
        self._changed = True  # a command since the last run: the next run sets up anew
        self._new = True      # ... one not run before: that set-up is tried first
        self._known = set()   # commands run without error: a repeat is not tried again
        self._ahead: list[str] = []     # the next commands, tried together already (try_ahead)
        if self.comm is not None:
            from mpi4py import MPI
            self.lib.lammps_open(len(args), argv, _vp(MPI._handleof(self.comm)), ctypes.byref(self.ptr))
            self._watch()
            return
        # A forked copy must be able to call MPI_Finalize without a server of the parent's
        # MPI: a singleton MPI without one. Set only while MPI starts (mpirun's children
        # must not inherit it).
        saved = os.environ.get(_ISOLATED)
        os.environ[_ISOLATED] = "1"
        try:
            self.lib.lammps_open_no_mpi(len(args), argv, ctypes.byref(self.ptr))
        finally:
            if saved is None:
                del os.environ[_ISOLATED]
            else:
                os.environ[_ISOLATED] = saved
        self._watch()

    def context(self, text: str) -> None:
        """What is being run (the script's file and line), named if LIGGGHTS ends the process."""
        self.helper.collheat_context(text.encode())

    def new_warnings(self) -> list[str]:
        """LIGGGHTS' WARNING lines written to its screen log since the last call (rank 0's)."""
        self.helper.collheat_flush(self.ptr)
        try:
            size = self.log.stat().st_size
        except FileNotFoundError:
            return []
        start = getattr(self, "_screen_read", 0)
        if size <= start:
            return []
        with open(self.log, "rb") as f:
            f.seek(start)
            text = f.read(size - start).decode(errors="replace")
        complete = text.rfind("\n") + 1               # a line still being written waits for the next call
        lines = text[:complete].splitlines(keepends=True)
        warnings, k, read = [], 0, 0
        while k < len(lines):
            if not lines[k].startswith("WARNING"):
                read += len(lines[k])
                k += 1
                continue
            # a warning ends at its source location, "(./src/contact_models.h:364)": LIGGGHTS'
            # whitelist warning is "WARNING: " and then 8 lines of text before it
            end = next((j for j in range(k, min(k + WARNING_LINES, len(lines))) if _LOCATION.search(lines[j])), None)
            if end is None and len(lines) - k < WARNING_LINES:
                break                   # the rest of it is still being written: read it at the next call
            end = k if end is None else end
            warnings.append(" ".join(" ".join(ln.split()) for ln in lines[k:end + 1] if ln.strip()))
            read += sum(len(ln) for ln in lines[k:end + 1])
            k = end + 1
        self._screen_read = start + len(text[:read].encode(errors="replace"))
        return warnings

    def _watch(self) -> None:
        self.helper.collheat_watch_exit(self.ptr, str(self.log).encode())
        global _disarm_registered
        if not _disarm_registered:  # Python's own exit runs this first: the helper stays quiet
            atexit.register(self.helper.collheat_watch_exit, None, b"")
            _disarm_registered = True

    # -- commands ---------------------------------------------------------------------
    def command(self, line: str) -> None:
        """Execute one LIGGGHTS command; raise LiggghtsError with LIGGGHTS' message."""
        if line.split()[:1] == ["include"]:
            raise LiggghtsError("'include' does nothing through the C API: use Liggghts.file()")
        if self._ahead and self._ahead[0] == line:
            self._ahead.pop(0)          # passed in the copy that tried it with those before it
            self._new = True
        elif line in self._known:       # run before without error (a CFDEM case's command at every
            pass                        # coupling step): not tried again; an error returns (the helper)
        elif line.split()[:1] == ["shell"]:
            self._ahead = []            # not in a copy: its files and programs would be acted on twice
        else:
            self._ahead = []
            self._tried(lambda: self._call(line), line)
            self._new = True
        self._execute(line, LiggghtsError)
        self._known.add(line)
        self._changed = True

    def try_ahead(self, lines: list[str]) -> None:
        """Try the next commands together, in one forked copy, instead of each in its own
        (a fork costs a few ms): those that pass there run without a trial of their own if
        they come next, in this order. From the first that fails there (or that the copy dies
        in), each is tried alone when it comes, which reports its error as usual."""
        self._ahead = []
        shell = next((k for k, line in enumerate(lines) if line.split()[:1] == ["shell"]), len(lines))
        lines = lines[:shell]           # (a shell command is not tried: see command)
        if not self.check or len(lines) < 2:
            return
        passed = self.workdir / "log.trial.passed"

        def call() -> int:
            fd = os.open(passed, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            for line in lines:
                if self._call(line):
                    return 1
                os.write(fd, b".")      # one byte per command passed: a crash leaves the count
            return 0

        try:
            self._tried(call, f"{lines[0]} and the {len(lines) - 1} commands after it")
        except LiggghtsError:
            pass                        # the one that failed says so when it comes
        n = passed.stat().st_size if passed.exists() else 0
        passed.unlink(missing_ok=True)
        self._ahead = list(lines[:n])

    def commands(self, lines: Iterable[str] | str) -> None:
        """Execute several commands (an iterable, or a string of lines; '#' starts a comment)."""
        if isinstance(lines, str):
            lines = lines.splitlines()
        lines = [ln for ln in (line.split("#", 1)[0].strip() for line in lines) if ln]
        self.try_ahead(lines)
        for line in lines:
            self.command(line)

    def file(self, path: str | os.PathLike) -> None:
        """Execute an input file (what ``include`` would do)."""
        path = Path(path)
        if not path.is_file():
            raise LiggghtsError(f"LIGGGHTS input {path} does not exist")
        self._ahead = []
        self._tried(lambda: self._call(str(path), is_file=True), f"file {path}")
        self._execute(str(path), LiggghtsError, is_file=True)
        self._changed = self._new = True

    def check_restart(self, path: str | os.PathLike) -> None:
        """A restart file just written, read back whole in a forked copy: LIGGGHTS writes it
        with fwrite and ignores a failed write, so a full disk left a cut file (8000 of 10,441
        bytes) and a checkpoint that said nothing. LiggghtsError with LIGGGHTS' message if it
        cannot read it (serial only: see ``check``). A copy still reading after 10 s and 1 s per
        MB of the file is ended by its alarm (LIGGGHTS' reader can loop for ever on a file cut at
        some places: measured, a pour's restart cut at 8,000 bytes)."""
        limit = 10 + int(Path(path).stat().st_size / 1e6)

        def call() -> int:
            os.dup2(os.open(os.devnull, os.O_WRONLY), 1)   # (the copy's only: a fix's read prints "version 3 8")
            signal.alarm(limit)                             # (SIGALRM's default ends the copy)
            return self._call("clear") or self._call(f"read_restart {path}")
        self._tried(call, f"read_restart {path}")

    def set_up_next(self) -> None:
        """The next run starts with a full set-up (a script's ``run``, whose default ``pre yes``
        recomputes the forces from a fresh neighbour list, as plain LIGGGHTS does at each run)."""
        self._changed = True

    def keep_set_up(self) -> None:
        """The next run starts without a set-up, whatever came since the last one (the caller
        put back what a set-up would recompute: a checkpoint's forces)."""
        self._changed = False

    def run(self, steps: int) -> None:
        """Advance ``steps`` time steps as one chunk (``run N pre no post no``); the first run
        after any command does a full set-up (``pre yes``), tried first in a forked copy (an
        error there is bad input, LiggghtsError); an error while stepping is LiggghtsFailed."""
        if steps < 0:
            raise ValueError(f"steps must be >= 0, got {steps}")
        self._ahead = []
        line = f"run {steps} post no" if self._changed else f"run {steps} pre no post no"
        set_up = self._changed and self._new
        if set_up:                          # the set-up is tried (bad input), unless only commands run
            self._tried(lambda: self._call("run 0 post no"), line)     # before came since the last run;
        elif not self._changed:             # what fails while stepping returns. Mesh walls keep the bins
            self.helper.collheat_keep_mesh_bins(self.ptr)   # of their triangles (plugins/liggghts/run_chunks.cpp)
        start = self.step
        try:
            self._execute(line, LiggghtsFailed, what="during the run, at step {step}")
        except LiggghtsFailed:
            # on several ranks no copy tried the set-up: an error before the first step (LIGGGHTS
            # counts a step at its start) is the set-up's, bad input as it is serially
            if set_up and not self.check and self.step == start:
                raise LiggghtsError(f"LIGGGHTS refused '{line}': {self.failed}") from None
            raise
        self._changed = self._new = False

    def _call(self, line: str, is_file: bool = False) -> int:
        """One command (or input file) through the helper: 0, or 1 when LIGGGHTS reported
        an error (``collheat_failure``) and returned instead of ending the process."""
        return self.helper.collheat_command(self.ptr, line.encode(), int(is_file))

    def _execute(self, line: str, error: type, is_file: bool = False, what: str | None = None) -> None:
        if self.failed:
            raise LiggghtsError(f"LIGGGHTS stopped at an earlier error and runs nothing more: {self.failed}")
        if self._call(line, is_file):
            self.failed = (self.helper.collheat_failure() or b"").decode(errors="replace").strip() or "no message"
            raise error(f"{(what or repr(line)).format(step=self.step)}: {self.failed}")

    def _tried(self, call, what: str) -> None:
        """Run ``call`` in a forked copy of this process, its LIGGGHTS output going to a
        file of its own; raise LiggghtsError with LIGGGHTS' message if the copy died."""
        if not self.check:
            return
        self.helper.collheat_flush(self.ptr)
        trial = self.workdir / "log.trial"
        # Interrupts wait until the trial is over: a handler's exception raised inside fork's
        # hooks would be swallowed, and the copy must not run Python's handlers at all.
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, (signal.SIGINT, signal.SIGTERM, signal.SIGHUP))
        try:
            pid = os.fork()
            if pid == 0:  # the copy: never returns into Python's normal flow
                try:
                    # a copy that dies of a fault is reported by the parent ("LIGGGHTS crashed
                    # on ..."): no Python traceback dump of the copy (faulthandler, on under
                    # pytest and PYTHONFAULTHANDLER) on the user's terminal
                    faulthandler.disable()
                    self.helper.collheat_watch_exit(self.ptr, b"")  # the parent reports, not the copy
                    self.helper.collheat_trial_output(self.ptr, str(trial).encode())
                    failed = call()
                    self.helper.collheat_flush(self.ptr)
                    os._exit(1 if failed else 0)
                finally:
                    os._exit(1)
            status = self._wait_trial(pid, trial)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        if os.waitstatus_to_exitcode(status) != 0:
            text = trial.read_text(errors="replace") if trial.exists() else ""
            trial.unlink(missing_ok=True)
            errors = [ln for ln in text.splitlines() if ln.startswith("ERROR")]
            code = os.waitstatus_to_exitcode(status)
            if errors or code > 0:
                message = errors[-1] if errors else (text.strip().splitlines() or ["no message"])[-1]
                raise LiggghtsError(f"LIGGGHTS refused '{what}': {message}")
            raise LiggghtsError(f"LIGGGHTS crashed on '{what}' (signal {signal.Signals(-code).name}, no error message: "
                                "a fault of LIGGGHTS or of the host's helper on this input; please report it)")
        trial.unlink(missing_ok=True)

    @staticmethod
    def _wait_trial(pid: int, trial: Path) -> int:
        """Wait for the copy: woken the moment it ends (a pidfd; where the kernel has none,
        by polling). One that wrote an ERROR line and still lives a second later is stuck in
        MPI_Finalize (MPI started by another LIGGGHTS user of this process, without the
        isolated singleton): end it."""
        errored_at, start, status = None, time.monotonic(), None
        try:
            fd = os.pidfd_open(pid)
        except OSError:
            fd = None
        poller = select.poll()
        if fd is not None:
            poller.register(fd, select.POLLIN)

        def ended() -> bool:                      # within 20 ms (or 2 ms, polling), or now
            nonlocal status
            if fd is not None:
                return bool(poller.poll(20))
            done, status = os.waitpid(pid, os.WNOHANG)
            if not done:
                status = None
                time.sleep(0.002)
            return bool(done)

        try:
            while not ended():
                now = time.monotonic()
                if (errored_at is None and now - start > 0.5 and trial.exists()
                        and "\nERROR" in "\n" + trial.read_text(errors="replace")):
                    errored_at = now
                if errored_at is not None and now - errored_at > 1.0:
                    os.kill(pid, signal.SIGKILL)
                    break
            return status if status is not None else os.waitpid(pid, 0)[1]
        finally:
            if fd is not None:
                os.close(fd)

    # -- per-atom data ----------------------------------------------------------------
    @property
    def nlocal(self) -> int:
        """Number of atoms owned by this process."""
        return ctypes.cast(self.lib.lammps_extract_global(self.ptr, b"nlocal"),
                           ctypes.POINTER(_int))[0]

    @property
    def natoms(self) -> int:
        return self.lib.lammps_get_natoms(self.ptr)

    @property
    def step(self) -> int:
        """Current time step number."""
        raw = self.lib.lammps_extract_global(self.ptr, b"ntimestep")
        return ctypes.cast(raw, ctypes.POINTER(ctypes.c_int64))[0]

    def styles(self) -> tuple[str, str, bool]:
        """LIGGGHTS' unit style now (the script's ``units``, a restart file's, or the default lj),
        its atom style (the script's ``atom_style``, a restart file's, or the default atomic) and
        whether its atoms are plain spheres (radius and mass per atom, no other shape)."""
        h = self.helper
        return (h.collheat_unit_style(self.ptr).decode(), h.collheat_atom_style(self.ptr).decode(),
                bool(h.collheat_sphere_atoms(self.ptr)))

    def dump_every(self) -> int:
        """The interval [steps] of the most frequent dump defined now with a fixed interval
        (a dump whose interval is a variable is left out); 0 if there is none."""
        return self.helper.collheat_dump_every(self.ptr)

    @property
    def dt(self) -> float:
        """Time step (s)."""
        return ctypes.cast(self.lib.lammps_extract_global(self.ptr, b"dt"),
                           ctypes.POINTER(ctypes.c_double))[0]

    def take_jump_skip(self) -> bool:
        """Whether a ``next`` since the last call exhausted its variable, so that LIGGGHTS would
        skip the next ``jump`` (plugins/liggghts/input_loop.cpp); the flag is cleared."""
        return bool(self.helper.collheat_take_jump_skip(self.ptr))

    def variable(self, name: str) -> float:
        """Value of an equal-style variable."""
        raw = self.lib.lammps_extract_variable(self.ptr, name.encode(), None)
        if not raw:
            raise LiggghtsError(f"no equal-style variable '{name}'")
        return ctypes.cast(raw, ctypes.POINTER(ctypes.c_double))[0]

    def fix_global(self, fix_id: str, i: int, j: int | None = None) -> float:
        """Element i (or i, j) of a fix's global vector (array), e.g. of a property/global."""
        raw = self.lib.lammps_extract_fix(self.ptr, fix_id.encode(), 0, 1 if j is None else 2, i, j or 0)
        if not raw:
            raise LiggghtsError(f"fix '{fix_id}' has no global {'vector' if j is None else 'array'}")
        return ctypes.cast(raw, ctypes.POINTER(ctypes.c_double))[0]

    def box(self):
        """(lo, hi) corners of the simulation box [m]."""
        get = lambda name: ctypes.cast(self.lib.lammps_extract_global(self.ptr, name.encode()),
                                       ctypes.POINTER(ctypes.c_double))[0]
        lo = np.array([get(f"box{a}lo") for a in "xyz"])
        hi = np.array([get(f"box{a}hi") for a in "xyz"])
        return lo, hi

    def atom(self, name: str) -> np.ndarray:
        """Zero-copy view of a per-atom array of the local atoms, in LIGGGHTS' local order:
        x, v, f, omega (n, 3); radius, rmass, id, type (n,); ``release_step`` (n,): the step at
        which fix insert/stream releases each atom it inserted (0: none; the fixes keep it in
        the per-atom array of their ``fix release_fix_insert_stream``). Valid until the next run."""
        if name == "release_step":
            return self._release_step()
        if name not in _ATOM:
            raise ValueError(f"unknown per-atom array '{name}'; choices: {', '.join(_ATOM)}")
        ctype, cols = _ATOM[name]
        raw = self.lib.lammps_extract_atom(self.ptr, name.encode())
        n = self.nlocal
        if not raw or n == 0:
            return np.zeros((0, cols) if cols else (0,), dtype=np.dtype(ctype))
        if cols:
            first = ctypes.cast(raw, ctypes.POINTER(ctypes.POINTER(ctype)))[0]
            return np.ctypeslib.as_array(first, shape=(n, cols))
        return np.ctypeslib.as_array(ctypes.cast(raw, ctypes.POINTER(ctype)), shape=(n,))

    def _release_step(self) -> np.ndarray:
        # column 4 of fix insert/stream's 14 values per atom (its finalize_insertion in
        # fix_insert_stream.cpp), rows contiguous (LAMMPS' memory->grow of a 2-d array)
        raw = self.lib.lammps_extract_fix(self.ptr, b"release_fix_insert_stream", 1, 2, 0, 0)
        if not raw:
            raise LiggghtsError("no fix insert/stream (its per-atom 'release_fix_insert_stream')")
        n = self.nlocal
        if n == 0:
            return np.zeros(0)
        first = ctypes.cast(raw, ctypes.POINTER(ctypes.POINTER(ctypes.c_double)))[0]
        return np.ctypeslib.as_array(first, shape=(n, 14))[:, 4]

    def property_atom(self, name: str) -> np.ndarray:
        """Zero-copy view of the per-atom scalar of a ``fix property/atom`` named ``name``
        (for ``fix heat/gran``: ``Temp`` in K, ``heatFlux`` in W). Writes into it are seen by
        the next run; values written before the first run are reset by it."""
        raw = self.lib.lammps_extract_fix(self.ptr, name.encode(), 1, 1, 0, 0)
        if not raw:
            raise LiggghtsError(f"no per-atom property '{name}' (a fix property/atom with that id)")
        return np.ctypeslib.as_array(ctypes.cast(raw, ctypes.POINTER(ctypes.c_double)),
                                     shape=(self.nlocal,))

    def temperature(self) -> np.ndarray:
        """Particle temperatures (K) of ``fix heat/gran``: a writable zero-copy view. Ghost
        copies (periodic boundaries, other MPI ranks) see a write at the next re-neighbour."""
        return self.property_atom("Temp")

    def external_force(self, fix_id: str) -> np.ndarray:
        """Writable zero-copy (n, 3) view of the force (N) that ``fix <fix_id> all external
        pf/array 1`` adds to each local atom every step. It holds uninitialised memory until
        written, and the set-up of a run already adds it: write it (or zero it) and run a
        set-up again (``command("run 0")``) before the first step, as ``SceneDem`` does."""
        raw = self.helper.collheat_fix_external_force(self.ptr, fix_id.encode())
        if not raw:
            raise LiggghtsError(f"no 'fix {fix_id} ... external pf/array' (or no run yet)")
        return np.ctypeslib.as_array(raw, shape=(self.nlocal, 3))

    def move_mesh_time(self, fix_id: str, value: float | None = None) -> float:
        """The time [s] of ``fix <fix_id> ... move/mesh`` since its motion began (its phase);
        with ``value``, set it first. LIGGGHTS' restart files do not keep it (see
        plugins/liggghts/restart_state.cpp)."""
        t = ctypes.c_double(0.0 if value is None else value)
        if self.helper.collheat_move_mesh_time(self.ptr, fix_id.encode(), ctypes.byref(t), int(value is not None)):
            raise LiggghtsError(f"no 'fix {fix_id} ... move/mesh'")
        return t.value

    def random_state(self, what: str, id_: str, value: int | None = None) -> int | None:
        """The state of one of insertion's random generators on this rank (None: there is none):
        ``what`` is "region", "insert", "distribution", "template_insertion" or "template_mc",
        ``id_`` the region's or fix's id; with ``value``, set it first. LIGGGHTS' restart does
        not bring them all back (see plugins/liggghts/restart_state.cpp)."""
        s = ctypes.c_int(0 if value is None else value)
        if self.helper.collheat_random_state(self.ptr, what.encode(), id_.encode(), ctypes.byref(s),
                                             int(value is not None)):
            return None
        return s.value

    def insert_progress(self, id_: str, value: list | None = None) -> list | None:
        """The progress of ``fix <id_> insert/*`` (None: there is none): [the step of its next
        insertion (0: none more), particles inserted so far, their mass in kg, the step of its first
        insertion, that of its most recent (-1: none)]; with ``value``, set it first. LIGGGHTS'
        restart loses a finished insertion's 'none more' (see plugins/liggghts/restart_state.cpp)."""
        state = (ctypes.c_double * 5)(*(value or [0.0] * 5))
        if self.helper.collheat_insert_progress(self.ptr, id_.encode(), state, int(value is not None)):
            return None
        return list(state)

    # -- contacts ---------------------------------------------------------------------
    def add_pair_contacts(self, compute_id: str = "pairs") -> None:
        """Define the pair-contact compute read by :meth:`pair_contacts` (once per pair
        style, before the first run)."""
        self.command(f"compute {compute_id} all pair/gran/local {_PAIR_KEYWORDS}")

    def add_wall_contacts(self, compute_id: str = "walls") -> None:
        """Define the mesh-wall contact compute read by :meth:`wall_contacts` (after the
        ``fix wall/gran ... mesh`` it reports on). LIGGGHTS reports mesh walls only: for
        primitive planes use :meth:`plane_contacts`."""
        self.command(f"compute {compute_id} all wall/gran/local {_PAIR_KEYWORDS}")

    def local_array(self, compute_id: str) -> np.ndarray:
        """A local compute's rows on the current step, as a (rows, cols) copy."""
        rows, cols, data = _int(), _int(), ctypes.POINTER(ctypes.c_double)()
        if self.helper.collheat_compute_local(self.ptr, compute_id.encode(), ctypes.byref(rows),
                                              ctypes.byref(cols), ctypes.byref(data)) != 0:
            raise LiggghtsError(f"no local compute '{compute_id}'")
        shape = (rows.value, max(cols.value, 1))
        if rows.value == 0:
            return np.zeros(shape)
        return np.ctypeslib.as_array(data, shape=shape).copy()

    def pair_contacts(self, compute_id: str = "pairs") -> ComputeRows:
        """Particle-particle contacts now (see :class:`ComputeRows`)."""
        a = self._contact_array(compute_id)
        return ComputeRows(i=a[:, 6].astype(np.int64), j=a[:, 7].astype(np.int64),
                        delta=a[:, 10], vi=a[:, 0:3], vj=a[:, 3:6], area=a[:, 9])

    def wall_contacts(self, compute_id: str = "walls") -> ComputeRows:
        """Particle-mesh-wall contacts now: ``i`` the atom id, ``j`` the wall's index in
        its fix (from 0), ``vi`` the particle's and ``vj`` the wall's velocity (m/s)."""
        a = self._contact_array(compute_id)
        # LIGGGHTS' order for walls: wall velocity, particle velocity; wall, atom, triangle.
        return ComputeRows(i=a[:, 7].astype(np.int64), j=a[:, 6].astype(np.int64),
                        delta=a[:, 10], vi=a[:, 3:6], vj=a[:, 0:3], area=a[:, 9])

    def plane_contacts(self, axis: int, position: float, wall: int = 0) -> ComputeRows:
        """Contacts with a fixed primitive plane wall ``axis`` = ``position`` (axis 0, 1, 2
        for x, y, z; m), from geometry: overlap radius - distance (m), area of the cut
        circle pi (2 r delta - delta^2) (m^2), as LIGGGHTS reports for mesh walls; ``j`` is
        ``wall``, ``vj`` zero."""
        r, v = self.atom("radius"), self.atom("v")
        delta, _ = primitive_overlap(self.atom("x"), r, ("xyz"[axis] + "plane", (position,)))
        on = delta > 0
        return ComputeRows(i=self.atom("id")[on].astype(np.int64), j=np.full(on.sum(), wall),
                        delta=delta[on], vi=v[on].copy(), vj=np.zeros((on.sum(), 3)),
                        area=np.pi * (2 * r[on] * delta[on] - delta[on] ** 2))

    def _contact_array(self, compute_id: str) -> np.ndarray:
        a = self.local_array(compute_id)
        if a.shape[1] != 11:
            raise LiggghtsError(f"contact compute '{compute_id}' has {a.shape[1]} columns, not "
                                "11: define it with add_pair_contacts()/add_wall_contacts()")
        return a

    def close(self) -> None:
        if self.ptr:
            self.helper.collheat_watch_exit(None, b"")
            if not self.failed:          # one left mid-command is not taken apart: its memory goes with the process
                self.lib.lammps_close(self.ptr)
            self.ptr = _vp()
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None

    def __enter__(self) -> "Liggghts":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
