"""The fluid of a CFD-DEM run: the project's OpenFOAM solver ``collheatFoam`` kept running
for a whole simulation and driven from Python.

:class:`FluidSolver` starts the solver (serial, or ``mpirun -np N`` after ``decomposePar``),
exchanges per-particle and per-cell data with each rank through two named pipes (see
``plugins/openfoam/collheatFoam/hostLink.H``), and turns the fluid seen by each particle into
a force with a drag law chosen by name (:mod:`plugins.drag`). Every exchange is checked: a
solver that diverges or stops raises :class:`FluidError` carrying the tail of its log.

Nothing waits on the solver for ever: every open, read and write of the pipes has a deadline
(``timeout``, default ``$COLLHEAT_FLUID_TIMEOUT`` or 120 s), and a solver that never connects,
dies, or stops answering (e.g. stopped by SIGSTOP) ends with a FluidError saying which and
after how long. The solver runs in a session of its own, so a terminal's Ctrl-C reaches only
the host, which then ends the solver (:meth:`FluidSolver.stop`).

Units: SI throughout. The solver's pressure is kinematic (m^2/s^2); this module gives Pa.
"""
from __future__ import annotations

import fcntl
import functools
import math
import os
import re
import select
import shutil
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
from foamlib import FoamFile

from plugins import drag as drag_laws
from plugins.drag import fluid_force, fluid_fraction
from pyhost.engines.fluid_case import is_time_name, start_time

# The solver built by tools/setup_engines.sh; COLLHEAT_SOLVER names another build (a variant under test).
SOLVER = Path(os.environ.get("COLLHEAT_SOLVER", Path(__file__).resolve().parents[2] / ".setup" / "bin" / "collheatFoam"))
LOCATE, ADVANCE, FIELDS, WRITE, STOP, TEMPERATURE = 1, 2, 3, 4, 5, 6
TIMEOUT = float(os.environ.get("COLLHEAT_FLUID_TIMEOUT", 120.0))   # s, see the module doc


def _divided_points() -> np.ndarray:
    """Rows (weight, x, y, z) of points in the unit sphere (radius 1) for the ``divided``
    void fraction: three shells of a third of the volume each, the inner one by its centre,
    the middle by 6 points on the axes and the outer by 8 on the diagonals, each at the
    radius that halves its shell's volume."""
    axes = np.vstack([np.eye(3), -np.eye(3)])
    diagonals = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)]) / np.sqrt(3)
    rows = [[1 / 3, 0, 0, 0]]
    rows += [[1 / 18, *(0.5 ** (1 / 3) * a)] for a in axes]
    rows += [[1 / 24, *((5 / 6) ** (1 / 3) * a)] for a in diagonals]
    return np.array(rows)


DIVIDED = _divided_points()


class FluidError(RuntimeError):
    """The fluid solver failed; the message ends with the tail of its log."""


class OutsideMesh(ValueError):
    """Points outside the fluid mesh (``locate``): ``index``, their indices in the request."""

    def __init__(self, message, index):
        super().__init__(message)
        self.index = index


class FluidCaseError(ValueError):
    """The solver refused the case's input before its first step (its exit code 2, e.g. a
    boundary condition it cannot honour): bad input, with the tail of its log."""


def _exchange(method):
    """Marks a request/answer exchange: while one is under way the pipes hold half a
    message, so :meth:`FluidSolver.stop` must end the solver instead of asking it to stop.
    An advance still under way (``advance(wait=False)``) is waited for first."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        self.wait()
        self._busy = True
        result = method(self, *args, **kwargs)
        self._busy = False
        return result
    return wrapper


def foam_env() -> dict:
    """Environment for Debian's OpenFOAM v1912 binaries and OpenMPI as root."""
    env = dict(os.environ)
    if "OMPI_COMM_WORLD_SIZE" in env:   # a host started by mpirun: the solver (or its own mpirun)
        env = {k: v for k, v in env.items() if not k.startswith(("OMPI_", "PMIX_", "PMI_", "OPAL_"))}  # is a job of its own
    env.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
    env.setdefault("USER", "root")
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def log_tail(log: Path, lines: int = 25) -> str:
    try:
        text = log.read_text(errors="replace").rstrip().splitlines()
    except FileNotFoundError:
        return f"(no log at {log})"
    return "\n".join(text[-lines:])


