"""What a run leaves on disk, written as it goes so that a crash or an interrupt keeps it.

- ``CsvLog``: rows appended and flushed at every write (collisions, history);
- ``ColumnLog``: the same rows as one raw little-endian file per column and a JSON schema
  (the collisions with ``output.collisions = "binary"``); ``read_collisions`` reads either
  form as numpy arrays, ``collisions_to_csv`` writes the CSV form of a binary log;
- ``VtkSeries``: one .vtu per frame (meshio) and a .pvd index rewritten after each frame,
  so ParaView and pyvista (``pyvista.read(...pvd)``) open whatever was written; under MPI
  (``PieceSeries``) each rank writes its own piece of a frame (``write_piece``) and rank 0 the
  frame's .pvtu naming them, which the .pvd lists;
- ``Progress``: one line every few seconds of wall time: simulated time, rate, time left.
"""
from __future__ import annotations

import contextlib
import csv
import hashlib
import importlib
import json
import math
import os
import re
import sys
import time
from pathlib import Path

import numpy as np

from pyhost import signals


@contextlib.contextmanager
def naming(path: Path):
    """An OSError of a write (a full disk) names the file it was writing (a failed write or
    flush names none: the message said 'a file')."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None:
            exc.filename = str(path)
        raise


TAIL = 1 << 16          # bytes before a checkpoint's end of a log whose hash the checkpoint keeps


def tail_digest(path: Path, size: int) -> str:
    """sha256 of the last TAIL bytes of ``path`` before byte ``size``."""
    with open(path, "rb") as f:
        f.seek(max(0, size - TAIL))
        return hashlib.sha256(f.read(min(size, TAIL))).hexdigest()


def check_resume(path: Path, size: int, digest: str | None) -> None:
    """A log a restart appends to must hold what it held at the checkpoint: ValueError (exit 2)
    naming the file if it is missing, shorter (cut after the checkpoint: appending would leave
    a hole, once padded with zeros) or different before that point (the last TAIL bytes)."""
    actual = path.stat().st_size if path.is_file() else None
    if actual is None or actual < size:
        raise ValueError(f"{path}: {'missing' if actual is None else f'{actual} bytes'}, where the checkpoint "
                         f"needs its first {size}: it was cut or removed after the checkpoint; restore it, or "
                         "run anew with --overwrite")
    if digest is not None and tail_digest(path, size) != digest:
        raise ValueError(f"{path}: its bytes before the checkpoint's end ({size}) differ from what the run wrote "
                         "(edited after the checkpoint?); restore it, or run anew with --overwrite")


def check_logs(out: Path, logs: dict) -> None:
    """Every log of a run's output folder against its mark at a checkpoint (``mark()`` of
    CsvLog or ColumnLog, as the checkpoint's state keeps them), and every VTK frame the
    checkpoint's series lists, before anything is cut: ValueError naming the first that is
    missing, shorter or changed. Bare sizes of older checkpoints are checked for length only."""
    out = Path(out)
    for name in ("collisions", "history"):
        mark = logs.get(name)
        if isinstance(mark, dict) and "tails" in mark:             # binary columns
            kinds = {c["name"]: c["kind"] for c in json.loads((out / name / SCHEMA).read_text())["columns"]}
            for c, kind in kinds.items():
                file = ColumnLog._file_name_of(c, kind)
                check_resume(out / name / file, int(mark["rows"]) * _DTYPES[kind].itemsize, mark["tails"].get(file))
        elif mark is not None:
            size, tail = (mark["size"], mark["tail"]) if isinstance(mark, dict) else (int(mark), None)
            check_resume(out / f"{name}.csv", size, tail)
    for name in ("particles", "fluid"):      # the VTK series: the frames its .pvd will list again
        frames = logs.get(name) or []
        missing = [f for _, f in frames if not (out / "vtk" / f).is_file()]
        if missing:
            raise ValueError(f"{out / 'vtk' / missing[0]} is missing ({len(missing)} of the {len(frames)} frames of "
                             f"{name}.pvd written before the checkpoint are): the restart would list frames that "
                             "are not there; put them back, or run the case anew with --overwrite")


class CsvLog:
    """A CSV file with a fixed header; ``write(rows)`` appends and flushes. ``resume_at``: its
    :meth:`mark` at a checkpoint (or the bare size [bytes] of older checkpoints): the file is
    checked (``check_resume``), what came after is cut, and rows follow it.
    Rows are formatted and written by the output thread (``_output_writer``) while the caller
    goes on (one write at a time: the next write, :meth:`size`, :meth:`mark` and :meth:`close`
    wait for it, and raise what it raised): formatting a 27k box's 96,000 collisions took
    0.4 s, which the DEM's next chunk now hides (the engine's call releases the GIL)."""

    def __init__(self, path: Path, columns: tuple, resume_at: int | dict | None = None):
        self.path, self.columns = Path(path), columns
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._pending = None           # the write under way
        if resume_at is not None:
            mark = resume_at if isinstance(resume_at, dict) else dict(size=resume_at, tail=None)
            check_resume(self.path, mark["size"], mark["tail"])
            os.truncate(self.path, mark["size"])
            self._file = open(self.path, "a", newline="")
            self._csv = csv.writer(self._file)
            return
        self._file = open(self.path, "w", newline="")
        self._csv = csv.writer(self._file)
        with naming(self.path):
            self._csv.writerow(columns)
            self._file.flush()

    @property
    def size(self) -> int:
        """Bytes written so far (all flushed)."""
        self._wait()
        return self._file.tell()

    def mark(self) -> dict:
        """Where a restart resumes this log, and the hash of what precedes it."""
        return dict(size=self.size, tail=tail_digest(self.path, self.size))

    def write(self, rows) -> None:
        """Rows (sequences of values), appended and flushed by the output thread; ``rows`` must
        not change afterwards."""
        self._submit(rows)

    def write_columns(self, **arrays) -> None:
        """Rows from equal-length arrays named by the columns (copied: the caller may change
        its arrays)."""
        cols = [np.array(arrays[c]) for c in self.columns]
        if cols and len(cols[0]):
            self._submit(cols, True)

    CHUNK = 2000            # rows per writerows call: the caller's thread gets the GIL between two

    def _write_now(self, rows, columns: bool = False) -> None:
        with naming(self.path):
            if columns:
                for k in range(0, len(rows[0]), self.CHUNK):
                    part = [c[k:k + self.CHUNK] for c in rows]
                    text = _csv_lines(part)
                    if text is None:
                        self._csv.writerows(zip(*(c.tolist() for c in part)))
                    else:
                        self._file.write(text)
            else:
                self._csv.writerows(rows)
            self._file.flush()

    def _submit(self, rows, columns: bool = False) -> None:
        self._wait()
        self._pending = _output_writer().submit(self._write_now, rows, columns)

    def _wait(self) -> None:
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.result()

    def close(self) -> None:
        try:
            self._wait()
        finally:
            with naming(self.path):
                self._file.close()


_NEEDS_QUOTES = frozenset(',"\r\n')


def _csv_lines(columns) -> str | None:
    """Rows of equal-length arrays as csv.writer (its default dialect) writes them, numbers as
    str() gives them: a quarter less of the output thread's time than writerows on a 27k box's
    collisions (0.57 -> 0.43 s CPU for 96,000 rows), which holds the GIL. None where a text
    value would need quotes (csv.writer then writes them)."""
    if len(columns) < 2:                # (csv.writer quotes a row's one empty field)
        return None
    texts = []
    for c in columns:
        kind = c.dtype.kind
        if kind == "f":
            texts.append(list(map(float.__repr__, c.tolist())))
        elif kind in "iu":
            texts.append(list(map(int.__repr__, c.tolist())))
        elif kind != "U":
            return None
        else:
            values = c.tolist()
            if any(_NEEDS_QUOTES.intersection(v) for v in set(values)):
                return None
            texts.append(values)
    return "".join(line + "\r\n" for line in map(",".join, zip(*texts)))


SCHEMA, COLUMN_FORMAT = "schema.json", 1


class ColumnLog:
    """Rows as columns: in ``folder``, one raw little-endian file per column, ``NAME.f8``
    (float64), ``NAME.i8`` (int64) or, for text, ``NAME.u2`` (uint16 codes into the schema's
    ``categories`` of that column), and ``schema.json`` (columns, kinds, categories; rewritten
    atomically when a new text value appears). ``write_columns`` appends and flushes every file.
    ``kinds``: column -> "f8", "i8" or "str". ``resume_at``: the rows at a checkpoint: each
    file is cut to that many rows, and rows follow them. numpy.fromfile / memmap read a column
    (``read_columns``)."""

    def __init__(self, folder: Path, kinds: dict, resume_at: int | None = None):
        self.folder, self.columns = Path(folder), tuple(kinds)
        self.kinds = dict(kinds)
        bad = {c: k for c, k in self.kinds.items() if k not in ("f8", "i8", "str")}
        if bad:
            raise ValueError(f"ColumnLog: unknown column kinds {bad} (f8, i8, str)")
        self.folder.mkdir(parents=True, exist_ok=True)
        self.categories = {c: [] for c, k in self.kinds.items() if k == "str"}
        if resume_at is not None:
            old = json.loads((self.folder / SCHEMA).read_text())
            self.categories.update({c["name"]: list(c.get("categories", [])) for c in old["columns"]
                                    if c["name"] in self.categories})
        mark = resume_at if isinstance(resume_at, dict) else dict(rows=resume_at, tails={})
        self.rows = 0 if resume_at is None else int(mark["rows"])
        self._code = {c: {v: k for k, v in enumerate(cats)} for c, cats in self.categories.items()}
        self._files = {}
        for c in self.columns:
            path = self.folder / self._file_name(c)
            if resume_at is not None:
                size = self.rows * _DTYPES[self.kinds[c]].itemsize
                check_resume(path, size, mark["tails"].get(path.name))
                os.truncate(path, size)
            self._files[c] = open(path, "ab" if resume_at is not None else "wb")
        self._schema()

    @staticmethod
    def _file_name_of(name: str, kind: str) -> str:
        return f"{name}.{'u2' if kind == 'str' else kind}"

    def _file_name(self, c: str) -> str:
        return self._file_name_of(c, self.kinds[c])

    def _schema(self) -> None:
        from pyhost.outdir import write_atomic
        cols = [dict(name=c, kind=self.kinds[c], file=self._file_name(c),
                     **({"categories": self.categories[c]} if c in self.categories else {})) for c in self.columns]
        write_atomic(self.folder / SCHEMA, json.dumps(dict(format=COLUMN_FORMAT, byteorder="little",
                                                            columns=cols), indent=1))

    @property
    def size(self) -> int:
        """Rows written so far (all flushed)."""
        return self.rows

    def mark(self) -> dict:
        """Where a restart resumes this log (``resume_at``), with the hash of each column file's
        bytes before it."""
        tails = {}
        for c in self.columns:
            path = self.folder / self._file_name(c)
            tails[path.name] = tail_digest(path, self.rows * _DTYPES[self.kinds[c]].itemsize)
        return dict(rows=self.rows, tails=tails)

    def write_columns(self, **arrays) -> None:
        """Rows from equal-length arrays named by the columns."""
        n = len(arrays[self.columns[0]]) if self.columns else 0
        if not n:
            return
        new = False
        for c in self.columns:
            a = np.asarray(arrays[c])
            if len(a) != n:
                raise ValueError(f"ColumnLog: column {c} has {len(a)} rows, {self.columns[0]} has {n}")
            if self.kinds[c] == "str":
                values, inverse = np.unique(a.astype(str), return_inverse=True)
                codes = self._code[c]
                for v in values.tolist():
                    if v not in codes:
                        codes[v] = len(self.categories[c])
                        self.categories[c].append(v)
                        new = True
                a = np.array([codes[v] for v in values.tolist()], "<u2")[inverse.ravel()]
            else:
                a = a.astype(_DTYPES[self.kinds[c]], copy=False)
            with naming(self._files[c].name):
                self._files[c].write(a.tobytes())
        if new:
            self._schema()
        for f in self._files.values():
            with naming(f.name):
                f.flush()
        self.rows += n

    def close(self) -> None:
        for f in self._files.values():
            with naming(f.name):
                f.close()


_DTYPES = {"f8": np.dtype("<f8"), "i8": np.dtype("<i8"), "str": np.dtype("<u2")}


def read_columns(folder: Path) -> dict:
    """The columns of a ``ColumnLog`` folder: name -> numpy array (text columns as str
    arrays), in the schema's order; ValueError naming the file if a column is short or the
    schema unreadable."""
    folder = Path(folder)
    try:
        schema = json.loads((folder / SCHEMA).read_text())
        cols = schema["columns"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{folder / SCHEMA}: not a column log schema ({exc})") from None
    out, rows = {}, None
    for k, c in enumerate(cols):
        if not isinstance(c, dict) or not {"name", "kind", "file"} <= set(c):
            raise ValueError(f"{folder / SCHEMA}: columns[{k}]: needs name, kind and file, got {str(c)[:80]}")
        if c["kind"] not in _DTYPES:
            raise ValueError(f"{folder / SCHEMA}: columns[{k}] ({c['name']}): unknown kind {c['kind']!r}; "
                             f"known: {', '.join(_DTYPES)}")
        dtype = _DTYPES[c["kind"]]
        path = folder / c["file"]
        if not path.is_file():
            raise ValueError(f"{path}: missing (column {c['name']} of {folder / SCHEMA})")
        size = path.stat().st_size
        if size % dtype.itemsize:
            raise ValueError(f"{path}: {size} bytes, not a whole number of {dtype.itemsize}-byte values")
        a = np.fromfile(path, dtype)
        rows = len(a) if rows is None else rows
        if len(a) != rows:
            raise ValueError(f"{path}: {len(a)} rows, {cols[0]['file']} has {rows}")
        if c["kind"] == "str":
            cats = np.array(c.get("categories", []) or [""], str)
            if len(a) and a.max() >= len(cats):
                raise ValueError(f"{path}: code {int(a.max())} beyond the schema's {len(cats)} categories")
            a = cats[a]
        out[c["name"]] = a
    return out


COLLISION_KINDS = dict(time="f8", step="i8", i="i8", j="i8", wall="i8", v0="f8", Q="f8", e="f8", t_coll="f8", model="str")
"""The kind of each collisions column; side columns Q_<model> are f8."""


def collision_kinds(columns) -> dict:
    return {c: COLLISION_KINDS.get(c, "f8") for c in columns}


def read_collisions(out: Path) -> dict:
    """The collisions of a run's output folder as column name -> numpy array, from the binary
    form (OUT/collisions/) if there is one, else from OUT/collisions.csv: i, j, wall int64,
    model str, the others float64; both forms give the same values bit for bit.
    FileNotFoundError naming both if the run wrote neither."""
    out = Path(out)
    if (out / "collisions" / SCHEMA).is_file():
        return read_columns(out / "collisions")
    path = out / "collisions.csv"
    if not path.is_file():
        raise FileNotFoundError(f"{out}: no collisions (neither collisions.csv nor collisions/{SCHEMA})")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None:
            raise ValueError(f"{path}: empty (no header)")
        rows = list(reader)
    short = next((k for k, row in enumerate(rows) if len(row) != len(header)), None)
    if short is not None:
        raise ValueError(f"{path}: line {short + 2}: {len(rows[short])} fields, the header has {len(header)}")
    text = np.array(rows, str).reshape(-1, len(header))
    kinds = collision_kinds(header)
    out = {}
    for k, c in enumerate(header):
        try:
            out[c] = text[:, k] if kinds[c] == "str" else text[:, k].astype(_DTYPES[kinds[c]].newbyteorder("="))
        except ValueError:
            bad = next(r for r, v in enumerate(text[:, k]) if not _parses(v, kinds[c]))
            raise ValueError(f"{path}: line {bad + 2}, column {c}: {str(text[bad, k])!r} is not a number") from None
    return out


def _parses(value: str, kind: str) -> bool:
    try:
        (int if kind == "i8" else float)(value)
        return True
    except ValueError:
        return False


def collisions_to_csv(out: Path, target: Path | None = None, chunk: int = 1 << 20) -> Path:
    """OUT/collisions.csv (or ``target``) from the binary form OUT/collisions/, byte for byte
    the file the run would have written with ``output.collisions = "csv"``; returns its path."""
    out = Path(out)
    cols = read_columns(out / "collisions")
    target = Path(target) if target else out / "collisions.csv"
    tmp = target.with_name(target.name + ".tmp")
    log = CsvLog(tmp, tuple(cols))
    n = len(next(iter(cols.values()))) if cols else 0
    try:
        for a in range(0, n, chunk):
            log.write_columns(**{c: v[a:a + chunk] for c, v in cols.items()})
        log.close()
        tmp.replace(target)
    except BaseException:               # a full disk or a stop: no half-written file stays behind
        log.close()
        tmp.unlink(missing_ok=True)
        raise
    return target


_writer = None


def _output_writer():
    """The one thread that writes VTK frames (meshio's XML and zlib, about 1 ms a frame of
    1,000 particles) and CSV rows, in the order they were handed to it, so that the next DEM
    chunk runs meanwhile: the engine's ctypes call and zlib both release the GIL. Conveyor's
    1,401 frames took 1.5 s of the run's 7.3 s."""
    global _writer
    if _writer is None:
        from concurrent.futures import ThreadPoolExecutor
        # A stop (pyhost.signals) raised between the start of the pool's thread and its
        # registration for the interpreter's exit left that thread waiting for work nobody
        # would send, and the process waiting for it at exit, forever, after it had said it
        # stopped cleanly (a SIGINT at the first frame). The thread starts with stops deferred.
        with signals.deferred():
            writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="output-writer")
            writer.submit(int).result()
            _writer = writer
    return _writer


