"""The DEM for the coupling loop: Debian's LIGGGHTS 3.8 in this process, through its C API.

Implements what ``pyhost.loop.Coupling`` needs: ``run(steps)``, ``state()`` (zero-copy views
of positions and velocities in particle order) and ``add_velocity``. Runs are chunked
with ``run N pre no post no`` (bit-identical to one long run, see shared/ENGINES.md).
LIGGGHTS ends its process on any error, so the input is generated from a validated scene
(``pyhost.dem_input``) and checked by a dry run of the same script in a separate
``liggghts`` process before this one loads it: an error then arrives as a Python exception
carrying LIGGGHTS' own message.
"""
from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

from pyhost.dem_input import Particles, input_lines, write_data

LIB = "libliggghts.so.3"


class DemError(RuntimeError):
    """LIGGGHTS refused the input; the message is LIGGGHTS' own."""


def check_input(script: Path, workdir: Path) -> None:
    """Run the script for zero steps in a separate liggghts process; raise DemError with the
    engine's message if it fails."""
    exe = shutil.which("liggghts")
    if exe is None:
        raise DemError("liggghts is not installed: run tools/setup.sh --engines")
    probe = workdir / "in.check"
    probe.write_text(script.read_text() + "run 0\n")
    r = subprocess.run(["stdbuf", "-o0", exe, "-in", probe.name, "-log", "log.check", "-echo", "none"],
                       cwd=workdir, capture_output=True, text=True)
    if r.returncode != 0:
        lines = [l for l in r.stdout.splitlines() if "ERROR" in l] or r.stdout.splitlines()[-5:]
        raise DemError(f"LIGGGHTS rejected {script}: " + " | ".join(lines))


class Liggghts:
    """LIGGGHTS in this process for a scene's particles (ids 1..N in ``particles`` order)."""

    def __init__(self, scene, particles: Particles, workdir: Path):
        self.workdir = Path(workdir).resolve()
        self.workdir.mkdir(parents=True, exist_ok=True)
        data = write_data(self.workdir / "particles.data", scene, particles)
        script = self.workdir / "in.dem"
        script.write_text("\n".join(["atom_modify sort 0 0"] + input_lines(scene, data.name)) + "\n")
        check_input(script, self.workdir)
        self.lib = ctypes.CDLL(LIB, mode=ctypes.RTLD_GLOBAL)
        self._declare()
        self.n = len(particles.radius)
        self.ptr = ctypes.c_void_p()
        args = [b"liggghts", b"-screen", b"/dev/null", b"-log", str(self.workdir / "log.dem").encode()]
        argv = (ctypes.c_char_p * len(args))(*args)
        cwd = Path.cwd()
        try:
            os.chdir(self.workdir)
            self.lib.lammps_open_no_mpi(len(args), argv, ctypes.byref(self.ptr))
            self.lib.lammps_file(self.ptr, str(script).encode())
            self.command("run 0")
        finally:
            os.chdir(cwd)
        self._views()

    def _declare(self) -> None:
        L, vp, cp = self.lib, ctypes.c_void_p, ctypes.c_char_p
        L.lammps_open_no_mpi.argtypes = [ctypes.c_int, ctypes.POINTER(cp), ctypes.POINTER(vp)]
        L.lammps_open_no_mpi.restype = None
        L.lammps_close.argtypes = [vp]
        L.lammps_close.restype = None
        L.lammps_file.argtypes = [vp, cp]
        L.lammps_file.restype = None
        L.lammps_command.argtypes = [vp, cp]
        L.lammps_command.restype = cp
        L.lammps_extract_atom.argtypes = [vp, cp]
        L.lammps_extract_atom.restype = vp
        L.lammps_extract_global.argtypes = [vp, cp]
        L.lammps_extract_global.restype = vp

    def command(self, text: str) -> None:
        self.lib.lammps_command(self.ptr, text.encode())

    def _per_atom(self, name: str, cols: int, ctype=ctypes.c_double):
        nlocal = ctypes.cast(self.lib.lammps_extract_global(self.ptr, b"nlocal"), ctypes.POINTER(ctypes.c_int))[0]
        if nlocal != self.n:
            raise DemError(f"LIGGGHTS holds {nlocal} particles, the scene {self.n}: particles left the domain")
        raw = self.lib.lammps_extract_atom(self.ptr, name.encode())
        if cols:                                   # double **: rows of one contiguous block
            first = ctypes.cast(raw, ctypes.POINTER(ctypes.POINTER(ctype)))[0]
            return np.ctypeslib.as_array(first, shape=(nlocal, cols))
        return np.ctypeslib.as_array(ctypes.cast(raw, ctypes.POINTER(ctype)), shape=(nlocal,))

    def _views(self) -> None:
        ids = self._per_atom("id", 0, ctypes.c_int)
        self.order = np.argsort(ids)               # local index of particle k (id k + 1)
        self.identity = bool(np.all(self.order == np.arange(self.n)))
        self.x, self.v = self._per_atom("x", 3), self._per_atom("v", 3)

    def run(self, steps: int) -> None:
        self.command(f"run {int(steps)} pre no post no")
        self._views()

    def state(self):
        if self.identity:
            return self.x, self.v
        return self.x[self.order], self.v[self.order]

    def add_velocity(self, index, dv) -> None:
        np.add.at(self.v, self.order[np.asarray(index)], dv)

    def close(self) -> None:
        if self.ptr:
            self.lib.lammps_close(self.ptr)
            self.ptr = ctypes.c_void_p()
