"""The output folder of a run: refused when it holds another run (unless overwriting),
cleared of that run's files when overwriting, checked writable before any engine starts;
small files written atomically, so that a crash or a full disk never leaves half a
summary.json."""
from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

from pyhost.cli import UserError

# What ``python -m pyhost run`` writes; an overwrite removes these and nothing else.
RUN_FILES = ("summary.json", "scene.json", "collisions.csv", "collisions", "history.csv", "vtk", "dem", "fluid",
             "temperatures.png", "particles.png",
             "checkpoint", ".checkpoint.new", ".checkpoint.old")


def prepare_output(out: Path, overwrite: bool = False) -> None:
    """Make ``out`` ready for a new run; UserError naming the folder if it cannot be."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: is a file, not a folder")
    if (out / "summary.json").exists() and not overwrite:
        raise UserError(f"--out {out}: holds another run (summary.json); give --overwrite to replace it, "
                        f"or another --out")
    try:
        out.mkdir(parents=True, exist_ok=True)
        for name in RUN_FILES:
            old = out / name
            if old.is_dir() and not old.is_symlink():
                shutil.rmtree(old)
            else:
                old.unlink(missing_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as exc:
        raise UserError(f"--out {out}: cannot write there ({exc.strerror})") from None


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to a temporary file beside ``path``, then rename it over ``path``: a
    reader sees the old file or the whole new one, never a part."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with open(tmp, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.filename is None:     # a failed write names no file
            exc.filename = str(path)
        raise


def run_output(out: Path) -> str | None:
    """What marks ``out`` as a run's output folder (``pyhost run``), which post must not write
    into: its scene.json, a file only a run writes (history.csv, collisions.csv, checkpoint,
    ...: a run of an older version or stopped on a full disk has no scene.json), or a
    summary.json that is not post's (a run's has a status, post's its frames); None if
    nothing does."""
    for name in RUN_FILES:
        if name not in ("summary.json", "vtk") and (out / name).exists():
            return name
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return "summary.json with a status" if not isinstance(summary, dict) or "frames" not in summary else None
