"""Recording the frame corpus: each scenario run in process with the corpus's stage timer and
planner watcher (calib/corpus.py describes the folder, calib/plan_corpus.py its planning part).
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2

from mobigrasp.calib import corpus, plan_corpus, program
from mobigrasp.host.vision.registry import DETECTORS
from mobigrasp.services.run_job import RunOptions, execute, host_config, resolve_scenario


def record(out: Path, scenarios: list[str], time_limit_s: float | None = None,
           progress: Callable[[int, int, str], None] | None = None) -> dict:
    """Run each scenario in process and write the corpus to ``out``; returns the index.
    ``progress(done, total, what)`` after each scenario (tools.progress.StepProgress)."""
    out = Path(out)
    corpus.prepare(out)
    index: dict = {"format": corpus.FORMAT, "scenarios": [], "frames": []}
    planning: list = []
    for k, name in enumerate(scenarios):
        rec = corpus.FrameRecorder(set(DETECTORS))
        cam = host_config(resolve_scenario(name)[1])["camera"]
        # the camera parameters the detectors were built with (host/app_factory.py rounds them)
        camera = {k: int(round(cam[k])) for k in ("f_px", "u0_px", "v0_px")}
        with tempfile.TemporaryDirectory(prefix="mobigrasp-corpus-") as tmp, \
                plan_corpus.tap_planners(plan_corpus.PlanRecorder()) as plans:
            summary, _ = execute(RunOptions(scenario=name, transport="inproc",
                                            out=Path(tmp) / "run", progress=False,
                                            plots=False, time_limit_s=time_limit_s,
                                            timer=rec))
        sc_name = summary["scenario"]
        plan_corpus.write_run(out, sc_name, plans, planning)
        (out / sc_name).mkdir(exist_ok=True)
        for i, (sha, entry) in enumerate(rec.frames.items()):
            rel = f"{sc_name}/{i:05d}.png"
            # PNG stores the array's bytes as they are (OpenCV reads back the same order)
            if not cv2.imwrite(str(out / rel), rec.pixels[sha]):
                raise corpus.CorpusError(f"{out / rel}: could not write the frame")
            index["frames"].append({"file": rel, "scenario": sc_name, **entry})
        index["scenarios"].append({"name": sc_name, "seed": summary["seed"], "camera": camera,
                                   "calls": rec.calls, "frames": len(rec.frames),
                                   "trace_sha256": summary.get("trace_sha256")})
        if progress is not None:
            progress(k + 1, len(scenarios), f"{sc_name}: {len(rec.frames)} frames, "
                     f"{rec.calls} detector calls, {len(plans.calls)} planner calls")
    plan_corpus.write_index(out, planning)
    (out / corpus.INDEX).write_text(json.dumps(index, indent=1, sort_keys=True) + "\n")
    return index


def record_steps(scenario: str, time_limit_s: float | None = None) -> program.Recording:
    """Run ``scenario`` in process with the Python host program and a calib/program.py
    ``Recorder`` on its interface: what the C program is replayed with (``mobigrasp
    calibrate``'s whole control steps and frame pipelines), with the configuration the run
    gave its host (``time_limit_s`` bounds SEARCH there too)."""
    cfg = host_config(resolve_scenario(scenario)[1], time_limit_s)
    rec = program.Recorder()
    with tempfile.TemporaryDirectory(prefix="mobigrasp-steps-") as tmp:
        summary, _ = execute(RunOptions(scenario=scenario, transport="inproc",
                                        out=Path(tmp) / "run", progress=False, plots=False,
                                        mcap=False, time_limit_s=time_limit_s, recorder=rec))
    return program.Recording(summary["scenario"], cfg, rec.calls, summary.get("trace_sha256"))
