"""The run folder: trace.jsonl written as the run goes, camera snapshots, summary.json.

Nothing is lost when a run crashes midway: every trace line is flushed when written, and the
summary is written in a ``finally`` by the runner with ``status`` "crashed" and what is known.
The trace holds simulated-time data only, so its SHA-256 (``trace_sha256``) is the same for the
same scenario and seed over any transport and at any speed.
"""

from __future__ import annotations

import hashlib
import json
import math
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


class TraceWriter:
    """One JSON event per line, sorted keys, flushed per line; hashes exactly what it writes."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fh = self.path.open("w", encoding="utf-8")
        self._sha = hashlib.sha256()
        self.lines = 0

    def write(self, event: dict) -> None:
        """Append one event (must carry ``t_us`` and ``ev``)."""
        if "t_us" not in event or "ev" not in event:
            raise ValueError(f"trace event needs t_us and ev: {event!r}")
        line = _LINE_ENCODER.encode(_clean(event)) + "\n"
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


def read_trace(path: Path) -> list[dict]:
    """All events of a trace file (a torn last line from a crash is skipped)."""
    events = []
    with Path(path).open(encoding="utf-8") as fh:
        for line in fh:
            try:
                events.append(json.loads(line))
            except json.JSONDecodeError:
                break
    return events


def write_summary(path: Path, summary: dict) -> None:
    """summary.json, written atomically (temp file + rename) so a reader never sees half."""
    path = Path(path)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(_clean(summary), indent=2, sort_keys=True) + "\n")
    tmp.replace(path)


def _points(result: Any) -> list[tuple[int, int]]:
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
                pts.extend(_points(value))
    elif isinstance(result, list):
        for item in result:
            pts.extend(_points(item))
    return pts


def draw_detection(rgb: np.ndarray, results: dict | None, label: str) -> np.ndarray:
    """BGR image for a PNG: the frame, a cross at every detected point, and a caption."""
    img = cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2BGR)
    for name, result in (results or {}).items():
        colour = (0, 255, 0) if result is not None else (0, 0, 255)
        for u, v in _points(result):
            cv2.drawMarker(img, (u, v), colour, cv2.MARKER_CROSS, 12, 1)
        if result is None:
            cv2.putText(img, f"{name}: none", (4, img.shape[0] - 6), cv2.FONT_HERSHEY_PLAIN,
                        0.8, colour, 1)
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
