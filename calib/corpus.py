"""The frame corpus: the frames the host's detectors were given in scenario runs, on disk.

A corpus folder holds ``corpus.json`` and one PNG per distinct frame (lossless; the pixel bytes
read back equal the bytes the detector got). Frames are recorded (services/corpus.py) by running
each scenario in process with a stage timer (HostApp's ``timer`` hook), which sees every detector
call with its arguments: the frame and, for the pose-reading detectors, the joint angles snapshot.
The timer only calls the detector, so the run and its trace are those of ``mobigrasp run``; a
scenario and seed give the same corpus every time.

``corpus.json``: ``{"format": FORMAT, "scenarios": [{"name", "seed", "camera", "calls"}],
"frames": [{"file", "scenario", "shape", "sha256", "calls": [{"detector", "args"}]}]}`` where a
frame's ``calls`` are the distinct (detector, arguments) it was given to, in order of first call.

Beside them, ``planning.json`` and ``planning/``: every Bezier planner call of the runs
(calib/plan_corpus.py).
"""

from __future__ import annotations

import hashlib
import json
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from mobigrasp.calib import plan_corpus

FORMAT = "mobigrasp-corpus/1"
INDEX = "corpus.json"


class CorpusError(ValueError):
    """A corpus folder that cannot be read or written: the message names the file and key."""


@dataclass(frozen=True)
class Call:
    """One detector call of the corpus: its frame, the arguments after the frame and the
    camera parameters (f_px, u0_px, v0_px) the detector was built with."""

    scenario: str
    frame_file: str
    detector: str
    args: tuple
    camera: tuple[int, int, int]


class FrameRecorder:
    """HostApp stage timer that keeps every distinct detector call of one run."""

    def __init__(self, detectors: set[str]) -> None:
        self.detectors = detectors
        self.frames: dict[str, dict] = {}  # sha256 -> entry (in order of first use)
        self.pixels: dict[str, np.ndarray] = {}
        self.calls = 0

    def __call__(self, stage: str, fn, *args):
        if stage in self.detectors and args and isinstance(args[0], np.ndarray):
            rgb = args[0]
            sha = hashlib.sha256(np.ascontiguousarray(rgb).tobytes()).hexdigest()
            entry = self.frames.get(sha)
            if entry is None:
                entry = {"sha256": sha, "shape": list(rgb.shape), "calls": []}
                self.frames[sha] = entry
                self.pixels[sha] = np.array(rgb, copy=True)
            call = {"detector": stage, "args": _plain(args[1:])}
            self.calls += 1
            if call not in entry["calls"]:
                entry["calls"].append(call)
        return fn(*args)


def _plain(v: Any) -> Any:
    if isinstance(v, (tuple, list)):
        return [_plain(x) for x in v]
    if isinstance(v, np.integer):
        return int(v)
    return v


def prepare(out: Path) -> None:
    """Create ``out`` or clear a corpus made before; refuse a file or a foreign folder."""
    if out.exists() and not out.is_dir():
        raise CorpusError(f"{out}: --out is a file, not a folder")
    if out.is_dir() and any(out.iterdir()):
        index = out / INDEX
        if not index.is_file():
            raise CorpusError(f"{out}: not empty and has no {INDEX}: refusing to write into it")
        old = read_index(out)
        for sc in old["scenarios"]:  # only the folders this command made
            d = out / sc["name"]
            if d.is_dir():
                shutil.rmtree(d)
        try:
            plan_corpus.clear(out)
        except plan_corpus.PlanCorpusError as exc:
            raise CorpusError(str(exc)) from exc
        index.unlink()
    out.mkdir(parents=True, exist_ok=True)


def read_index(folder: Path) -> dict:
    """The checked ``corpus.json`` of ``folder``; CorpusError naming the file and key."""
    path = Path(folder) / INDEX
    try:
        data = json.loads(path.read_bytes().decode("utf-8"))
    except FileNotFoundError as exc:
        raise CorpusError(f"{path}: no corpus index (make one with mobigrasp corpus)") from exc
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CorpusError(f"{path}: not a JSON corpus index ({exc})") from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise CorpusError(f"{path}: key 'format' is not {FORMAT!r}")
    for key in ("scenarios", "frames"):
        if not isinstance(data.get(key), list):
            raise CorpusError(f"{path}: key {key!r} must be a list")
    for i, fr in enumerate(data["frames"]):
        if not isinstance(fr, dict) or not isinstance(fr.get("file"), str) \
                or not isinstance(fr.get("calls"), list):
            raise CorpusError(f"{path}: key 'frames[{i}]' needs 'file' and 'calls'")
        if Path(fr["file"]).is_absolute() or ".." in Path(fr["file"]).parts:
            raise CorpusError(f"{path}: key 'frames[{i}].file' leaves the corpus folder")
    return data


def load_frame(folder: Path, entry: dict) -> np.ndarray:
    """The pixels of one corpus frame, checked against its recorded hash."""
    path = Path(folder) / entry["file"]
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None or img.ndim != 3 or img.shape[2] != 3:
        raise CorpusError(f"{path}: not a 3-channel PNG frame")
    if hashlib.sha256(img.tobytes()).hexdigest() != entry.get("sha256"):
        raise CorpusError(f"{path}: pixels differ from key 'sha256' of its index entry")
    return img


def calls(folder: Path, index: dict) -> list[Call]:
    """Every (frame, detector, arguments) of the corpus, in index order."""
    cams = {}
    for sc in index["scenarios"]:
        cam = sc.get("camera") if isinstance(sc, dict) else None
        if not isinstance(cam, dict) or not all(isinstance(cam.get(k), int)
                                                for k in ("f_px", "u0_px", "v0_px")):
            raise CorpusError(f"{Path(folder) / INDEX}: key 'scenarios[].camera' needs integer "
                              f"f_px, u0_px, v0_px")
        cams[sc["name"]] = (cam["f_px"], cam["u0_px"], cam["v0_px"])
    out = []
    for fr in index["frames"]:
        if fr.get("scenario") not in cams:
            raise CorpusError(f"{Path(folder) / INDEX}: frame {fr['file']}: key 'scenario' "
                              f"names no scenario of the index")
        for c in fr["calls"]:
            out.append(Call(fr["scenario"], fr["file"], c["detector"], tuple(
                tuple(a) if isinstance(a, list) else a for a in c.get("args", [])),
                cams[fr["scenario"]]))
    return out
