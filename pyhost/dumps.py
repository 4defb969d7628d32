"""Streaming reader of LIGGGHTS (and LAMMPS) dump files, frame by frame, in bounded memory.

Reads ``dump custom`` and ``dump atom`` text (``ITEM: ATOMS`` with any column order),
``dump local`` (``ITEM: ENTRIES``) of ``compute pair/gran/local`` and ``wall/gran/local``,
and ``dump custom/vtk`` legacy VTK files (through pyvista). Text files may be gzipped (told by
their first bytes, not their name); one file may hold many steps, or each step its own file.
Files are read in the order of their first timestep, not of their names (``dump.1000`` sorts
before ``dump.500`` by name).

``DumpReader(paths, ...)`` yields ``Frame``s: one numpy array of the frame's rows (parsed by
numpy's C loader, never row by row in Python), the box and its periodicity from
``ITEM: BOX BOUNDS``, and the column names. ``frame["radius"]``, ``frame["f_Temp"]`` (which also
finds ``f_Temp[0]``), ``frame.positions()`` (x y z, unwrapped or scaled), ``frame.vector("v")``.

A local dump's header names its columns only ``c_ID[k]``. What column k of compute ID holds
comes from the compute's keywords (``Compute``, e.g. from ``read_script`` of the LIGGGHTS input
that wrote the dumps): LIGGGHTS writes the keywords' groups in its code order, whatever order
they were typed in (``LOCAL_GROUPS``; measured in ../shared/ENGINES.md and read from
``compute_pair_gran_local.h`` of LIGGGHTS 3.8). A column that cannot be placed for sure is an
error, never a guess.

Any problem is a ``DumpError`` naming the file, the frame's timestep, the line and the problem.
With ``skip_bad_frames`` the reader records a warning (``reader.warnings``), skips the frame and
goes on from the next ``ITEM: TIMESTEP``.
"""
from __future__ import annotations

import glob
import gzip
import re
import zlib
from dataclasses import dataclass, field, replace
from itertools import islice
from pathlib import Path

import numpy as np

from pyhost.engines.liggghts.computes import Compute


class DumpError(ValueError):
    """A problem in a dump file: file, timestep of the frame (None before the first), line, problem."""

    def __init__(self, file, step, line, problem: str):
        self.file, self.step, self.line, self.problem = str(file), step, line, problem
        where = f"{file}: line {line}" if line else f"{file}"
        super().__init__(f"{where}: timestep {'?' if step is None else step}: {problem}")




@dataclass(frozen=True)
class Clock:
    """The time of a script's steps across its runs, as LIGGGHTS steps them: each run's
    (first step, last step, time step [s], time at its first step [s]) in script order, a
    ``reset_timestep`` numbering the next run's steps anew and a ``timestep`` changing its dt.
    A frame's ``count`` is its step counted through the runs (never going back), from which
    ``time`` gives the time [s]. ``steady(dt)``: one run from step 0 at dt, without end."""

    runs: tuple

    @staticmethod
    def steady(dt: float) -> "Clock":
        return Clock(((0, float("inf"), dt, 0.0),))

    @property
    def offsets(self) -> np.ndarray:
        """The count at each run's first step."""
        return np.cumsum([0] + [last - first for first, last, _, _ in self.runs[:-1]])

    def time(self, count) -> np.ndarray | float:
        """The time [s] of a step's count (scalar or array); beyond the last run, at its dt."""
        offsets, count = self.offsets, np.asarray(count)
        r = np.maximum(np.searchsorted(offsets, count, side="right") - 1, 0)
        t0, dt = np.array([run[3] for run in self.runs]), np.array([run[2] for run in self.runs])
        t = t0[r] + (count - offsets[r]) * dt[r]
        return float(t) if t.ndim == 0 else t

    def counter(self):
        """``place(step)`` for the frames of one dump stream in their order: the step's count, the
        frame's run being the same as the last frame's or a later one (after a reset_timestep,
        one whose steps go back to it); None for a step no run from there holds."""
        offsets = self.offsets
        at = [0, None]                              # the run of the last frame, its step

        def place(step: int):
            r, last = at
            while r < len(self.runs):
                first, end = self.runs[r][:2]
                if first <= step <= end and (last is None or step >= last):
                    at[:] = r, step
                    return int(offsets[r] + step - first)
                r, last = r + 1, None
            return None

        return place


