"""Throughput of the dump reader (pyhost.dumps): frames/s and particle rows/s.

Writes dumps shaped like LIGGGHTS' ``dump custom ... id type x y z vx vy vz radius f_Temp[0]``
(values as %g, the trailing space of the header) into a temporary folder: one file holding
every step, the same gzipped, and one file per step; then reads each through DumpReader
(with the columns post-processing requires checked) and prints the figures, best of --repeat.

Run: .venv/bin/python tools/bench_dumps.py [--frames 50] [--particles 20000]
"""
from __future__ import annotations

import argparse
import gzip
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from pyhost.dumps import DumpReader

HEADER = ("ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{n}\nITEM: BOX BOUNDS pp pp ff\n"
          "0 0.1\n0 0.1\n0 0.2\nITEM: ATOMS id type x y z vx vy vz radius f_Temp[0] \n")


def write(folder: Path, frames: int, n: int) -> None:
    rng = np.random.default_rng(0)
    with open(folder / "all.dump", "w") as every:
        for k in range(frames):
            data = np.column_stack([rng.permutation(n) + 1, rng.integers(1, 3, n), rng.random((n, 3)) * 0.1,
                                    rng.normal(0, 0.3, (n, 3)), rng.uniform(1e-3, 2e-3, n), 300 + rng.random(n)])
            text = HEADER.format(step=1000 * k, n=n) + "".join(
                " ".join(f"{v:g}" for v in row) + " \n" for row in data.tolist())
            every.write(text)
            (folder / f"dump.{1000 * k}").write_text(text)
    with open(folder / "all.dump", "rb") as src, gzip.open(folder / "all.dump.gz", "wb") as dst:
        shutil.copyfileobj(src, dst)


def measure(paths, repeat: int) -> tuple[float, int, int]:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        frames = rows = 0
        for f in DumpReader(paths, require=("id", "type", "position", "velocity", "radius")):
            frames, rows = frames + 1, rows + len(f)
        best = min(best, time.perf_counter() - start)
    return best, frames, rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, default=50)
    p.add_argument("--particles", type=int, default=20000)
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        write(folder, args.frames, args.particles)
        size = (folder / "all.dump").stat().st_size
        print(f"{args.frames} frames of {args.particles} particles, {size / 1e6:.1f} MB of text "
              f"({(folder / 'all.dump.gz').stat().st_size / 1e6:.1f} MB gzipped)")
        print(f"{'input':<22} {'s':>7} {'frames/s':>9} {'rows/s':>10} {'MB/s':>6}")
        for name, paths in (("one file", [folder / "all.dump"]), ("one file, gzipped", [folder / "all.dump.gz"]),
                            ("one file per step", [folder / "dump.*"])):
            t, frames, rows = measure(paths, args.repeat)
            print(f"{name:<22} {t:7.2f} {frames / t:9.1f} {rows / t:10.3g} {size / t / 1e6:6.1f}")


if __name__ == "__main__":
    main()
