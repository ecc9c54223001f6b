"""The run folder: trace.jsonl written as the run goes, camera snapshots, summary.json.

Nothing is lost when a run crashes midway: every trace line is flushed when written, and the
summary is written in a ``finally`` by the runner with ``status`` "crashed" and what is known.
The trace holds simulated-time data only, so its SHA-256 (``trace_sha256``) is the same for the
same scenario and seed over any transport and at any speed.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import math
import os
import re
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

import cv2
import numpy as np


def _clean(obj: Any) -> Any:
    """JSON-safe copy: numpy to Python, non-finite floats to None, floats rounded to 9 digits."""
    t = type(obj)
    if t is int or t is str or t is bool or obj is None:  # most leaves: returned as they are
        return obj
    if t is dict:
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, float):
        return round(obj, 9) if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.generic):
        return _clean(obj.item())
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    return obj


# What json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False) builds on every
# call, built once (same output: dumps is JSONEncoder(those options).encode(obj))
_LINE_ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"), allow_nan=False)


# The trace's bound: at most this many bytes per simulated second (the shipped scenarios peak
# at 16 kB in a second, 0.5-0.63 MB per simulated minute: docs/outputs.md "Trace size"); an
# event beyond it is counted, not written, except the ones a reader needs to follow the run
TRACE_MAX_BYTES_PER_S = 128 * 1024
_ALWAYS_WRITTEN = frozenset({"start", "state", "end"})


class TraceWriter:
    """One JSON event per line, sorted keys, flushed per line; hashes exactly what it writes.

    At most ``max_bytes_per_s`` bytes of events per simulated second: the others are counted
    (:attr:`dropped_events`, :attr:`dropped_bytes`) and a ``trace_dropped`` event with the
    counts of that second is written with the first event of a later one."""

    def __init__(self, path: Path, max_bytes_per_s: int = TRACE_MAX_BYTES_PER_S) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fh = self.path.open("w", encoding="utf-8")
        self._sha = hashlib.sha256()
        self.lines = 0
        self.max_bytes_per_s = max_bytes_per_s
        self.dropped_events = 0
        self.dropped_bytes = 0
        self._second = 0
        self._second_bytes = 0
        self._second_dropped = [0, 0]  # events, bytes

    def write(self, event: dict) -> None:
        """Append one event (must carry ``t_us`` and ``ev``)."""
        if "t_us" not in event or "ev" not in event:
            raise ValueError(f"trace event needs t_us and ev: {str(event)[:200]}")
        line = _LINE_ENCODER.encode(_clean(event)) + "\n"
        second = event["t_us"] // 1_000_000
        if second > self._second:
            if self._second_dropped[0]:
                n, b = self._second_dropped
                self._second_dropped = [0, 0]
                self._put(_LINE_ENCODER.encode({"ev": "trace_dropped", "t_us": event["t_us"],
                                                "second": self._second, "events": n,
                                                "bytes": b}) + "\n")
            self._second, self._second_bytes = second, 0
        if self._second_bytes + len(line) > self.max_bytes_per_s \
                and event["ev"] not in _ALWAYS_WRITTEN:
            self.dropped_events += 1
            self.dropped_bytes += len(line)
            self._second_dropped[0] += 1
            self._second_dropped[1] += len(line)
            return
        self._second_bytes += len(line)
        self._put(line)

    def _put(self, line: str) -> None:
        self._sha.update(line.encode())
        self._fh.write(line)
        self._fh.flush()
        self.lines += 1

    def sha256(self) -> str:
        """Digest of every line written so far."""
        return self._sha.hexdigest()

    def close(self) -> None:
        """Close the file (idempotent)."""
        if not self._fh.closed:
            self._fh.close()


def json_lines(path: Path) -> Iterator[tuple[int, Any]]:
    """(line number, value) of each line of a JSON-lines file (a trace, a campaign's rows),
    up to a torn last line, which a run or campaign stopped while writing it leaves."""
    with Path(path).open(encoding="utf-8", errors="replace") as fh:
        for n, line in enumerate(fh, 1):
            try:
                value = json.loads(line)
            except json.JSONDecodeError:
                return
            yield n, value


def split_rows(path: Path) -> tuple[list[tuple[int, dict]], list[tuple[int, str]]]:
    """The lines of a JSON-lines file of rows (a campaign's): (line number, row) of every
    line that is a JSON object, and (line number, text) of every other line (damaged: torn by
    a kill, cut, or garbled), each in file order. Nothing is dropped unseen."""
    rows: list[tuple[int, dict]] = []
    damaged: list[tuple[int, str]] = []
    with Path(path).open(encoding="utf-8", errors="replace", newline="\n") as fh:
        for n, line in enumerate(fh, 1):
            try:
                value = json.loads(line) if line.endswith("\n") else None
            except (ValueError, RecursionError):
                value = None
            if isinstance(value, dict):
                rows.append((n, value))
            elif line.strip():
                damaged.append((n, line.rstrip("\n")))
    return rows, damaged


def set_aside(path: Path, keep: list[str], damaged: list[str], aside: Path) -> None:
    """Rewrite ``path`` with the lines ``keep`` (atomically) after appending the lines
    ``damaged`` to ``aside``: a damaged row is moved, never lost, and never read again."""
    if damaged:
        with Path(aside).open("a", encoding="utf-8") as fh:
            fh.write("".join(line + "\n" for line in damaged))
    tmp = Path(path).with_suffix(".tmp")
    tmp.write_text("".join(line + "\n" for line in keep), encoding="utf-8")
    tmp.replace(path)


def read_trace(path: Path) -> list[dict]:
    """All events of a trace file (a torn last line from a crash is skipped)."""
    return [event for _, event in json_lines(path)]


def write_summary(path: Path, summary: dict) -> None:
    """summary.json, written atomically (temp file + rename) so a reader never sees half."""
    path = Path(path)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(_clean(summary), indent=2, sort_keys=True) + "\n")
    tmp.replace(path)


def detection_points(result: Any) -> list[tuple[int, int]]:
    """Pixel points a detection result names: ``u<x>_q4`` with ``v<x>_q4`` (u_q4, u1_q4, um_q4,
    u_c_q4, ...), in Q4 px."""
    pts: list[tuple[int, int]] = []
    if isinstance(result, dict):
        for key, value in result.items():
            if isinstance(value, int | float) and key.startswith("u") and key.endswith("_q4"):
                v = result.get("v" + key[1:])
                if isinstance(v, int | float):
                    pts.append((int(value) // 16, int(v) // 16))
            elif isinstance(value, dict | list):
                pts.extend(detection_points(value))
    elif isinstance(result, list):
        for item in result:
            pts.extend(detection_points(item))
    return pts


SNAPSHOT_LINE_PX = 12  # text line height of the 0.8-scale Hershey plain font, plus spacing


def draw_detection(rgb: np.ndarray, results: dict | None, label: str) -> np.ndarray:
    """BGR image for a PNG: the frame, a cross at every detected point, and a caption."""
    img = cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2BGR)
    missed = 0
    for name, result in (results or {}).items():
        colour = (0, 255, 0) if result is not None else (0, 0, 255)
        for u, v in detection_points(result):
            cv2.drawMarker(img, (u, v), colour, cv2.MARKER_CROSS, 12, 1)
        if result is None:  # one line per detector that found nothing, stacked upwards
            cv2.putText(img, f"{name}: none", (4, img.shape[0] - 6 - SNAPSHOT_LINE_PX * missed),
                        cv2.FONT_HERSHEY_PLAIN, 0.8, colour, 1)
            missed += 1
    cv2.putText(img, label, (4, 12), cv2.FONT_HERSHEY_PLAIN, 0.8, (255, 255, 0), 1)
    return img


class Snapshots:
    """Keeps the last few frames and writes one PNG at every task state change.

    The PNGs are encoded and written by a worker thread (cv2.imwrite releases the GIL: 3-15 ms
    each that the run's loop, which calls :meth:`on_host_event`, no longer waits for); reading
    :attr:`written` waits for them, so its files exist once it is read."""

    def __init__(self, folder: Path, keep: int = 12) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.keep = keep
        self._frames: dict[int, np.ndarray] = {}
        self._last_detect: dict | None = None
        self._written: list[str] = []
        self._writer: ThreadPoolExecutor | None = None  # started at the first snapshot
        self._pending: list[Future] = []
        # OpenCV builds its Hershey font tables on the first putText (~50-100 ms): pay that here,
        # before the run's loop, not at the first state change in the middle of it
        cv2.putText(np.zeros((1, 1, 3), np.uint8), "0", (0, 0), cv2.FONT_HERSHEY_PLAIN, 0.8,
                    (255, 255, 0), 1)

    def on_frame(self, seq: int, capture_us: int, rgb: np.ndarray) -> None:
        """Rig callback for every captured frame."""
        self._frames[seq] = rgb
        while len(self._frames) > self.keep:
            del self._frames[min(self._frames)]

    def on_host_event(self, event: dict) -> None:
        """Host trace event: remember detections, snapshot at state changes."""
        if event.get("ev") == "detect":
            self._last_detect = event
        elif event.get("ev") == "state" and self._frames:
            det = self._last_detect
            seq = det["seq"] if det and det["seq"] in self._frames else max(self._frames)
            results = det["results"] if det and det["seq"] == seq else None
            to = str(event.get("to", event.get("state", "?")))
            label = f"t={event['t_us'] / 1e6:.2f}s {event.get('from', '')}->{to} frame {seq}"
            name = f"{len(self._written):03d}_{event['t_us'] // 1000:07d}ms_{to}.png"
            img = draw_detection(self._frames[seq], results, label)  # a new image: the thread's
            record_written(self.folder.parent, f"{self.folder.name}/{name}")
            if self._writer is None:
                self._writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="snapshots")
            self._pending.append(self._writer.submit(cv2.imwrite, str(self.folder / name), img))
            self._written.append(name)

    @property
    def written(self) -> list[str]:
        """The snapshot files (names in ``folder``), in order; waits until they are written
        (and raises what writing one raised)."""
        pending, self._pending = self._pending, []
        for future in pending:
            future.result()
        if self._writer is not None:  # idle now: its thread ends (a later snapshot starts one)
            self._writer.shutdown()
            self._writer = None
        return self._written


# --- where a run folder is, who holds it, and what mobigrasp may delete in it ---------------

RUNS_ROOT = Path("runs")
# written into every run folder mobigrasp creates: a first line, then the path (relative to the
# folder) of every file mobigrasp wrote there, listed before it is written; only those are ever
# removed or overwritten by a later run
RUN_MARKER = ".mobigrasp-run"
CAMPAIGN_MARKER = ".mobigrasp-campaign"
_MARKER_HEAD = ("a mobigrasp folder: the files listed below are the ones mobigrasp wrote here, "
                "the only ones it ever removes\n")
# the top-level files of a run (listed in the marker when the folder is taken: a SIGKILL at
# any time leaves nothing of the run's unlisted)
RUN_FILES = ("summary.json", "summary.json.tmp", "trace.jsonl", "trace.mcap", "report.html",
             "profile.json")
_NAME_MAX = 100
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]")
_DEFAULT_TRIES = 100  # default folders of a command that never collides: <name>, <name>-2, ...


class RunFolderError(ValueError):
    """The run folder cannot be used (the message names the path and why): exit code 2."""


class FolderInUse(RunFolderError):
    """Another mobigrasp process holds the folder's lock."""


def safe_component(name: str) -> str:
    """``name`` as one path component of ``[A-Za-z0-9._-]``: every other character becomes
    ``_``, a leading dot too (no ``.``, ``..`` or hidden folder), at most 100 characters."""
    safe = _UNSAFE.sub("_", name)[:_NAME_MAX]
    if not safe or safe.startswith("."):
        safe = "_" + safe[1:] if safe else "_"
    return safe


def default_run_folder(name: str, seed: int, runs_root: Path = RUNS_ROOT,
                       suffix: str = "") -> Path:
    """``<runs_root>/<sanitised name>-<seed><suffix>``: always one folder directly under the
    root (``suffix`` is the command's own, e.g. ``-sim``, of the same safe characters)."""
    return Path(runs_root) / safe_component(f"{safe_component(name)}-{int(seed)}{suffix}")


def _listed_path(line: str) -> str | None:
    """A marker line as a relative path inside the folder, or None (absolute, ``..``, empty)."""
    rel = line.rstrip("\n")
    parts = Path(rel).parts
    if not rel or Path(rel).is_absolute() or any(p in ("..", ".") for p in parts):
        return None
    return rel


# The run marker of earlier versions: this one line and no list. Such a folder's own files are
# the ones those versions wrote: these names, and PNGs of theirs in plots/ and frames/.
_MARKER_UNLISTED = "a mobigrasp run folder: `mobigrasp run` may replace the files it wrote here"
_UNLISTED_PNG = {"plots": re.compile(r"(trajectory|joints|bezier|fuzzy|arm9_load)\.png"),
                 "frames": re.compile(r"\d{3}_\d{7}ms_[A-Za-z0-9_?]+\.png")}


def owned_files(folder: Path, marker: str = RUN_MARKER) -> list[str]:
    """The files the folder's marker lists (mobigrasp wrote them), in order, once each."""
    try:
        lines = (Path(folder) / marker).read_text(encoding="utf-8", errors="replace"
                                                   ).splitlines()
    except OSError:
        return []
    if lines == [_MARKER_UNLISTED] and marker == RUN_MARKER:
        return [*RUN_FILES, *(f"{sub}/{p.name}" for sub, pattern in _UNLISTED_PNG.items()
                              if (Path(folder) / sub).is_dir()
                              for p in sorted((Path(folder) / sub).iterdir())
                              if pattern.fullmatch(p.name))]
    listed = (_listed_path(line) for line in lines[1:])
    return list(dict.fromkeys(rel for rel in listed if rel is not None))


def record_written(folder: Path, *names: str, marker: str = RUN_MARKER) -> None:
    """List ``names`` (relative to ``folder``) in its marker before they are written; nothing
    when the folder has no marker (a folder that is not a run's)."""
    path = Path(folder) / marker
    if not path.is_file() or path.is_symlink():
        return
    new = [n for n in names if n not in set(owned_files(folder, marker))]
    if new:
        with path.open("a", encoding="utf-8") as fh:
            fh.write("".join(n + "\n" for n in new))


class OwnedFolder:
    """A folder held by one mobigrasp process: an exclusive lock on the folder itself (flock
    on its descriptor, released by the kernel however the process ends), and its marker.

    :meth:`take` locks and checks without changing anything; :meth:`prepare` then removes what
    the previous holder listed in the marker and lists ``files`` for this one."""

    def __init__(self, path: Path, marker: str, fd: int, created: tuple[Path, ...]) -> None:
        self.path = path
        self.marker = marker
        self._fd: int | None = fd
        self._created = created  # the folders take() made, deepest first

    @classmethod
    def take(cls, out: Path, marker: str, what: str, option: str = "--out") -> OwnedFolder:
        """Lock ``out`` (created if missing); RunFolderError when it is a symbolic link, a file,
        in use by another process, or holds files and no ``marker``. Changes nothing but
        creating the folder and its missing parents (removed again when refused)."""
        out = Path(out)
        if out.is_symlink():
            raise RunFolderError(f"{option} {out} is a symbolic link: refusing to write through it")
        if out.exists() and not out.is_dir():
            raise RunFolderError(f"{option} {out} exists and is a file, not a folder")
        created = tuple(p for p in (out, *out.parents) if not p.exists())
        try:
            out.mkdir(parents=True, exist_ok=True)
            fd = os.open(out, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        except OSError as exc:
            _remove_empty(created)
            raise RunFolderError(f"{option} {out}: cannot create the {what} folder "
                                 f"({exc.filename or out}: {exc.strerror or exc})") from exc
        held = cls(out, marker, fd, created)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            held._fd = None
            os.close(fd)
            raise FolderInUse(f"{option} {out} is in use by another mobigrasp process: "
                              f"refusing to touch it") from exc
        if not (out / marker).is_file() and any(out.iterdir()):
            held.abandon()
            raise RunFolderError(f"{option} {out} is not empty and is not a mobigrasp {what} "
                                 f"folder (no {marker}): refusing to write into it")
        return held

    def check(self, files: tuple[str, ...] = ()) -> None:
        """What :meth:`prepare` would refuse, without changing anything: RunFolderError when
        one of ``files`` is there and not listed in the marker, or the folder cannot be
        written into."""
        out = self.path
        listed = owned_files(out, self.marker)
        foreign = [f for f in files if f not in listed
                   and ((out / f).exists() or (out / f).is_symlink())]
        if foreign:
            raise RunFolderError(f"--out {out} holds {foreign[0]}, which mobigrasp did not "
                                 f"write: refusing to overwrite it")
        if not os.access(out, os.W_OK | os.X_OK):
            raise RunFolderError(f"--out {out}: cannot prepare the folder ({out}: "
                                 f"{os.strerror(errno.EACCES)})")

    def prepare(self, files: tuple[str, ...] = (), remove_previous: bool = True) -> Path:
        """Make the folder this holder's: refuse (RunFolderError, nothing changed) when one of
        ``files`` is there and not listed in the marker (:meth:`check`); remove the previously
        listed files (``remove_previous``) and list ``files``. The folder's path."""
        out = self.path
        self.check(files)
        listed = owned_files(out, self.marker)
        try:
            keep: list[str] = []
            for rel in listed:
                p = out / rel
                if not remove_previous:
                    keep.append(rel)
                    continue
                if p.is_file() and not p.is_symlink():
                    p.unlink()
                    parent = p.parent
                    if parent != out and parent.is_dir() and not any(parent.iterdir()):
                        parent.rmdir()
                elif p.exists() or p.is_symlink():
                    keep.append(rel)  # not a plain file any more: not ours to remove
            body = "".join(rel + "\n" for rel in dict.fromkeys([*keep, *files]))
            tmp = out / (self.marker + ".tmp")
            tmp.write_text(_MARKER_HEAD + body, encoding="utf-8")
            tmp.replace(out / self.marker)
        except OSError as exc:
            raise RunFolderError(f"--out {out}: cannot prepare the folder "
                                 f"({exc.filename or out}: {exc.strerror or exc})") from exc
        return out

    def __enter__(self) -> OwnedFolder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def release(self) -> None:
        """Drop the lock (idempotent)."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def abandon(self) -> None:
        """Drop the lock and remove the folders :meth:`take` created, if they are empty."""
        self.release()
        _remove_empty(self._created)


def _remove_empty(folders: tuple[Path, ...]) -> None:
    """Remove ``folders`` (deepest first) while they are empty."""
    for folder in folders:
        try:
            folder.rmdir()
        except FileNotFoundError:
            continue  # a mkdir that failed made not all of them
        except OSError:
            return


def claim_run_folder(out: Path | None, name: str, seed: int, runs_root: Path = RUNS_ROOT,
                     suffix: str = "", next_free: bool = False) -> OwnedFolder:
    """Lock the folder a run writes into (nothing changed yet; :meth:`OwnedFolder.prepare`
    then readies it); RunFolderError when it cannot be used.

    ``out`` None: :func:`default_run_folder`, which must stay under ``runs_root``; with
    ``next_free`` a default folder in use gives way to ``<name>-2``, ``-3``, ... A folder that
    exists is used only when it is empty or a previous run's (it holds :data:`RUN_MARKER`); a
    symbolic link, a file, a path under a file or an unwritable place is refused with the path
    named, and a folder another process holds is refused."""
    if out is not None:
        return OwnedFolder.take(Path(out), RUN_MARKER, "run")
    root = Path(runs_root).resolve()
    for k in range(1, _DEFAULT_TRIES + 1 if next_free else 2):
        cand = default_run_folder(name, seed, runs_root, suffix if k == 1 else f"{suffix}-{k}")
        if cand.resolve().parent != root:
            raise RunFolderError(f"run folder {cand} is not directly under {runs_root}")
        try:
            return OwnedFolder.take(cand, RUN_MARKER, "run")
        except FolderInUse:
            if not next_free:
                raise
    first = default_run_folder(name, seed, runs_root, suffix)
    raise RunFolderError(f"the default run folder {first} and its {_DEFAULT_TRIES - 1} next "
                         f"ones are in use: pass --out")