@dataclass(frozen=True, eq=False)
class Frame:
    """One dump frame: rows ``data`` (n, columns) of float64, named by ``columns``."""

    file: str
    line: int                       # line of its ITEM: TIMESTEP (0 for VTK)
    step: int                       # its step counted through the script's runs (``Clock``; the file's without one)
    time: float | None              # [s] (``Clock.time``), None without a clock or dt
    box: np.ndarray | None          # (3, 2) lo hi [m]; None for VTK (no box in the file)
    periodic: tuple                 # (bool, bool, bool)
    columns: tuple
    data: np.ndarray
    kind: str = "atoms"             # atoms, pair, wall, local
    groups: dict = field(default_factory=dict)     # name -> column indices of a group (local)
    timestep: int | None = None     # the step as the file numbers it (None: ``step``)

    def __len__(self) -> int:
        return len(self.data)

    def index(self, name: str):
        """Column index (int) or indices (list) of name; None if absent. ``f_X`` finds ``f_X[0]``."""
        if name in self.groups:
            return self.groups[name]
        for candidate in (name, f"{name}[0]", name[:-3] if name.endswith("[0]") else None):
            if candidate in self.columns:
                return self.columns.index(candidate)
        return None

    def __contains__(self, name: str) -> bool:
        return self.index(name) is not None

    def __getitem__(self, name: str) -> np.ndarray:
        k = self.index(name)
        if k is None and not len(self.data):       # a frame without rows (a VTK file of 0 points has no names)
            return np.empty((0, 3) if name in self.groups else 0)
        if k is None:
            raise KeyError(f"{self.file}: timestep {self.step}: no column {name!r}; columns: {' '.join(self.columns)}")
        return self.data[:, k]

    def vector(self, name: str) -> np.ndarray:
        """(n, 3) of group name (local), or of columns name+x, name+y, name+z (vx vy vz)."""
        if name in self.groups:
            return self.data[:, self.groups[name]]
        return np.stack([self[name + c] for c in "xyz"], axis=1)

    def positions(self) -> np.ndarray:
        """(n, 3) centres [m] from x y z, xu yu zu, or the scaled xs ys zs / xsu ysu zsu."""
        if not len(self.data):
            return np.empty((0, 3))
        for suffix in ("", "u"):
            if all(c + suffix in self.columns for c in "xyz"):
                return np.stack([self[c + suffix] for c in "xyz"], axis=1)
            if all(c + "s" + suffix in self.columns for c in "xyz"):
                s = np.stack([self[c + "s" + suffix] for c in "xyz"], axis=1)
                return self.box[:, 0] + s * (self.box[:, 1] - self.box[:, 0])
        raise KeyError(f"{self.file}: timestep {self.step}: no positions (x y z, xu.., xs..)")


POSITION_SETS = ("x y z", "xu yu zu", "xs ys zs", "xsu ysu zsu")
REQUIRED = {"id": ("id",), "type": ("type",), "position": POSITION_SETS, "velocity": ("vx vy vz",),
            "radius": ("radius",)}
"""Columns post-processing needs, each satisfied by any of the column sets listed."""


def _missing(columns, require) -> list:
    have = set(columns)
    return [name for name in require
            if not any(set(option.split()) <= have for option in REQUIRED[name])]


def open_text(path: Path):
    """Text stream of a plain or gzipped file (gzip told by its magic bytes)."""
    with open(path, "rb") as f:
        magic = f.read(2)
    if magic == b"\x1f\x8b":
        return gzip.open(path, "rt", encoding="ascii", errors="strict")
    return open(path, encoding="ascii", errors="strict")


STREAM_ERRORS = (EOFError, gzip.BadGzipFile, zlib.error, UnicodeDecodeError, OSError)


def _is_number(words: list[str]) -> bool:
    try:
        float(words[0])
        return True
    except (IndexError, ValueError):
        return False


