"""On-disk cache of generated marker textures (speed only: the arrays are stored bit for bit).

Generating the 512 x 512 marker textures (mcu_sim/world/markers.py, 3 x 3 supersampled) takes
~0.3 s per texture, paid in every run's first frame. The levels are stored as a ``.npz`` keyed by
the SHA-256 of the generator's source file, the numpy version, the CPU architecture, the
texture's name and its arguments, so any change to the drawing code or numpy makes a new
entry; a file that cannot be read or does not hold what is expected is ignored and rebuilt.

Folder: ``$MOBIGRASP_CACHE_DIR`` if set (``off`` disables the cache), else
``$XDG_CACHE_HOME/mobigrasp`` or ``~/.cache/mobigrasp``. An unwritable folder only costs speed.
"""

from __future__ import annotations

import hashlib
import os
import platform
import tempfile
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path

import numpy as np


def cache_dir() -> Path | None:
    """The cache folder, or None when caching is off."""
    env = os.environ.get("MOBIGRASP_CACHE_DIR")
    if env is not None:
        return None if env.strip().lower() in ("", "off", "0", "none") else Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "mobigrasp"


@lru_cache(maxsize=8)
def _source_digest(source_file: str) -> str:
    return hashlib.sha256(Path(source_file).read_bytes()).hexdigest()


def cache_key(source_file: str, name: str, *args: object) -> str:
    """File name of one texture: depends on the generator's source, numpy and the arguments."""
    h = hashlib.sha256()
    for part in (_source_digest(source_file), np.__version__, platform.machine(), name,
                 repr(args)):
        h.update(part.encode())
        h.update(b"\0")
    return f"{name}-{h.hexdigest()[:32]}.npz"


def _load(path: Path) -> tuple[np.ndarray, ...] | None:
    try:
        with np.load(path, allow_pickle=False) as z:
            n = int(z["count"])
            levels = tuple(z[f"level{k}"] for k in range(n))
    except (OSError, KeyError, ValueError, EOFError):
        return None
    if not levels or any(a.dtype != np.uint8 or a.ndim != 3 for a in levels):
        return None
    return levels


def _store(path: Path, levels: tuple[np.ndarray, ...]) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=path.stem, suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as f:
            np.savez(f, count=np.int64(len(levels)),
                     **{f"level{k}": a for k, a in enumerate(levels)})
        os.replace(tmp, path)  # atomic: concurrent runs never see half a file
    except OSError:
        pass


def cached_levels(source_file: str, name: str, args: tuple,
                  build: Callable[[], tuple[np.ndarray, ...]]) -> tuple[np.ndarray, ...]:
    """``build()``'s texture levels, from the disk cache when an entry exists."""
    folder = cache_dir()
    if folder is None:
        return build()
    path = folder / cache_key(source_file, name, *args)
    levels = _load(path)
    if levels is None:
        levels = build()
        _store(path, levels)
    return levels
