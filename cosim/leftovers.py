"""A run's shared memory and temporary folders, recorded as its own, and the sweep of a dead
run's.

Every frame ring (/dev/shm/mobigrasp-frames-PID-*), lockstep socket folder
(/tmp/mobigrasp-ls-PID-*) and folder of temporary files (/tmp/mobigrasp-run-PID-*) is made by
:func:`temp_dir` or :func:`temp_file`, which record it in this user's ledger (a folder of
mode 0700 in the temporary folder): the path, its device and inode, and the owner's pid and
start time, and for a folder a random token also written into it (:data:`OWNER_FILE`). A run
ends by removing its own; one killed outright (SIGKILL) cannot, so the next run removes what the
ledger proves belongs to a process that is gone: an owner whose pid is free or now another
process, the same inode at the recorded path and, for a folder, the same token inside. A name
that merely looks like one of these is never touched.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import tempfile
from pathlib import Path

KINDS = ("frames", "ls", "run")
_LEDGER = "mobigrasp-ledger-{uid}"
OWNER_FILE = ".mobigrasp-owner"  # in a recorded folder: the token its record holds


def prefix(kind: str) -> str:
    """The name prefix of this process's ``kind`` (one of :data:`KINDS`) of leftover."""
    if kind not in KINDS:
        raise ValueError(f"unknown kind of run leftover {kind!r}, expected one of {KINDS}")
    return f"mobigrasp-{kind}-{os.getpid()}-"


def _start_ticks(pid: int) -> int | None:
    """When process ``pid`` started (clock ticks since boot, /proc), None if it does not
    exist or there is no /proc."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return int(stat.rsplit(")", 1)[1].split()[19])  # field 22: starttime


def owner_alive(pid: int, start_ticks: int | None = None) -> bool:
    """Whether process ``pid`` exists (one of another user's counts as alive) and, when
    ``start_ticks`` is given, is the one that started then (not a later one with its pid)."""
    if pid <= 0:
        return True  # not a pid a run could have: never swept
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    if start_ticks is not None:
        now = _start_ticks(pid)
        return now is None or now == start_ticks
    return True


def ledger_dir(root: Path | None = None) -> Path:
    """This user's ledger under ``root`` (default: the temporary folder); made on first use,
    refused (OSError) when it is not a folder of this user's that only they may write."""
    path = Path(root or tempfile.gettempdir()) / _LEDGER.format(uid=os.getuid())
    try:
        path.mkdir(mode=0o700)
    except FileExistsError:
        pass
    st = os.lstat(path)
    if not os.path.isdir(path) or os.path.islink(path) or st.st_uid != os.getuid() \
            or st.st_mode & 0o022:
        raise OSError(f"{path} is not a private folder of this user's")
    return path


def _record_name(path: str) -> str:
    return os.path.basename(path) + ".json"


def own(path: str, ledger: Path | None = None) -> None:
    """Record ``path`` (made just now by this process) in the ledger."""
    token = None
    if os.path.isdir(path) and not os.path.islink(path):
        token = secrets.token_hex(16)
        Path(path, OWNER_FILE).write_text(token)
    st = os.lstat(path)
    record = {"path": os.path.abspath(path), "dev": st.st_dev, "ino": st.st_ino,
              "token": token, "pid": os.getpid(), "start_ticks": _start_ticks(os.getpid())}
    book = ledger_dir(ledger)
    tmp = book / (_record_name(path) + ".tmp")
    tmp.write_text(json.dumps(record))
    tmp.replace(book / _record_name(path))


def disown(path: str, ledger: Path | None = None) -> None:
    """Drop ``path``'s record (its owner removed it)."""
    try:
        (ledger_dir(ledger) / _record_name(path)).unlink()
    except OSError:
        pass


class _OwnedTempDir(tempfile.TemporaryDirectory):
    """A TemporaryDirectory recorded in the ledger while it exists."""

    def __init__(self, kind: str, ledger: Path | None = None) -> None:
        super().__init__(prefix=prefix(kind))
        self._ledger = ledger
        own(self.name, ledger)

    def cleanup(self) -> None:
        super().cleanup()
        disown(self.name, self._ledger)


def temp_dir(kind: str, ledger: Path | None = None) -> tempfile.TemporaryDirectory:
    """A temporary folder of this run's ``kind``, recorded; ``cleanup()`` removes both."""
    return _OwnedTempDir(kind, ledger)


def temp_file(kind: str, directory: str | None = None, ledger: Path | None = None
              ) -> tuple[int, str]:
    """(fd, path) of a new temporary file of this run's ``kind`` (in ``directory``), recorded;
    :func:`disown` it when it is removed."""
    fd, path = tempfile.mkstemp(prefix=prefix(kind), dir=directory)
    own(path, ledger)
    return fd, path


def _holds_token(path: str, token: str | None) -> bool:
    """Whether ``path`` is the object recorded: a folder holds the recorded token, a file was
    recorded without one."""
    if not os.path.isdir(path) or os.path.islink(path):
        return token is None
    try:
        return token is not None and Path(path, OWNER_FILE).read_text() == token
    except OSError:
        return False


def sweep(ledger: Path | None = None) -> list[Path]:
    """Remove what the ledger proves dead runs left behind; the paths removed. A record whose
    path is gone or is another object now is dropped without touching anything."""
    removed = []
    try:
        book = ledger_dir(ledger)
        records = sorted(book.glob("*.json"))
    except OSError:
        return removed
    for rec_path in records:
        try:
            rec = json.loads(rec_path.read_text())
            path, pid = str(rec["path"]), int(rec["pid"])
            start = rec.get("start_ticks")
            dev, ino, token = int(rec["dev"]), int(rec["ino"]), rec.get("token")
        except (OSError, ValueError, KeyError, TypeError):
            continue  # not a record this module wrote: left alone
        if owner_alive(pid, None if start is None else int(start)):
            continue
        try:
            st = os.lstat(path)
        except OSError:
            st = None
        if st is not None and (st.st_dev, st.st_ino) == (dev, ino) \
                and _holds_token(path, token):
            try:
                if os.path.isdir(path) and not os.path.islink(path):
                    shutil.rmtree(path)
                else:
                    os.unlink(path)
                removed.append(Path(path))
            except OSError:
                continue  # another run swept it first, or it is not ours to remove
        try:
            rec_path.unlink()
        except OSError:
            pass
    return removed
