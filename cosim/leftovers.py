"""Names of a run's shared memory and temporary folders, and the sweep of a dead run's.

Every frame ring (/dev/shm/mobigrasp-frames-PID-*), lockstep socket folder
(/tmp/mobigrasp-ls-PID-*) and run folder of temporary files (/tmp/mobigrasp-run-PID-*) carries
the pid of the process that made it. A run ends by removing its own; one killed outright
(SIGKILL) cannot, so the next run removes those whose owner is no longer alive. Nothing else is
touched: only these three kinds of name, made by mobigrasp, and only with a dead owner.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from pathlib import Path

KINDS = ("frames", "ls", "run")
_NAME = re.compile(r"^mobigrasp-(frames|ls|run)-(\d+)-[A-Za-z0-9_]+$")


def prefix(kind: str) -> str:
    """The name prefix of this process's ``kind`` (one of :data:`KINDS`) of leftover."""
    if kind not in KINDS:
        raise ValueError(f"unknown kind of run leftover {kind!r}, expected one of {KINDS}")
    return f"mobigrasp-{kind}-{os.getpid()}-"


def owner_alive(pid: int) -> bool:
    """Whether a process ``pid`` exists (one of another user's counts as alive)."""
    if pid <= 0:
        return True  # not a pid a run could have: never swept
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _roots() -> list[Path]:
    roots = [Path(tempfile.gettempdir())]
    if os.path.isdir("/dev/shm"):
        roots.append(Path("/dev/shm"))
    return roots


def sweep(roots: list[Path] | None = None) -> list[Path]:
    """Remove the leftovers of dead runs under ``roots`` (default: the temporary folder and
    /dev/shm); the paths removed."""
    removed = []
    for root in roots if roots is not None else _roots():
        try:
            entries = list(os.scandir(root))
        except OSError:
            continue
        for entry in entries:
            m = _NAME.match(entry.name)
            if m is None or owner_alive(int(m.group(2))):
                continue
            try:
                if entry.is_dir(follow_symlinks=False):
                    shutil.rmtree(entry.path)
                elif entry.is_file(follow_symlinks=False) and m.group(1) == "frames":
                    os.unlink(entry.path)
                else:
                    continue
            except OSError:
                continue  # another run swept it first, or it is not ours to remove
            removed.append(Path(entry.path))
    return removed
