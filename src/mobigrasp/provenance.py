"""Which source a result came from: the git checkout the package is imported from (an editable
install) and its commit, ``+dirty`` with uncommitted changes; ``unknown`` for a wheel."""

from __future__ import annotations

import subprocess
from pathlib import Path

from mobigrasp.resources import data_dir


def source_checkout() -> Path | None:
    """The git checkout the package is imported from (an editable install), else None."""
    here = data_dir("mobigrasp")
    try:
        top = subprocess.run(["git", "-C", str(here), "rev-parse", "--show-toplevel"],
                             capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    # a wheel installed in a virtual environment that lies inside some other repository: the
    # checkout is ours when it holds this package's source (src/mobigrasp/)
    if not top or not (Path(top) / "src" / "mobigrasp" / "resources.py").is_file():
        return None
    return Path(top)


def source_commit(paths: tuple[str, ...] = (), digits: int | None = None,
                  untracked: bool = True) -> str:
    """The checkout's commit (``digits`` long, git's default length when None), ``+dirty`` when
    ``paths`` (all when empty) have uncommitted changes (untracked files counted when
    ``untracked``); ``unknown`` outside a checkout."""
    root = source_checkout()
    if root is None:
        return "unknown"
    short = "--short" if digits is None else f"--short={digits}"
    status = ["status", "--porcelain", *(() if untracked else ("--untracked-files=no",))]
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", short, "HEAD"],
                              capture_output=True, text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), *status, "--", *paths],
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (head + ("+dirty" if dirty else "")) if head else "unknown"