def later(fn, *args):
    """``fn(*args)`` done by the output thread, after what was handed to it before; its future."""
    return _output_writer().submit(fn, *args)


def preload() -> None:
    """meshio imported by the output thread now (0.1-0.25 s: it imports every format it reads
    and its command line's libraries), while the caller goes on to start the engines, whose
    calls release the GIL; the first frame finds it loaded (``_write_frame``)."""
    _output_writer().submit(importlib.import_module, "meshio")


def _write_frame(path: Path, points, cells, point_data) -> None:
    """One frame's file, named if it cannot be written (a full disk), and then removed: the
    index never names a half frame. (In the output thread: the run's own thread never imports
    meshio.)"""
    import meshio

    try:
        with naming(path):
            meshio.write(path, meshio.Mesh(points, cells, point_data=point_data))
    except BaseException:
        path.unlink(missing_ok=True)
        raise


def vertex_mesh(points, point_data: dict) -> tuple:
    """Points [m] with per-point arrays as a mesh of vertices (``_write_frame``'s points, cells
    and point data), copied (the caller's may be the engine's memory, which the next chunk
    changes): a frame of a ``VtkSeries``, or a rank's piece of one."""
    points = np.array(points, float).reshape(-1, 3)
    cells = [("vertex", np.arange(len(points)).reshape(-1, 1))]
    return points, cells, {k: np.array(v) for k, v in point_data.items()}


