"""The planning corpus: every Bezier planner call of the scenario runs, beside the frame corpus.

While :func:`mobigrasp.services.corpus.record` runs a scenario, :func:`tap_planners` watches
the two planners the host's task calls (000's ``plan_000``, 001's ``plan_001``) through the hook
the host offers (host/planning/observe.py). The recorder keeps each call's arguments and the
Plan it returned and changes neither, so the run and its trace are those of ``mobigrasp run``.

Files (in the corpus folder, beside ``corpus.json``):

- ``planning.json``: ``{"format": FORMAT, "calls": [{"file", "scenario", "planner", "inputs",
  "result"}]}``; ``inputs`` are the planner's arguments (positions, velocity, heading, target,
  the sonar ranges, the parameters and, for 001, the remembered regions), ``result`` the reason,
  samples, stride, modelled ARM9 cycles and the chosen candidate (u, end point, cost, length,
  ∫κ, clearance) or null. Floats are written by ``repr`` (they read back bit for bit).
- ``planning/<scenario>/<k>.npz``: the candidate set of call k: control points ``ctrl``
  (N, 4, 3), ``reasons`` (codes of :data:`REASONS`), ``us``, ``endpoints``, ``cost``,
  ``length``, ``kint``, ``clearance``; for 001 also the regions of the plan (``regions``:
  ox, oy (1/16 mm), lo, hi (µrad), η, R_r (1/16 mm), arc bound per row, integers).
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from mobigrasp.host.planning import bezier_q

FORMAT = "mobigrasp-planning/2"  # 2: the regions in integers (1/16 mm, µrad)
INDEX = "planning.json"
FOLDER = "planning"
# reason codes (the C kernels' codes too, hostc/bezier.h)
REASONS = bezier_q.REASONS  # the C's codes (hostc/bezier.h)


class PlanCorpusError(ValueError):
    """A planning corpus that cannot be read: the message names the file and key."""


def _plain(v: Any) -> Any:
    if dataclasses.is_dataclass(v) and not isinstance(v, type):
        return {f.name: _plain(getattr(v, f.name)) for f in dataclasses.fields(v)}
    if isinstance(v, np.ndarray):
        return [_plain(x) for x in v.tolist()]
    if isinstance(v, (tuple, list)):
        return [_plain(x) for x in v]
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return f if math.isfinite(f) else None
    return v


def region_rows(regions) -> np.ndarray:
    """(R, 7) int64: ox, oy (1/16 mm), lo, hi (µrad), η, R_r (1/16 mm), arc bound (0/1) of
    InfeasibleRegions."""
    return np.array([[r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4, r.r_r_q4,
                      int(r.arc_bound)] for r in regions], dtype=np.int64).reshape(-1, 7)


def rows_to_regions(rows: np.ndarray) -> list:
    """The InfeasibleRegions of :func:`region_rows`."""
    from mobigrasp.host.planning.sonar_regions import InfeasibleRegion

    return [InfeasibleRegion(*(int(v) for v in r[:6]), bool(r[6]))
            for r in np.asarray(rows).reshape(-1, 7)]


class PlanRecorder:
    """Keeps every planner call of one run: (planner, inputs, Plan)."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, dict, Any]] = []

    def __call__(self, planner: str, args: tuple, kw: dict, plan: Any) -> None:
        """The watcher (host/planning/observe.py): keep the call's inputs by name and its plan."""
        names = {"000": ("start_xy_m", "start_vel_xy_mps", "target_xy_m", "params",
                         "heading_rad"),
                 "001": ("start_xy_m", "start_vel_xy_mps", "heading_rad", "target_xy_m",
                         "sonar_mm", "params", "known_regions")}[planner]
        inputs = dict(zip(names, args, strict=False))
        inputs.update(kw)
        self.calls.append((planner, inputs, plan))


def tap_planners(rec: PlanRecorder):
    """Record the planner calls of the host's task while the block runs."""
    from mobigrasp.host.planning.observe import watching

    return watching(rec)


def _inputs_json(planner: str, inputs: dict) -> dict:
    from mobigrasp.host.planning.bezier000 import Params000
    from mobigrasp.host.planning.bezier001 import Params001

    out = {}
    for k, v in inputs.items():
        if k == "known_regions":
            out[k] = region_rows(v or []).tolist()
        else:
            out[k] = _plain(v)
    if "params" not in out:  # the planner's default
        out["params"] = _plain(Params000() if planner == "000" else Params001())
    return out