def local_compute(path) -> str:
    """The id of the compute whose rows a ``dump local`` file holds, from its first header
    (``ITEM: ENTRIES c_ID[1] ...``); DumpError if it is unreadable or not such a dump."""
    try:
        with open_text(path) as f:
            head = [f.readline() for _ in range(9)]
    except STREAM_ERRORS as exc:
        raise DumpError(path, None, 1, f"unreadable ({type(exc).__name__}: {exc})") from None
    if not head[8].startswith("ITEM: ENTRIES c_"):
        raise DumpError(path, None, 9, f"not a dump local of a compute: {head[8].strip()[:60]!r}")
    return head[8].split()[2].split("[")[0][2:]


class _Lines:
    """Lines of an open file with their 1-based numbers and a pushback for resynchronising."""

    def __init__(self, stream):
        self.stream, self.number, self.back = stream, 0, []

    def next(self) -> str | None:
        self.number += 1
        if self.back:
            return self.back.pop()
        line = self.stream.readline()
        if not line:
            self.number -= 1
            return None
        return line

    def take(self, n: int) -> list:
        lines = []
        while self.back and len(lines) < n:
            lines.append(self.back.pop())
        lines += islice(self.stream, n - len(lines))
        self.number += len(lines)
        return lines

    def push(self, lines: list) -> None:
        self.back.extend(reversed(lines))
        self.number -= len(lines)


VTK_SUFFIXES = (".vtk", ".vtp", ".vtu", ".pvtu")      # (.pvtu: a frame written in pieces, one per MPI rank)


def expand(paths) -> list:
    """Paths with shell wildcards expanded (for quoted ``'post/dump.*'``). A wildcard skips
    the ``*boundingBox*.vtk`` files LIGGGHTS' custom/vtk writes beside each frame (they hold
    the box only: ``heatGran_*.vtk`` matches them too)."""
    out = []
    for p in map(str, paths):
        hits = sorted(glob.glob(p)) if glob.has_magic(p) else [p]
        if glob.has_magic(p):
            hits = [h for h in hits if not (Path(h).suffix == ".vtk" and "boundingBox" in Path(h).name)]
        if not hits:
            raise DumpError(p, None, 0, "no file matches")
        for h in hits:
            if not Path(h).is_file():
                raise DumpError(h, None, 0, "no such file")
        out += hits
    return [Path(h) for h in out]


def _vtk_step(path: Path) -> int:
    digits = re.findall(r"\d+", path.name[: -len(path.suffix)])
    if not digits:
        raise DumpError(path, None, 0, "a VTK dump's timestep is read from its name, and this one has no number")
    return int(digits[-1])


def processor_parts(files) -> tuple[list, dict]:
    """A ``dump local`` whose file name has ``%`` (an MPI run's one file per processor):
    LIGGGHTS 3.8 writes its header, with processor 0's row count, into processor 0's file
    only; the other processors' files hold bare rows (or nothing). Each such file goes
    with the file of the same name but for a 0 in place of its processor number, whose
    frame it completes: (the files with a header, {that file: its processors' files})."""
    heads, bare = [], []
    for p in files:
        if p.suffix.lower() in VTK_SUFFIXES:
            heads.append(p)
            continue
        try:
            with open_text(p) as f:
                first = f.readline()
        except STREAM_ERRORS:
            heads.append(p)             # (its error is said when it is read)
            continue
        (bare if not first.startswith("ITEM:") and (not first.strip() or _is_number(first.split()))
         else heads).append(p)
    parts, header_of = {}, {}
    for h in heads:
        tokens = re.split(r"(\d+)", h.name)
        for k in range(1, len(tokens), 2):
            if tokens[k] == "0":
                header_of.setdefault((h.parent, tuple(tokens[:k]), tuple(tokens[k + 1:])), h)
    for p in bare:
        tokens = re.split(r"(\d+)", p.name)
        h = next((header_of[key] for k in range(1, len(tokens), 2) if tokens[k] != "0"
                  and (key := (p.parent, tuple(tokens[:k]), tuple(tokens[k + 1:]))) in header_of), None)
        if h is None:
            heads.append(p)             # (refused when read: no header, no processor 0's file given)
        else:
            parts.setdefault(h, []).append(p)
    return heads, parts