class VtkSeries:
    """Points with data, one file per frame, and the .pvd index of the frames so far.
    ``frames``: those of a checkpoint to continue from; later frame files are removed.
    The index is rewritten at most every ``INDEX_EVERY`` seconds of wall time while frames
    come (rewriting it after each frame made a long series cost quadratic time: 50,000 frames
    took 900 s), and by :meth:`flush`; a killed process leaves it that much behind.
    A frame is written by a thread of its own while the caller goes on (one frame at a time:
    the next write, the index and :meth:`flush` wait for it, and raise what it raised)."""

    INDEX_EVERY = 2.0       # s of wall time

    def __init__(self, folder: Path, name: str, frames: list | None = None):
        self.folder, self.name = Path(folder), name
        self.folder.mkdir(parents=True, exist_ok=True)
        self.frames: list[tuple[float, str]] = [tuple(f) for f in frames or []]
        self._indexed = -math.inf
        self._pending = None           # the frame being written
        if frames is not None:
            self._remove_later({f for _, f in self.frames})
            self._index()

    def _remove_later(self, kept: set) -> None:
        """The frame files a checkpoint's frames do not name (written after it) removed: .vtu
        frames, and .pvtu frames with their pieces (``PieceSeries``: a checkpoint of a run on
        several ranks may go on on one, and the other way round)."""
        stems = {Path(f).stem for f in kept}
        for old in sorted(self.folder.glob(f"{self.name}_*.vtu")) + sorted(self.folder.glob(f"{self.name}_*.pvtu")):
            piece = re.fullmatch(r"(.*_\d{5})_p\d+", old.stem)       # a rank's piece of a frame
            if old.name not in kept and (piece is None or piece.group(1) not in stems):
                old.unlink()

    def write(self, t: float, points, **point_data) -> Path:
        """Frame at time t [s]: points (n, 3) [m] and per-point arrays, copied (the caller's
        may be the engine's memory, which the next chunk changes)."""
        self._wait()
        file = f"{self.name}_{len(self.frames):05d}.vtu"
        self._pending = _output_writer().submit(_write_frame, self.folder / file, *vertex_mesh(points, point_data))
        self.frames.append((t, file))
        if time.monotonic() - self._indexed >= self.INDEX_EVERY:
            self._index()
        return self.folder / file

    def flush(self) -> None:
        """Every frame so far on disk, and its index (more frames may follow)."""
        self._index()

    def _wait(self) -> None:
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.result()

    def _index(self) -> None:
        self._wait()                   # (the index never names a frame not yet written)
        self._indexed = time.monotonic()
        index = self.folder / f"{self.name}.pvd"
        tmp = index.with_suffix(".pvd.tmp")
        try:
            with naming(index):
                tmp.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
                               + "".join(f'<DataSet timestep="{t!r}" file="{f}"/>\n' for t, f in self.frames)
                               + "</Collection>\n</VTKFile>\n")
                tmp.replace(index)
        except BaseException:           # a full disk or a stop: the last whole index stays, no half one
            tmp.unlink(missing_ok=True)
            raise


