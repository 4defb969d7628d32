"""What a run leaves on disk, written as it goes so that a crash or an interrupt keeps it.

- ``CsvLog``: rows appended and flushed at every write (collisions, history);
- ``VtkSeries``: one .vtu per frame (meshio) and a .pvd index rewritten after each frame,
  so ParaView and pyvista (``pyvista.read(...pvd)``) open whatever was written;
- ``Progress``: one line every few seconds of wall time: simulated time, rate, time left.
"""
from __future__ import annotations

import csv
import os
import sys
import time
from pathlib import Path

import meshio
import numpy as np


class CsvLog:
    """A CSV file with a fixed header; ``write(rows)`` appends and flushes. ``resume_at``: the
    size [bytes] of the file at a checkpoint: what came after is cut, and rows follow it."""

    def __init__(self, path: Path, columns: tuple, resume_at: int | None = None):
        self.path, self.columns = Path(path), columns
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if resume_at is not None:
            os.truncate(self.path, resume_at)
            self._file = open(self.path, "a", newline="")
            self._csv = csv.writer(self._file)
            return
        self._file = open(self.path, "w", newline="")
        self._csv = csv.writer(self._file)
        self._csv.writerow(columns)
        self._file.flush()

    @property
    def size(self) -> int:
        """Bytes written so far (all flushed)."""
        return self._file.tell()

    def write(self, rows) -> None:
        self._csv.writerows(rows)
        self._file.flush()

    def write_columns(self, **arrays) -> None:
        """Rows from equal-length arrays named by the columns."""
        cols = [np.asarray(arrays[c]) for c in self.columns]
        if cols and len(cols[0]):
            self.write(zip(*(c.tolist() for c in cols)))

    def close(self) -> None:
        self._file.close()


class VtkSeries:
    """Points with data, one file per frame, and the .pvd index of the frames so far.
    ``frames``: those of a checkpoint to continue from; later frame files are removed."""

    def __init__(self, folder: Path, name: str, frames: list | None = None):
        self.folder, self.name = Path(folder), name
        self.folder.mkdir(parents=True, exist_ok=True)
        self.frames: list[tuple[float, str]] = [tuple(f) for f in frames or []]
        if frames is not None:
            kept = {f for _, f in self.frames}
            for old in self.folder.glob(f"{self.name}_*.vtu"):
                if old.name not in kept:
                    old.unlink()
            self._index()

    def write(self, t: float, points, **point_data) -> Path:
        file = f"{self.name}_{len(self.frames):05d}.vtu"
        points = np.asarray(points, float)
        cells = [("vertex", np.arange(len(points)).reshape(-1, 1))]
        meshio.write(self.folder / file, meshio.Mesh(points, cells, point_data=point_data))
        self.frames.append((t, file))
        self._index()
        return self.folder / file

    def _index(self) -> None:
        index = self.folder / f"{self.name}.pvd"
        tmp = index.with_suffix(".pvd.tmp")
        tmp.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
                       + "".join(f'<DataSet timestep="{t!r}" file="{f}"/>\n' for t, f in self.frames)
                       + "</Collection>\n</VTKFile>\n")
        tmp.replace(index)


class Progress:
    """Prints simulated time, rate and time left at most every ``every`` seconds of wall time."""

    def __init__(self, end: float, every: float = 5.0, stream=sys.stdout):
        self.end, self.every, self.stream = end, every, stream
        self.start = self.last = time.perf_counter()

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