class DumpReader:
    """Frames of dump files in timestep order: ``for frame in DumpReader(paths): ...``.

    ``computes``: id -> Compute for local dumps (``read_script(...).computes``); ``clock`` (the
    script's ``Clock``, through its time step changes and resets) or else ``dt`` [s] gives each
    frame its time and its step counted through the runs; ``require``: names of ``REQUIRED`` an atom frame must hold;
    ``skip_bad_frames``: warn (``self.warnings``) and go on instead of raising.
    """

    def __init__(self, paths, computes: dict | None = None, dt: float | None = None, require=(),
                 skip_bad_frames: bool = False, clock: Clock | None = None):
        self.computes, self.require = dict(computes or {}), tuple(require)
        self.clock = clock if clock is not None else Clock.steady(dt) if dt is not None else None
        self.skip, self.warnings = skip_bad_frames, []
        files = expand(paths)
        boxes = [p for p in files if p.suffix.lower() in VTK_SUFFIXES and "_boundingBox_" in p.name]
        if boxes:
            self.warnings.append(f"{len(boxes)} box outlines of dump custom/vtk (*_boundingBox_*) not read "
                                 "as particle frames")
        files, self.parts = processor_parts([p for p in files if p not in boxes])
        self.files = self._order(files)

    def _with_parts(self, path: Path, frames):
        """The frames of ``path``, each completed by its processors' files' rows (``parts``)."""
        parts = self.parts.get(path)
        if not parts:
            yield from frames
            return
        frames = list(frames)
        if len(frames) != 1:
            self._fail(DumpError(parts[0], None, 1, f"another processor's part of {path.name} (a dump local with "
                                 f"'%' in its file name), whose {len(frames)} frames it cannot be split into: "
                                 "LIGGGHTS writes the header into processor 0's file only; write one file per step "
                                 "and processor ('dump ... local N post/pair.*.%')"))
            yield from frames
            return
        frame, rows = frames[0], [frames[0].data]
        for part in parts:
            try:
                with open_text(part) as f:
                    body = [ln for ln in f.read().splitlines() if ln.strip()]
                error = lambda problem, row, part=part: DumpError(part, frame.step, row + 1, problem)
                data = _parse(body, len(frame.columns), error)
                if frame.groups:
                    self._check_local(data, frame.columns, frame.groups, error)
            except _HeaderInRows as header:
                self._fail(DumpError(part, frame.step, header.row + 1, "a header among the processor's rows"))
                continue
            except DumpError as exc:
                self._fail(exc)
                continue
            except STREAM_ERRORS as exc:
                self._fail(DumpError(part, frame.step, 0, f"unreadable ({type(exc).__name__}: {exc})"))
                continue
            rows.append(data)
        yield replace(frame, data=np.concatenate(rows))

    def _fail(self, error: DumpError) -> None:
        if not self.skip:
            raise error
        self.warnings.append(f"skipped: {error}")

    def _first_step(self, path: Path):
        if path.suffix.lower() in VTK_SUFFIXES:
            return _vtk_step(path)
        try:
            with open_text(path) as f:
                head = [f.readline() for _ in range(2)]
        except STREAM_ERRORS as exc:
            raise DumpError(path, None, 1, f"unreadable ({type(exc).__name__}: {exc})") from None
        if not head[0]:
            raise DumpError(path, None, 0, "empty file")
        if head[0].strip() != "ITEM: TIMESTEP":
            bare = _is_number(head[0].split())
            raise DumpError(path, None, 1, f"not a LIGGGHTS dump: first line {head[0].strip()[:60]!r}, "
                                           "expected 'ITEM: TIMESTEP'"
                            + ("; rows without a header are another processor's part of a dump local with '%' in "
                               "its file name: give processor 0's file (the same name with 0 for the processor) "
                               "with it" if bare else ""))
        try:
            return int(head[1])
        except ValueError:
            raise DumpError(path, None, 2, f"timestep {head[1].strip()[:40]!r} is not an integer") from None

    def _order(self, paths) -> list:
        keyed = []
        for p in paths:
            try:
                keyed.append((self._first_step(p), str(p), p))
            except DumpError as exc:
                self._fail(exc)
        return [p for _, _, p in sorted(keyed)]

    def __iter__(self):
        last = None                                     # (count, file, step) of the previous frame
        place = self.clock.counter() if self.clock is not None else None
        for path in self.files:
            frames = self._vtk(path) if path.suffix.lower() in VTK_SUFFIXES else self._with_parts(path, self._text(path))
            for frame in frames:
                count = frame.step if place is None else place(frame.step)
                if count is None or last is not None and count < last[0]:
                    resets = self.clock is not None and len(self.clock.runs) > 1
                    self._fail(DumpError(frame.file, frame.step, frame.line,
                                         f"timestep goes backwards (previous frame: timestep {last[2]} in {last[1]})"
                                         + ("" if resets else ": a script's reset_timestep is followed with --script")
                                         if last is not None else "timestep before the script's first run"))
                    continue
                if last is not None and count == last[0]:
                    self.warnings.append(f"{frame.file}: line {frame.line}: timestep {frame.step} again: "
                                         "frame skipped")
                    continue
                last = (count, frame.file, frame.step)
                yield replace(frame, step=count, timestep=frame.step,
                              time=None if self.clock is None else self.clock.time(count))

    def _text(self, path: Path):
        try:
            stream = open_text(path)
        except OSError as exc:
            self._fail(DumpError(path, None, 0, f"cannot open: {exc.strerror}"))
            return
        with stream:
            lines = _Lines(stream)
            while True:
                start = lines.number + 1
                try:
                    frame = self._frame(lines, path)
                except DumpError as exc:
                    self._fail(exc)
                    if not self._resync(lines, path):
                        return
                    continue
                except STREAM_ERRORS as exc:
                    self._fail(DumpError(path, None, lines.number + 1, f"truncated or corrupt stream after line "
                                         f"{lines.number} ({type(exc).__name__}: {exc})"))
                    return
                if frame is None:
                    if lines.number + 1 == start == 1:
                        self._fail(DumpError(path, None, 0, "empty file"))
                    return
                yield frame

    def _resync(self, lines: _Lines, path: Path) -> bool:
        """After a bad frame: on to the next ITEM: TIMESTEP; False at the end of the file."""
        try:
            while (line := lines.next()) is not None:
                if line.startswith("ITEM: TIMESTEP"):
                    lines.push([line])
                    return True
        except STREAM_ERRORS as exc:
            self.warnings.append(f"{path}: line {lines.number + 1}: truncated or corrupt stream "
                                 f"({type(exc).__name__}: {exc}): rest of the file skipped")
        return False

    def _frame(self, lines: _Lines, path: Path) -> Frame | None:
        line = lines.next()
        if line is None:
            return None
        start, step = lines.number, None

        def error(problem, number=None):
            return DumpError(path, step, lines.number if number is None else number, problem)

        def item(expected):
            text = lines.next()
            if text is None:
                raise error(f"file ends where '{expected}' was expected (truncated)", lines.number + 1)
            if not text.startswith(expected):
                raise error(f"expected '{expected}', got {text.strip()[:60]!r}")
            return text[len(expected):].split()

        lines.push([line])
        item("ITEM: TIMESTEP")
        step = self._integer(lines, error, "timestep")
        head = lines.next()
        if head is None or not head.startswith("ITEM: NUMBER OF "):
            raise error("expected 'ITEM: NUMBER OF ATOMS' or 'ITEM: NUMBER OF ENTRIES', got "
                        f"{'end of file' if head is None else repr(head.strip()[:60])}")
        local = head.strip() == "ITEM: NUMBER OF ENTRIES"
        n = self._integer(lines, error, "row count")
        if n < 0:
            raise error(f"negative row count {n}")
        flags = item("ITEM: BOX BOUNDS")
        bounds = flags[-3:]
        if flags[:3] == ["xy", "xz", "yz"]:
            raise error("triclinic box: not supported")
        if len(bounds) != 3 or any(len(b) != 2 or set(b) - set("pfsm") for b in bounds):
            raise error(f"box boundary flags {' '.join(flags)!r} not understood (expected e.g. 'pp pp ff')")
        box = np.empty((3, 2))
        for k in range(3):
            text = lines.next()
            try:
                box[k] = [float(w) for w in (text or "").split()[:2]]
            except ValueError:
                raise error(f"box bounds {text.strip()[:60]!r}: two numbers expected") from None
        columns = item("ITEM: ENTRIES" if local else "ITEM: ATOMS")
        if not columns:
            raise error("header names no column")
        kind, groups = ("atoms", {}) if not local else self._local_layout(columns, error)
        if kind == "atoms" and self.require and (missing := _missing(columns, self.require)):
            raise error(f"required column missing: {', '.join(missing)} (columns: {' '.join(columns)})")
        body = lines.take(n)
        first = lines.number - len(body) + 1
        try:
            data = _parse(body, len(columns), lambda problem, row: error(problem, first + row))
        except _HeaderInRows as short:
            lines.push(body[short.row:])
            raise error(f"frame has {short.row} rows, its header says {n} (truncated)", first + short.row) from None
        if len(body) < n:
            raise error(f"file ends after {len(body)} rows of {n} (truncated)", first + len(body))
        if kind == "atoms":
            self._check_atoms(data, columns, lambda problem, row: error(problem, first + row))
        elif groups:
            self._check_local(data, columns, groups, lambda problem, row: error(problem, first + row))
        periodic = tuple(b == "pp" for b in bounds)
        return Frame(str(path), start, step, None, box, periodic, tuple(columns), data, kind, groups)

    @staticmethod
    def _integer(lines, error, what) -> int:
        text = lines.next()
        try:
            return int(text)
        except (TypeError, ValueError):
            raise error(f"{what} {'missing' if text is None else repr(text.strip()[:40])}: an integer expected") from None

    def _local_layout(self, columns, error):
        """Kind (pair, wall, local) and name -> column indices from the computes' keywords."""
        meaning, styles = [], set()
        for k, name in enumerate(columns):
            m = re.fullmatch(r"c_([^\[\]]+)\[(\d+)\]", name)
            if not m:
                meaning.append((name, None))
                continue
            cid, col = m.group(1), int(m.group(2))
            if cid not in self.computes:
                raise error(f"column {name}: what compute {cid}'s columns hold needs its keywords "
                            f"(--script with its 'compute {cid} ...' line, or --compute '{cid} STYLE keywords')")
            compute = self.computes[cid]
            styles.add(compute.style)
            cols = compute.columns()
            known = [c for c in cols if c[0] is not None]
            if col < 1 or (col > len(known) and len(known) == len(cols)):
                raise error(f"column {name}: compute {cid} ({compute.style} {' '.join(compute.keywords)}) "
                            f"writes {len(cols)} columns, not {col}: keywords do not match the dump")
            if col > len(known):
                raise error(f"column {name}: follows compute {cid}'s 'history', whose width depends on the "
                            "pair style: its meaning is ambiguous")
            meaning.append(known[col - 1])
        if len(styles) > 1:
            raise error(f"one dump mixes {' and '.join(sorted(styles))} columns")
        self._check_cut(columns, error)
        groups = {}
        for k, (name, comp) in enumerate(meaning):
            groups.setdefault(name, {})[comp] = k
        layout = {name: (parts[None] if None in parts else [parts[c] for c in sorted(parts)])
                  for name, parts in groups.items() if None in parts or len(parts) == 3}
        kind = "local" if not styles else ("wall" if Compute("", styles.pop()).wall else "pair")
        return kind, layout

    def _check_cut(self, columns, error) -> None:
        """A dump that lists a compute's columns 1..N where N ends inside one of its keyword's
        groups (5 of the 6 'vel' columns): written by a compute of other keywords than the
        ones given (a user dumps whole groups)."""
        listed = {}
        for name in columns:
            if m := re.fullmatch(r"c_([^\[\]]+)\[(\d+)\]", name):
                listed.setdefault(m.group(1), []).append(int(m.group(2)))
        for cid, cols in listed.items():
            known = [c for c in self.computes[cid].columns() if c[0] is not None]
            n = len(cols)
            if sorted(cols) == list(range(1, n + 1)) and n < len(known) and known[n - 1][0] == known[n][0]:
                compute = self.computes[cid]
                raise error(f"the dump has columns 1-{n} of compute {cid}, which ends inside its "
                            f"'{known[n][0]}' columns by the keywords {compute.style} {' '.join(compute.keywords)} "
                            f"({len(known)} columns): the keywords (--script, --compute) are not those of the "
                            "compute that wrote this dump")

    # columns that hold whole numbers, and their least value, whatever the compute's keywords
    _WHOLE = {"id_i": 1, "id_j": 1, "periodic": 0, "mesh": 0, "triangle": 0}

    def _check_local(self, data, columns, groups, error) -> None:
        """Contact rows read by the computes' keywords (from --script or --compute) must hold
        ids where the keywords place them: keywords that are not those the dump was written
        with would otherwise reinterpret its columns without a word."""
        for name, least in self._WHOLE.items():
            k = groups.get(name)
            if not isinstance(k, int) or not len(data):
                continue
            bad = np.flatnonzero((data[:, k] != np.round(data[:, k])) | (data[:, k] < least))
            if len(bad):
                raise error(f"column {columns[k]} should hold {name} by the compute's keywords, but holds "
                            f"{data[bad[0], k]:g}: the keywords (--script, --compute) are not those of the "
                            "compute that wrote this dump", bad[0])

    def _check_atoms(self, data, columns, error) -> None:
        if "radius" in columns:
            bad = np.flatnonzero(data[:, columns.index("radius")] < 0)
            if len(bad):
                raise error(f"negative radius {data[bad[0], columns.index('radius')]:g}", bad[0])
        if "id" in columns:
            ids = data[:, columns.index("id")]
            _, first = np.unique(ids, return_index=True)
            if len(first) < len(ids):
                row = int(np.setdiff1d(np.arange(len(ids)), first).min())
                raise error(f"duplicate id {ids[row]:.0f} in one frame", row)

    def _vtk(self, path: Path):
        import pyvista

        step = _vtk_step(path)
        try:
            with pyvista.vtk_verbosity("off"):      # an empty frame (0 points) is no problem here
                mesh = pyvista.read(str(path))
        except Exception as exc:          # VTK's reader raises assorted types for broken files
            self._fail(DumpError(path, step, 0, f"not a readable VTK file ({type(exc).__name__}: {exc})"))
            return
        columns, arrays = ["x", "y", "z"], [np.asarray(mesh.points, float)]
        for name in mesh.point_data.keys():
            a = np.asarray(mesh.point_data[name], float)
            if a.ndim == 2 and a.shape[1] == 3:
                columns += [name + c for c in "xyz"] if name != "v" else ["vx", "vy", "vz"]
            else:
                columns.append(name)
            arrays.append(a.reshape(len(a), -1))
        data = np.concatenate(arrays, axis=1) if mesh.n_points else np.empty((0, len(columns)))
        error = lambda problem, row: DumpError(path, step, 0, f"point {row}: {problem}")
        try:
            if mesh.n_points and (missing := _missing(columns, self.require)):
                raise DumpError(path, step, 0, f"required column missing: {', '.join(missing)} "
                                               f"(point data: {' '.join(mesh.point_data.keys())})")
            bad = np.flatnonzero(~np.isfinite(data).all(axis=1))
            if len(bad):
                raise error("NaN or infinite value", bad[0])
            self._check_atoms(data, columns, error)
        except DumpError as exc:
            self._fail(exc)
            return
        yield Frame(str(path), 0, step, None, None, (False, False, False), tuple(columns), data)


class _HeaderInRows(Exception):
    def __init__(self, row):
        self.row = row


def _parse(body: list, ncols: int, error) -> np.ndarray:
    """Rows of numbers (len(body), ncols) by numpy's C parser; on failure the first bad row
    is found and named (wrong column count, non-numeric token, NaN or infinity), or
    _HeaderInRows raised where the next frame's header starts among the rows (a short frame)."""
    if not body:
        return np.empty((0, ncols))
    try:
        data = np.loadtxt(body, dtype=float, comments=None, ndmin=2)
        if data.shape[1] == ncols and np.isfinite(data).all():
            return data
    except ValueError:
        pass
    for k, text in enumerate(body):
        if text.startswith("ITEM:"):
            raise _HeaderInRows(k)
        words = text.split()
        if len(words) != ncols:
            raise error(f"{len(words)} values in a row, the header names {ncols} columns", k)
        for w in words:
            try:
                value = float(w)
            except ValueError:
                raise error(f"non-numeric value {w[:30]!r}", k) from None
            if not np.isfinite(value):
                raise error(f"non-finite value {w!r}", k)
    raise AssertionError("loadtxt refused rows that parse one by one")