def run_utility(case: Path, *command: str) -> None:
    """Run an OpenFOAM utility in ``case`` (log in ``case/log.<utility>``); FluidError if
    it fails."""
    log = Path(case) / f"log.{command[0]}"
    with open(log, "w") as out:
        rc = subprocess.run([*command, "-case", str(case)], stdout=out, stderr=subprocess.STDOUT,
                            env=foam_env()).returncode
    if rc != 0:
        raise FluidError(f"{command[0]} failed in {case} (exit code {rc}); end of {log}:\n"
                         f"{log_tail(log)}")


SEVERE_NON_ORTHOGONALITY = 70.0
"""deg: OpenFOAM's own threshold of a severely non-orthogonal face (checkMesh)."""


def non_orthogonal_cause(case: Path) -> str:
    """Words naming the mesh's non-orthogonality as a likely cause of a diverged run, when
    checkMesh finds faces beyond SEVERE_NON_ORTHOGONALITY, with the case's non-orthogonal
    correctors; '' otherwise (or if checkMesh cannot tell)."""
    try:
        r = subprocess.run(["checkMesh", "-case", str(case), "-constant", "-noTopology"], capture_output=True,
                           text=True, errors="replace", env=foam_env(), timeout=300)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    found = re.search(r"Mesh non-orthogonality Max: ([\d.eE+-]+)", r.stdout)
    if not found or float(found.group(1)) <= SEVERE_NON_ORTHOGONALITY:
        return ""
    faces = re.search(r"Number of severely non-orthogonal \(> [\d.]+ degrees\) faces: (\d+)", r.stdout)
    correctors = re.search(r"nNonOrthogonalCorrectors\s+(\d+)", (case / "system" / "fvSolution").read_text(
        errors="replace")) if (case / "system" / "fvSolution").is_file() else None
    return (f"; the mesh is strongly non-orthogonal, up to {float(found.group(1)):.1f} deg (checkMesh"
            + (f": {faces.group(1)} faces above {SEVERE_NON_ORTHOGONALITY:g} deg" if faces else "")
            + f"), with {correctors.group(1) if correctors else 0} non-orthogonal correctors (fvSolution's PIMPLE "
            "nNonOrthogonalCorrectors): a likely cause; give it 2 or more and laplacianSchemes 'Gauss linear "
            "limited corrected 0.5', or mesh the case with less skewed cells")