def write_run(out: Path, scenario: str, rec: PlanRecorder, index: list) -> None:
    """The calls of one run into ``out/planning/<scenario>/`` and onto ``index``."""
    if rec.calls:
        (Path(out) / FOLDER / scenario).mkdir(parents=True, exist_ok=True)
    for k, (planner, inputs, plan) in enumerate(rec.calls):
        rel = f"{FOLDER}/{scenario}/{k:04d}.npz"
        c = plan.candidates
        arrays = {"ctrl": np.asarray(c.ctrl, np.float64).reshape(-1, 4, 3),
                  "reasons": np.array([REASONS.index(r) for r in c.reasons], np.int8),
                  "us": np.asarray(c.us, np.int64), "endpoints": np.asarray(c.endpoints,
                                                                            np.int64),
                  "cost": np.asarray(c.cost, np.float64), "length": np.asarray(c.length,
                                                                               np.float64),
                  "kint": np.asarray(c.kint, np.float64),
                  "clearance": np.asarray(c.clearance, np.float64)}
        if planner == "001":
            arrays["regions"] = region_rows(plan.extra.get("regions", []))
        with open(Path(out) / rel, "wb") as fh:
            np.savez(fh, **arrays)
        best = plan.best_candidate
        result = {"reason": plan.reason, "n_samples": int(plan.n_samples),
                  "stride": int(plan.stride), "cycles": int(plan.ops.cycles()),
                  "candidates": len(c),
                  "best": None if best is None else _plain(
                      {"u": best.u, "endpoint": best.endpoint, "cost": best.cost,
                       "length_m": best.length_m, "kappa_integral": best.kappa_integral,
                       "clearance_m": best.clearance_m}),
                  "extra": {k: _plain(v) for k, v in plan.extra.items() if k != "regions"}}
        index.append({"file": rel, "scenario": scenario, "planner": planner,
                      "inputs": _inputs_json(planner, inputs), "result": result})


def write_index(out: Path, calls: list) -> None:
    """``planning.json`` of the calls written by :func:`write_run`."""
    (Path(out) / INDEX).write_text(json.dumps({"format": FORMAT, "calls": calls}, indent=1,
                                              sort_keys=True) + "\n")


def clear(out: Path) -> None:
    """Remove the planning files this module wrote in ``out`` (nothing else)."""
    import shutil

    index = Path(out) / INDEX
    if index.is_file():
        for c in read_index(out)["calls"]:
            p = Path(out) / c["file"]
            if p.is_file():
                p.unlink()
        index.unlink()
    folder = Path(out) / FOLDER
    if folder.is_dir():
        for d in sorted(folder.iterdir()):
            if d.is_dir() and not any(d.iterdir()):
                d.rmdir()
        if not any(folder.iterdir()):
            shutil.rmtree(folder)


def read_index(folder: Path) -> dict:
    """The checked ``planning.json`` of ``folder``."""
    path = Path(folder) / INDEX
    try:
        data = json.loads(path.read_bytes().decode("utf-8"))
    except FileNotFoundError as exc:
        raise PlanCorpusError(f"{path}: no planning index (make one with mobigrasp corpus)") \
            from exc
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise PlanCorpusError(f"{path}: not a JSON planning index ({exc})") from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise PlanCorpusError(f"{path}: key 'format' is not {FORMAT!r}")
    if not isinstance(data.get("calls"), list):
        raise PlanCorpusError(f"{path}: key 'calls' must be a list")
    for i, c in enumerate(data["calls"]):
        if not isinstance(c, dict) or c.get("planner") not in ("000", "001") \
                or not isinstance(c.get("file"), str) or not isinstance(c.get("inputs"), dict) \
                or not isinstance(c["inputs"].get("params"), dict) \
                or not isinstance(c.get("result"), dict) \
                or not isinstance(c["result"].get("n_samples"), int):
            raise PlanCorpusError(f"{path}: key 'calls[{i}]' needs 'file', 'planner' (000 or "
                                  f"001), 'inputs' with 'params' and 'result' with 'n_samples'")
        p = Path(c["file"])
        if p.is_absolute() or ".." in p.parts:
            raise PlanCorpusError(f"{path}: key 'calls[{i}].file' leaves the corpus folder")
    return data


def load_arrays(folder: Path, call: dict) -> dict[str, np.ndarray]:
    """The candidate arrays of one call."""
    path = Path(folder) / call["file"]
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise PlanCorpusError(f"{path}: not a planning call's arrays ({exc})") from exc


def params_of(call: dict):
    """The Params000 / Params001 of a recorded call."""
    from mobigrasp.host.planning.bezier000 import Params000
    from mobigrasp.host.planning.bezier001 import Params001
    from mobigrasp.host.planning.grasp_circle import ArmGeometry001
    from mobigrasp.host.planning.sonar_regions import SonarConfig

    p = dict(call["inputs"]["params"])
    if call["planner"] == "000":
        return Params000(**p)
    p["sonar"] = SonarConfig(**p["sonar"])
    p["arm"] = ArmGeometry001(**p["arm"])
    return Params001(**p)


def replay(call: dict):
    """Run the recorded call's planner again on its recorded inputs; the Plan."""
    from mobigrasp.host.planning.bezier000 import plan_000
    from mobigrasp.host.planning.bezier001 import plan_001

    i = call["inputs"]
    params = params_of(call)
    if call["planner"] == "000":
        return plan_000(i["start_xy_m"], i["start_vel_xy_mps"], i["target_xy_m"], params,
                        heading_rad=i.get("heading_rad"))
    return plan_001(i["start_xy_m"], i["start_vel_xy_mps"], i["heading_rad"], i["target_xy_m"],
                    i["sonar_mm"], params, known_regions=rows_to_regions(
                        np.asarray(i.get("known_regions") or [], np.float64)))