def piece_name(name: str, frame: int, rank: int) -> str:
    """The file of one rank's piece of a frame of a ``PieceSeries``."""
    return f"{name}_{frame:05d}_p{rank}.vtu"


_pieces = {}        # (folder, name) -> this rank's piece being written (write_piece)


def write_piece(folder, name: str, frame: int, rank: int, points, **point_data) -> None:
    """This rank's piece of frame number ``frame`` of the ``PieceSeries`` ``name`` in
    ``folder``: its own particles, written by its output thread while it goes on (the
    piece before waits for it first, and raises what it raised). Returns once the piece
    before this one is on disk (``PieceSeries`` names a frame in its index once every rank
    has said so: ``wait_piece``)."""
    wait_piece(folder, name)
    path = Path(folder) / piece_name(name, frame, rank)
    _pieces[str(folder), name] = _output_writer().submit(_write_frame, path, *vertex_mesh(points, point_data))


def wait_piece(folder, name: str) -> None:
    """This rank's last piece of the series on disk (raises what its writing raised)."""
    pending = _pieces.pop((str(folder), name), None)
    if pending is not None:
        pending.result()


class PieceSeries(VtkSeries):
    """A ``VtkSeries`` whose frames are written in pieces, one per MPI rank (each rank its own
    particles: ``write_piece``), rank 0 writing each frame's .pvtu (the pieces' names and the
    arrays' types) and the .pvd index of the .pvtu files. A frame is named in the index once
    every rank's piece is on disk: ``done(k)`` (each rank waited for its frames before k),
    and at ``flush`` (the caller first has every rank wait: ``wait_piece``)."""

    def __init__(self, folder: Path, name: str, ranks: int, frames: list | None = None):
        self.ranks = ranks
        self.written = len(frames or [])         # frames whose every piece is on disk
        super().__init__(folder, name, frames)

    def next_frame(self) -> int:
        """The number of the frame to be written next."""
        return len(self.frames)

    def add(self, t: float, arrays: dict) -> Path:
        """Frame at time t [s] whose pieces the ranks are writing (``write_piece``, the
        number ``next_frame()``): its .pvtu, with ``arrays`` (name -> a numpy array of the
        pieces' dtype and trailing shape, e.g. rank 0's own) naming the arrays' types."""
        number = len(self.frames)
        file = f"{self.name}_{number:05d}.pvtu"
        columns = "".join(f'<PDataArray type="{_vtu_type(a)}" Name="{k}" NumberOfComponents="{_components(a)}"/>\n'
                          for k, a in arrays.items())
        pieces = "".join(f'<Piece Source="{piece_name(self.name, number, r)}"/>\n' for r in range(self.ranks))
        text = ('<?xml version="1.0"?>\n<VTKFile type="PUnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
                '<PUnstructuredGrid GhostLevel="0">\n<PPointData>\n' + columns + '</PPointData>\n'
                '<PPoints>\n<PDataArray type="Float64" Name="Points" NumberOfComponents="3"/>\n</PPoints>\n'
                + pieces + '</PUnstructuredGrid>\n</VTKFile>\n')
        with naming(self.folder / file):
            (self.folder / file).write_text(text)
        self.frames.append((t, file))
        self.written = number           # (every rank waited for its piece before this one's)
        if time.monotonic() - self._indexed >= self.INDEX_EVERY:
            self._index()
        return self.folder / file

    def write(self, t: float, points, **point_data) -> Path:
        raise RuntimeError("a PieceSeries' frames are written by every rank: write_piece, then add")

    def flush(self) -> None:
        """Every frame so far in the index: the caller had every rank wait for its pieces."""
        self.written = len(self.frames)
        self._index()

    def _index(self) -> None:
        listed, self.frames = self.frames, self.frames[:self.written]
        try:
            super()._index()
        finally:
            self.frames = listed