class FluidSolver:
    """``collheatFoam`` running on an OpenFOAM case, driven step by step.

    ``case``: a case directory with a mesh (or a blockMeshDict), 0/U, 0/p and
    constant/transportProperties giving ``nu`` (m^2/s) and ``rho`` (kg/m^3).
    ``nprocs``: MPI ranks (>1 decomposes the case first; the case needs
    system/decomposeParDict). ``drag``: name of a law in :mod:`plugins.drag`.
    ``alpha_min``: floor of the fluid volume fraction handed to the solver (-).
    ``void_fraction``: how a particle's volume (and drag) goes to the cells: ``"centre"``, all
    to the cell of its centre; ``"divided"``, spread over the cells its volume overlaps, by
    the 15 points of ``DIVIDED`` (as CFDEM's divided model; for cells not much larger than
    the particles, where the centre rule makes the fraction jump from cell to cell).
    ``timeout``: seconds the host waits for one answer of the solver.
    ``energy``: also solve the gas temperature (``collheatFoam -energy``: the case needs 0/T
    and ``Cp``, ``kappa`` in transportProperties); :meth:`advance` then takes the heat of
    each cell (W), :meth:`temperature` gives the cells' T.

    ``restart``: a folder of :meth:`save` to continue from (its time becomes the start time).
    ``ddt_alpha``: d(alpha)/dt in the continuity equation (False: left out, as CFDEM's solvers
    by default, ``collheatFoam -noDdtAlpha``).
    ``deltaT``: the case's own time step [s] (controlDict): :meth:`substeps` splits a coupling
    interval into steps no longer than it.

    Use ``with FluidSolver(case) as fluid: ...`` or :meth:`start` / :meth:`stop`.
    """

    def __init__(self, case: str | os.PathLike, *, nprocs: int = 1, drag: str = "gidaspow",
                 alpha_min: float = 0.3, timeout: float = TIMEOUT, energy: bool = False,
                 void_fraction: str = "centre", restart: str | os.PathLike | None = None, ddt_alpha: bool = True):
        self.case = Path(case).resolve()
        if not (self.case / "system" / "controlDict").is_file():
            raise FluidError(f"{self.case} is not an OpenFOAM case (no system/controlDict)")
        if nprocs < 1:
            raise ValueError(f"nprocs must be >= 1, got {nprocs}")
        self.drag_law = drag_laws.LAWS.lookup(drag)
        self.drag = drag
        self.nprocs, self.alpha_min, self.timeout = nprocs, alpha_min, timeout
        if void_fraction not in ("centre", "divided"):
            raise ValueError(f"void_fraction must be centre or divided, got {void_fraction!r}")
        self.void_fraction = void_fraction
        self.ddt_alpha = ddt_alpha
        self.deltaT = _value(FoamFile(self.case / "system" / "controlDict")["deltaT"])   # s, the case's step
        props = FoamFile(self.case / "constant" / "transportProperties")
        self.nu = _value(props["nu"])
        self.rho = _value(props["rho"])
        self.energy = energy
        if energy:
            missing = [k for k in ("Cp", "kappa") if k not in props]
            if missing or not (self.case / "0" / "T").is_file():
                raise FluidError(f"{self.case}: the gas energy needs 0/T and Cp, kappa in "
                                 f"constant/transportProperties; missing: {', '.join(missing) or '0/T'}")
            self.cp, self.kappa = _value(props["Cp"]), _value(props["kappa"])
        self._boundary_heat = 0.0    # J into the gas through the case's boundaries so far
        self.log = self.case / "log.collheatFoam"
        self.proc: subprocess.Popen | None = None
        self._fds: list[tuple[int, int]] = []
        self._busy = False
        self._pending = False        # an advance sent whose answers are not read yet
        self._time = start_time(self.case)[0]    # s: the controlDict's start (a restart's: its saved time)
        self.restart = None if restart is None else Path(restart)

    # -- life cycle -------------------------------------------------------------------
    def start(self) -> "FluidSolver":
        """Mesh (blockMesh if needed), decompose if parallel, launch, and connect."""
        if not SOLVER.is_file():
            raise FluidError(f"{SOLVER} is missing: run tools/setup.sh --engines")
        if not (self.case / "constant" / "polyMesh" / "owner").is_file():
            run_utility(self.case, "blockMesh")
        command = ([str(SOLVER), "-case", str(self.case)] + (["-energy"] if self.energy else [])
                   + ([] if self.ddt_alpha else ["-noDdtAlpha"]))
        if self.nprocs > 1:
            for old in self.case.glob("processor*"):
                shutil.rmtree(old)
            run_utility(self.case, "decomposePar", "-force")
            command = ["mpirun", "--oversubscribe", "-np", str(self.nprocs), *command, "-parallel"]
        if self.restart is not None:
            command.append("-restart")
            self._start_from(self.restart)
        link = self.case / ".link"
        shutil.rmtree(link, ignore_errors=True)
        link.mkdir()
        for rank in range(self.nprocs):
            os.mkfifo(link / f"rank{rank}.in")
            os.mkfifo(link / f"rank{rank}.out")
        with open(self.log, "w") as out:
            try:
                self.proc = subprocess.Popen([*command, "-link", str(link)], stdout=out,
                                             stderr=subprocess.STDOUT, env=foam_env(),
                                             start_new_session=True)
            except OSError as exc:
                shutil.rmtree(link, ignore_errors=True)
                raise FluidError(f"cannot start the fluid solver {command[0]}: {exc.strerror}") from None
        self._busy = True
        try:
            centres, volumes = self._connect(link)
        except BaseException:       # no solver, pipe or descriptor outlives a failed start
            self.stop()
            raise
        self.rank_cells = np.array([len(v) for v in volumes])
        self.offsets = np.concatenate([[0], np.cumsum(self.rank_cells)])
        self.cell_centres = np.concatenate(centres)
        self.cell_volumes = np.concatenate(volumes)
        n = len(self.cell_volumes)
        self._alpha, self._ksl, self._us = np.ones(n), np.zeros(n), np.zeros((n, 3))
        self.cell, self.slip = np.zeros(0, np.int64), np.zeros(0)
        self._busy = False
        if self.restart is not None:
            try:
                self._resume(self.restart)
            except BaseException:
                self.stop()
                raise
        return self

    def _connect(self, link: Path) -> tuple[list, list]:
        """Open each rank's pipes; its cell centres and volumes."""
        centres, volumes = [], []
        for rank in range(self.nprocs):
            fd_in = self._open_writer(link / f"rank{rank}.in")
            fd_out = os.open(link / f"rank{rank}.out", os.O_RDONLY | os.O_NONBLOCK)
            self._fds.append((fd_in, fd_out))
            for fd in (fd_in, fd_out):
                _widen(fd)
            nc = int(self._read(rank, np.int32, 1)[0])
            centres.append(self._read(rank, np.float64, 3 * nc).reshape(nc, 3))
            volumes.append(self._read(rank, np.float64, nc))
        return centres, volumes

    def stop(self) -> None:
        """End the solver (it writes nothing more) and remove the pipes. A solver in the
        middle of an exchange (the host was interrupted) or not answering is killed, with
        every process of its session (mpirun's ranks)."""
        if self.proc is None:
            return
        try:
            if self.proc.poll() is None and not self._busy and _state(self.proc.pid) != "T":
                self.wait()
                for rank in range(self.nprocs):
                    self._send(rank, np.int32(STOP).tobytes())
                for rank in range(self.nprocs):
                    self._read(rank, np.float64, 1)
                self.proc.wait(timeout=self.timeout)
                self._reconstruct()
        finally:
            for fds in self._fds:
                for fd in fds:
                    os.close(fd)
            self._fds = []
            self._kill()
            self.proc = None
            shutil.rmtree(self.case / ".link", ignore_errors=True)

    def _time_folders(self) -> list[Path]:
        """Where the solver writes a time: the case, or each rank's processor folder."""
        return [self.case] if self.nprocs == 1 else [self.case / f"processor{r}" for r in range(self.nprocs)]

    def save(self, folder: Path) -> float:
        """The fluid's whole state at its current time into ``folder`` (created): every field
        written with a double's 17 digits (:meth:`write`), that time's folder moved there from
        the case (from each processor folder when decomposed), with the host's last exchange
        (fraction, exchange coefficient and particle velocity sent, the particles' cells and
        slip speeds, the boundary heat so far) in ``host.npz``. Returns the time [s]."""
        before = [{p.name for p in d.iterdir()} for d in self._time_folders()]
        t = self.write()
        folder.mkdir(parents=True)
        for d, old in zip(self._time_folders(), before):
            new = [p for p in d.iterdir() if p.name not in old and p.is_dir() and is_time_name(p.name)]
            if len(new) == 1:
                shutil.move(str(new[0]), folder / d.relative_to(self.case) / new[0].name)
                continue
            # none new: the case's own writeControl wrote this time at this step (its times count from
            # the start, a restart's too), and the write above wrote it again with 17 digits: copied,
            # the case keeps its own write
            same = [] if new else [p for p in d.iterdir() if p.is_dir() and is_time_name(p.name)
                                   and math.isclose(float(p.name), t, rel_tol=1e-6, abs_tol=1e-12)]
            if len(same) != 1:
                raise FluidError(f"the solver's write at t = {t:g} s left {len(new)} new time folders in {d}"
                                 + ("" if new else f" and {len(same)} of that time"))
            shutil.copytree(same[0], folder / d.relative_to(self.case) / same[0].name)
        try:
            np.savez(folder / "host.npz", alpha=self._alpha, ksl=self._ksl, us=self._us, cell=self.cell,
                     slip=self.slip, boundary_heat=self.boundary_heat)
        except OSError as exc:          # a full disk names the file (pyhost.output.naming: an import cycle here)
            exc.filename = exc.filename or str(folder / "host.npz")
            raise
        return t

    def _start_from(self, folder: Path) -> None:
        """Before the launch: ``folder``'s time (:meth:`save`) into the case as its start time."""
        names = {p.name for d in self._time_folders() for p in (folder / d.relative_to(self.case)).glob("*")
                 if p.is_dir() and is_time_name(p.name)}
        if len(names) != 1:
            raise FluidError(f"{folder}: not a saved fluid state (time folders: {sorted(names) or 'none'})")
        name = names.pop()
        for d in self._time_folders():
            shutil.rmtree(d / name, ignore_errors=True)
            shutil.copytree(folder / d.relative_to(self.case) / name, d / name)
        control = FoamFile(self.case / "system" / "controlDict")
        control["startFrom"] = "startTime"
        control["startTime"] = float(name)
        self._time = float(name)

    def _resume(self, folder: Path) -> None:
        """At the end of a :meth:`start` from ``folder``: the host's side of the last exchange."""
        with np.load(folder / "host.npz") as saved:
            self._alpha, self._ksl, self._us = saved["alpha"], saved["ksl"], saved["us"]
            self.cell, self.slip = saved["cell"], saved["slip"]
            self._boundary_heat = float(saved["boundary_heat"])
        if len(self._alpha) != len(self.cell_volumes):
            raise FluidError(f"{folder}: the saved fluid has {len(self._alpha)} cells, the case "
                             f"{len(self.cell_volumes)}")

    def _reconstruct(self) -> None:
        """A decomposed run's written times (``write()``) as whole fields in the case, as a
        serial run leaves them (reconstructPar, for the times not reconstructed yet)."""
        if self.nprocs > 1 and any(p.name != "0" and p.name[0].isdigit()
                                   for p in (self.case / "processor0").iterdir()):
            run_utility(self.case, "reconstructPar", "-newTimes")

    def _kill(self) -> None:
        """SIGKILL the solver's session (also stopped processes and mpirun's ranks) and reap it."""
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.proc.wait()

    def __enter__(self) -> "FluidSolver":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def gravity(self) -> np.ndarray:
        """The case's gravity [m/s^2] (constant/g), zero if it has none."""
        g = self.case / "constant" / "g"
        return np.asarray(FoamFile(g)["value"], float) if g.is_file() else np.zeros(3)

    # -- coupling ---------------------------------------------------------------------
    def particle_forces(self, x: np.ndarray, v: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Fluid force on each particle (N, shape (n, 3)) from the current fluid: drag
        ``K (u - v)`` plus pressure gradient ``-V_p grad p``; also sets the per-cell fluid
        fraction, exchange coefficient Ksl and particle velocity Us used by the next
        :meth:`advance`, and keeps each particle's cell (``self.cell``), slip speed
        |u - v| (``self.slip``, m/s) and drag coefficient K (``self.exchange``, kg/s). ``x``
        positions (m), ``v`` velocities (m/s), ``d`` diameters (m)."""
        x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1, 3)
        v = np.asarray(v, dtype=np.float64).reshape(-1, 3)
        d = np.broadcast_to(np.asarray(d, dtype=np.float64), (len(x),))
        cell, u, gradp = self.locate(x)
        vp = np.pi * d**3 / 6.0
        ncells = len(self.cell_volumes)
        if self.void_fraction == "divided" and len(x):
            points = (x[:, None, :] + 0.5 * d[:, None, None] * DIVIDED[None, :, 1:]).reshape(-1, 3)
            cells = self.locate(points, strict=False, point_set=1)[0].reshape(len(x), -1)
            cells = np.where(cells >= 0, cells, cell[:, None])    # a point beyond a curved wall: the centre's
            share = np.broadcast_to(DIVIDED[:, 0], cells.shape)
        else:
            cells, share = cell[:, None], np.ones((len(x), 1))
        spread = lambda w: np.bincount(cells.ravel(), weights=(w[:, None] * share).ravel(), minlength=ncells)
        alpha = fluid_fraction(spread(vp), self.cell_volumes, self.alpha_min)
        slip = u - v
        self.cell, self.slip = cell, np.linalg.norm(slip, axis=1)
        k = self.drag_law(np.sum(alpha[cells] * share, axis=1), self.slip, d, self.rho, self.nu)
        self.exchange = k
        ksum = spread(k)
        kv = np.stack([spread(k * v[:, i]) for i in range(3)], axis=1)
        self.take_particles(alpha, ksum, kv)
        return fluid_force(k, slip, vp, self.rho, gradp)

    def take_particles(self, alpha: np.ndarray, ksum: np.ndarray, kv: np.ndarray) -> None:
        """The particle fields of the next :meth:`advance` from each cell's sums over its
        particles (``particle_forces``'s, or the MPI ranks' summed: ``pyhost.engines.fluid_ranks``):
        ``alpha`` the fluid fraction (:func:`fluid_fraction`), ``ksum`` the drag coefficients
        K [kg/s] summed, ``kv`` K v summed [kg m/s^2] (n, 3). The cells' Ksl = ksum / V
        [kg/(m^3 s)] and the particles' drag-weighted velocity Us = kv / ksum [m/s] (0 where no
        particle)."""
        self._alpha = alpha
        self._ksl = ksum / self.cell_volumes
        self._us = np.divide(kv, ksum[:, None], out=np.zeros(kv.shape), where=ksum[:, None] > 0)   # float
        # also with no particle yet (a script that inserts later): bincount of nothing is int

    @_exchange
    def cell_fluid(self) -> tuple[np.ndarray, np.ndarray]:
        """The fluid velocity [m/s] and kinematic pressure gradient [m/s^2] of every cell, in
        the order of ``cell_centres``, as :meth:`locate` gives them to a particle in that cell
        under the ``cell`` interpolation (OpenFOAM's interpolationCell returns the cell's value
        wherever in it the point is): a LOCATE of each rank's own cell centres, to that rank
        only, O(cells). FluidError if a centre is not found in its own cell (not a mesh of
        convex cells)."""
        for rank in range(self.nprocs):
            a, b = self.offsets[rank], self.offsets[rank + 1]
            self._send(rank, np.array([LOCATE, b - a, 0], np.int32).tobytes() + self.cell_centres[a:b].tobytes())
        u, gradp = [], []
        for rank, nc in enumerate(self.rank_cells):
            c = self._read(rank, np.int32, nc)
            u.append(self._read(rank, np.float64, 3 * nc).reshape(nc, 3))
            gradp.append(self._read(rank, np.float64, 3 * nc).reshape(nc, 3))
            if not np.array_equal(c, np.arange(nc)):
                wrong = int(np.flatnonzero(c != np.arange(nc))[0])
                raise FluidError(f"the fluid solver's rank {rank} finds the centre of its cell {wrong} in cell "
                                 f"{int(c[wrong])}: the mesh has cells that do not hold their centre")
        return np.concatenate(u), np.concatenate(gradp)

    @_exchange
    def locate(self, x: np.ndarray, strict: bool = True,
               point_set: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cell of each position (global index over ranks), fluid velocity (m/s) and kinematic
        pressure gradient (m/s^2) there, interpolated as controlDict's
        ``particleInterpolation`` says (default ``cell``). ValueError if a point is outside
        (OutsideMesh, ``strict``), else cell -1 there. ``point_set``: which set they are (0 the particles'
        centres, 1 the divided rule's points in them): the solver tries each point's cell of
        the last request of its set first."""
        x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1, 3)
        n = len(x)
        request = np.array([LOCATE, n, point_set], np.int32).tobytes() + x.tobytes()
        for rank in range(self.nprocs):
            self._send(rank, request)
        cell = np.full(n, -1, dtype=np.int64)
        u, gradp = np.zeros((n, 3)), np.zeros((n, 3))
        for rank in range(self.nprocs):
            c = self._read(rank, np.int32, n)
            ur = self._read(rank, np.float64, 3 * n).reshape(n, 3)
            gr = self._read(rank, np.float64, 3 * n).reshape(n, 3)
            mine = (c >= 0) & (cell < 0)
            cell[mine] = c[mine] + self.offsets[rank]
            u[mine], gradp[mine] = ur[mine], gr[mine]
        if strict and np.any(cell < 0):
            lost = np.flatnonzero(cell < 0)
            raise OutsideMesh(f"{len(lost)} point(s) outside the fluid mesh, e.g. index {lost[0]} "
                              f"at {x[lost[0]].tolist()} m", lost)
        return cell, u, gradp

    @_exchange
    def advance(self, duration: float, steps: int = 1, heat: np.ndarray | None = None,
                wait: bool = True) -> float | None:
        """Advance the fluid by ``duration`` (s) in ``steps`` equal time steps with the
        particle fields of the last :meth:`particle_forces`; returns the fluid time (s).
        With the gas energy, ``heat`` (W per cell, default none) goes into each cell's gas
        over the interval, and what entered through the boundaries adds to
        ``boundary_heat`` (J). ``wait=False``: return (None) once the request is sent; the
        solver steps while the host goes on (the DEM's next chunk), and the next use of the
        solver, :meth:`wait` or :meth:`stop` takes its answer first (a failed step raises
        there)."""
        if duration <= 0 or steps < 1:
            raise ValueError(f"need duration > 0 and steps >= 1, got {duration}, {steps}")
        if heat is not None and not self.energy:
            raise ValueError("heat given to a fluid without gas energy (energy=False)")
        heat = np.zeros(len(self._alpha)) if heat is None else np.asarray(heat, np.float64)
        head = (np.int32(ADVANCE).tobytes() + np.float64(duration / steps).tobytes()
                + np.int32(steps).tobytes())
        for rank in range(self.nprocs):
            a, b = self.offsets[rank], self.offsets[rank + 1]
            self._send(rank, head + self._alpha[a:b].tobytes() + self._ksl[a:b].tobytes()
                       + np.ascontiguousarray(self._us[a:b]).tobytes()
                       + (heat[a:b].tobytes() if self.energy else b""))
        self._pending = True
        if wait:
            self.wait()
            return self._time
        return None

    def wait(self) -> None:
        """The answer of an advance sent with ``wait=False``, if one is under way: its time
        and the heat through the boundaries. Raises FluidError if the solver failed in it."""
        if not self._pending:
            return
        self._pending = False
        self._busy = True
        for rank in range(self.nprocs):
            self._time = float(self._read(rank, np.float64, 1)[0])
            if self.energy:
                self._boundary_heat += float(self._read(rank, np.float64, 1)[0])
        self._busy = False

    @property
    def time(self) -> float:
        """The fluid's time [s], after the advance under way if one is."""
        self.wait()
        return self._time

    @property
    def boundary_heat(self) -> float:
        """Heat into the gas through the case's boundaries so far [J], with the advance under
        way if one is."""
        self.wait()
        return self._boundary_heat

    def substeps(self, interval: float) -> int:
        """Fluid steps in a coupling interval [s]: the interval over the case's deltaT, rounded
        where it is a whole number within 1e-6 (every CFDEM tutorial's deltaT is its coupling
        time: one step; CFDEM runs shorter ones as sub-steps), else up, so that no step is
        longer than deltaT."""
        n = interval / self.deltaT
        return max(1, round(n) if abs(n - round(n)) <= 1e-6 * n else math.ceil(n))

    def couple(self, x, v, d, duration: float, steps: int = 1) -> np.ndarray:
        """One coupling step: the force on each particle (N) from the current fluid, then the
        fluid advanced by ``duration`` (s) with these particles' fluid fraction and drag."""
        forces = self.particle_forces(x, v, d)
        self.advance(duration, steps)
        return forces

    @_exchange
    def temperature(self) -> np.ndarray:
        """Gas temperature (K) of every cell, in the order of ``cell_centres``."""
        if not self.energy:
            raise ValueError("no gas temperature: the fluid was started without energy")
        for rank in range(self.nprocs):
            self._send(rank, np.int32(TEMPERATURE).tobytes())
        return np.concatenate([self._read(rank, np.float64, nc) for rank, nc in enumerate(self.rank_cells)])

    def heat_capacity(self) -> np.ndarray:
        """Heat capacity of each cell's gas, rho Cp alpha V (J/K), with the fraction last sent."""
        return self.rho * self.cp * self._alpha * self.cell_volumes


    @_exchange
    def fields(self) -> tuple[np.ndarray, np.ndarray]:
        """Pressure (Pa) and velocity (m/s) of every cell, in the order of ``cell_centres``."""
        for rank in range(self.nprocs):
            self._send(rank, np.int32(FIELDS).tobytes())
        p, u = [], []
        for rank in range(self.nprocs):
            nc = self.rank_cells[rank]
            p.append(self._read(rank, np.float64, nc) * self.rho)
            u.append(self._read(rank, np.float64, 3 * nc).reshape(nc, 3))
        return np.concatenate(p), np.concatenate(u)

    @property
    def alpha(self) -> np.ndarray:
        """Fluid volume fraction of every cell as last sent (-)."""
        return self._alpha

    @_exchange
    def write(self) -> float:
        """Write all fields at the current fluid time; returns that time (s)."""
        for rank in range(self.nprocs):
            self._send(rank, np.int32(WRITE).tobytes())
        for rank in range(self.nprocs):
            self._time = float(self._read(rank, np.float64, 1)[0])
        return self._time

    # -- pipes ------------------------------------------------------------------------
    def _failed(self, what: str, waited: float | None = None) -> FluidError | FluidCaseError:
        """The error for a solver that ended while ``what``, or (``waited`` seconds given)
        one still alive that did not answer in time, which is then ended."""
        if waited is not None and self.proc.poll() is None:
            state = {"T": "stopped (SIGSTOP or a debugger)", "Z": "exiting"}.get(
                _state(self.proc.pid), "running but silent")
            self._kill()
            return FluidError(f"the fluid solver did not answer within {waited:.1f} s while {what}: "
                              f"it was {state}, and the host ended it (time-out: timeout argument or "
                              f"COLLHEAT_FLUID_TIMEOUT); end of {self.log}:\n{log_tail(self.log)}")
        try:                    # the pipe closed: give the solver a moment to end by itself
            self.proc.wait(timeout=2.0)
        except subprocess.TimeoutExpired:
            self._kill()
        rc = self.proc.returncode
        if rc == 2:
            return FluidCaseError(f"{self.case.name}: the fluid solver refused the case; end of "
                                  f"{self.log}:\n{log_tail(self.log)}")
        how = f"exit code {rc}"
        if rc < 0:
            how = f"killed by {signal.Signals(-rc).name}"
            if -rc == signal.SIGFPE:
                how += ": a floating point exception, the run diverged"
        tail = log_tail(self.log)
        if rc == -signal.SIGFPE or "the fluid diverged" in tail:    # (collheatFoam's maxSpeed guard says so)
            how += non_orthogonal_cause(self.case)
        return FluidError(f"the fluid solver stopped while {what} ({how}); end of {self.log}:\n{tail}")

    def _open_writer(self, path: Path) -> int:
        """The host's end of a request pipe, non-blocking: writes wait in :meth:`_send`."""
        start = time.monotonic()
        while True:
            try:
                return os.open(path, os.O_WRONLY | os.O_NONBLOCK)
            except OSError:  # ENXIO: the solver has not opened its end yet
                if self.proc.poll() is not None:
                    raise self._failed("starting") from None
                if time.monotonic() - start > self.timeout:
                    raise self._failed("starting: it never opened the link (start time-out)",
                                       time.monotonic() - start) from None
                time.sleep(0.005)

    def _send(self, rank: int, data: bytes) -> None:
        view = memoryview(data)
        start = time.monotonic()
        try:
            fd = self._fds[rank][0]
            while view:
                try:
                    view = view[os.write(fd, view):]
                except BlockingIOError:       # the pipe is full: the solver is not reading
                    if self.proc.poll() is not None:
                        raise self._failed("receiving a request") from None
                    if time.monotonic() - start > self.timeout:
                        raise self._failed("receiving a request", time.monotonic() - start) from None
                    select.select([], [fd], [], 0.5)
        except (BrokenPipeError, IndexError):
            raise self._failed("receiving a request") from None

    def _read(self, rank: int, dtype, count: int) -> np.ndarray:
        fd = self._fds[rank][1]
        need = np.dtype(dtype).itemsize * count
        chunks, got = [], 0
        start = time.monotonic()
        while got < need:
            ready, _, _ = select.select([fd], [], [], 0.5)
            if not ready:
                if self.proc.poll() is not None:
                    raise self._failed("computing")
                if time.monotonic() - start > self.timeout:
                    raise self._failed("computing", time.monotonic() - start)
                continue
            chunk = os.read(fd, need - got)
            if not chunk:
                raise self._failed("computing")
            chunks.append(chunk)
            got += len(chunk)
        return np.frombuffer(b"".join(chunks), dtype=dtype)


def _widen(fd: int) -> None:
    """The pipe's buffer raised from Linux's 64 KiB to the system's limit (1 MiB unless
    /proc/sys/fs/pipe-max-size says otherwise): a request or answer of some 10^4 particles then
    fits whole, so the host writes each rank's request without waiting for that rank to read it,
    and the ranks start together (each waits for the others inside its fluid step). Where the
    limit cannot be had, the pipe stays as it is (slower, not wrong)."""
    try:
        size = int(Path("/proc/sys/fs/pipe-max-size").read_text())
        fcntl.fcntl(fd, fcntl.F_SETPIPE_SZ, min(size, 1 << 20))
    except (OSError, ValueError, AttributeError):
        pass


def _state(pid: int) -> str:
    """One-letter state of a process (R, S, T stopped, Z zombie...), '' if unknown."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return ""


def _value(entry) -> float:
    """A number from an OpenFOAM entry that may carry a name and dimensions."""
    return float(getattr(entry, "value", entry))
