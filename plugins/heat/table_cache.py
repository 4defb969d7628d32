"""The fast path's tables on disk (the plugin's only I/O): one file per (model, b1, b2, c[,
spacing]) under COLLHEAT_CACHE (default ~/.cache/collheat), keyed on what the tables depend on
(every source file of the heat and DEM plugins, so an edited model never reads an old table),
with a checksum beside each that catches a damaged file. A file that cannot be written is
skipped: the table is then built again by the next process."""
from __future__ import annotations

import hashlib
import io
import os
import warnings
from functools import lru_cache
from pathlib import Path

import numpy as np


class CacheWarning(UserWarning):
    """A cached table was damaged and has been rebuilt."""


def cache_dir() -> Path:
    return Path(os.environ.get("COLLHEAT_CACHE", Path.home() / ".cache" / "collheat"))


@lru_cache(maxsize=1)
def source_digest(root: Path = Path(__file__).parents[1]) -> str:
    """SHA-256 of every Python file of the heat plugin (the models in models/ included) and of
    the DEM plugin it takes the Hertz constants from, with their paths: the tables depend on
    all of them, so an edited file gives a new cache key."""
    h = hashlib.sha256()
    for f in sorted(f for part in ("heat", "dem") for f in (root / part).rglob("*.py")):
        h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()


def _path(model: str, ident: tuple) -> Path:
    key = hashlib.sha256(repr(ident).encode() + source_digest().encode()).hexdigest()[:16]
    return cache_dir() / f"table-{model}-{key}.npy"


def load(model: str, ident: tuple) -> dict | None:
    """The stored state of the table ``ident`` of ``model``; None if there is none (or it was
    damaged: CacheWarning, and it is rebuilt)."""
    path = _path(model, ident)
    try:
        raw = path.read_bytes()
        if hashlib.sha256(raw).hexdigest() != path.with_suffix(".sha256").read_text().strip():
            raise ValueError("checksum mismatch")
        return np.load(io.BytesIO(raw), allow_pickle=True).item()
    except FileNotFoundError:
        return None
    except Exception as exc:        # whatever a damaged file makes the unpickler raise
        warnings.warn(f"table cache {path} is corrupt ({exc}); rebuilding it", CacheWarning, stacklevel=3)
        return None


def save(model: str, ident: tuple, state: dict) -> None:
    """Store a table's state: the file and its checksum each written whole (a temporary then
    renamed), the checksum first."""
    path = _path(model, ident)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        buffer = io.BytesIO()
        np.save(buffer, np.array(state, dtype=object), allow_pickle=True)
        for target, data in ((path.with_suffix(".sha256"), hashlib.sha256(buffer.getvalue()).hexdigest().encode()),
                             (path, buffer.getvalue())):
            tmp = target.with_name(f"{target.name}.tmp{os.getpid()}")
            tmp.write_bytes(data)
            os.replace(tmp, target)
    except OSError:
        pass
