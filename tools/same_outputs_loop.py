"""Runs of the project's cases, byte for byte against references taken before a change (issue 45,
the thin loop): ``take DIR CASE...`` runs each case with ``--test`` into DIR/CASE (the command
line's output, stdout and stderr, in DIR/CASE.log); ``compare REF NEW`` compares every file
under REF with the same path under NEW and says each one that differs, is missing or is new.

Left out of the comparison, and only they, are the text lines of ``WALL_CLOCK``: the progress
lines (rate and time left, printed every few seconds of wall time), a checkpoint's write
time, LIGGGHTS' and OpenFOAM's dates, timings and process ids in their logs, and the code
version in a checkpoint's manifest (the sources' SHA-256). Everything else, every CSV,
summary.json, VTK file, checkpoint file and every other line of the logs, must be
byte-identical. Exit 1 on any difference. The cases run with the same paths whichever tree
runs them (``RUN``): take both sets from trees at the same path.

    .venv/bin/python tools/same_outputs_loop.py take /tmp/ref two-particles hot-cold-box
    .venv/bin/python tools/same_outputs_loop.py compare /tmp/ref /tmp/new
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WALL_CLOCK = re.compile(
    r"simulated per s"                   # the progress line: its rate, and when it comes, are wall time
    r"|^checkpoint at t = .* MB, [0-9.]+ s$"    # a checkpoint's write time
    r"|Setting up run at|Loop time of|finish time|^Total wall time|time \(%\) ="   # LIGGGHTS' log: dates, timings
    r"|^Time   :|^PID    :|^Date   :|^Host   :|ExecutionTime ="      # OpenFOAM's logs: dates, timings
    r'|^ "code_version": '                # a checkpoint's manifest: the SHA-256 of the sources, changed by design
)
"""Lines left out of the comparison: wall-clock figures, dates, process ids, and the sources'
fingerprint in a checkpoint's manifest (a restart refuses a checkpoint of other sources)."""


RUN = Path("/tmp/same_outputs_loop.run")
"""Where every run writes, whichever tree and whichever DIR (paths in the outputs are the same):
moved to DIR/CASE after."""


def take(folder: Path, cases: list[str]) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for case in cases:
        shutil.rmtree(RUN, ignore_errors=True)
        with open(folder / f"{case}.log", "w") as log:
            code = subprocess.call([sys.executable, "-m", "pyhost", "run", str(ROOT / "cases" / case), "--test",
                                    "--out", str(RUN), "--overwrite"], stdout=log, stderr=subprocess.STDOUT,
                                   cwd=ROOT)
        shutil.rmtree(folder / case, ignore_errors=True)
        shutil.move(RUN, folder / case)
        print(f"{case}: exit {code}")


def lines(path: Path) -> list[bytes]:
    """The file's lines but those of ``WALL_CLOCK`` (text files; a binary file whole), and in
    LIGGGHTS' thermo output the CPU column (wall time) left out of each row."""
    data = path.read_bytes()
    if b"\0" in data[:4096]:
        return [data]
    kept, cpu = [], None
    for line in data.splitlines():
        words = line.split()
        if b"CPU" in words:                       # a thermo header: the rows under it have the column
            cpu = (words.index(b"CPU"), len(words))
        elif cpu and len(words) == cpu[1] and words[0].isdigit():
            line = b" ".join(words[:cpu[0]] + words[cpu[0] + 1:])
        if not WALL_CLOCK.search(line.decode(errors="replace")):
            kept.append(line)
    return kept


def compare(ref: Path, new: Path) -> int:
    a = {p.relative_to(ref) for p in ref.rglob("*") if p.is_file()}
    b = {p.relative_to(new) for p in new.rglob("*") if p.is_file()}
    bad = [f"missing: {p}" for p in sorted(a - b)] + [f"new: {p}" for p in sorted(b - a)]
    for p in sorted(a & b):
        x, y = lines(ref / p), lines(new / p)
        if x != y:
            where = next((k for k, (u, v) in enumerate(zip(x, y)) if u != v), min(len(x), len(y)))
            bad.append(f"differs: {p}" + (f" (line {where + 1}: {x[where][:120]!r} / {y[where][:120]!r})"
                                            if len(x) > 1 and where < min(len(x), len(y)) else ""))
    print("\n".join(bad) if bad else f"same: {len(a)} files")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "take":
        take(Path(sys.argv[2]), sys.argv[3:])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3])))
    else:
        sys.exit(__doc__)