def _vtu_type(a: np.ndarray) -> str:
    import meshio.vtu._vtu as vtu
    return vtu.numpy_to_vtu_type[np.dtype(a.dtype)]


def _components(a: np.ndarray) -> int:
    return int(np.prod(a.shape[1:], dtype=np.int64)) if a.ndim > 1 else 1


class Progress:
    """Prints simulated time, rate and time left at most every ``every`` seconds of wall time."""

    def __init__(self, end: float, every: float = 5.0, stream=None):
        self.end, self.every, self._stream = end, every, stream        # None: sys.stdout when printing
        self.start = self.last = time.perf_counter()

    @property
    def stream(self):
        return self._stream or sys.stdout

    def update(self, t: float, extra: str = "", force: bool = False) -> None:
        now = time.perf_counter()
        if not force and now - self.last < self.every:
            return
        self.last = now
        wall = now - self.start
        rate = t / wall if wall > 0 else 0.0
        if self.end == float("inf"):            # a script's runs: no end known in advance
            print(f"t = {t:.5g} s, {rate:.3g} s simulated per s{extra}", file=self.stream, flush=True)
            return
        left = (self.end - t) / rate if rate > 0 else float("inf")
        print(f"t = {t:.5g} / {self.end:.5g} s ({100 * t / self.end:5.1f} %), "
              f"{rate:.3g} s simulated per s, {left:.0f} s left{extra}", file=self.stream, flush=True)

    def of_run(self, t: float, totals: dict, force: bool = False) -> None:
        """A coupled run's progress at ``t`` [s]: with its collisions so far (summary.json's totals)."""
        self.update(t, f", {totals['collisions']} collisions", force)
