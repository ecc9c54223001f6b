"""The profiler's tables: a run's host stages against their ARM9 budgets (host/budget_verdict.py),
and the calibrated kernels' modelled time against their emulated time (``mobigrasp profile``,
docs/budget.md). The stage nearest its budget is the one with the highest worst-case share.
"""

from __future__ import annotations

import time

from mobigrasp.host.budget_verdict import FRAME_BUDGET_US, stage_budget_us


class WallTimer:
    """``timer(stage, fn, *args)`` hook for HostApp: calls fn and records its wall time."""

    def __init__(self) -> None:
        self.wall_s: dict[str, list[float]] = {}

    def __call__(self, stage, fn, *args):
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            self.wall_s.setdefault(stage, []).append(time.perf_counter() - t0)


def profile_table(stages: dict, wall_s: dict) -> tuple[list[dict], str | None]:
    """Rows per stage and the name of the stage with the highest worst-case budget share."""
    rows = []
    for name, st in sorted(stages.items()):
        budget = stage_budget_us(name)
        wall = wall_s.get(name, [])
        rows.append({
            "stage": name, "calls": st["calls"], "arm9_mean_us": round(st["mean_us"], 1),
            "arm9_p95_us": st["p95_us"], "arm9_max_us": st["max_us"], "budget_us": budget,
            "share_mean": round(st["mean_us"] / budget, 4),
            "share_max": round(st["max_us"] / budget, 4),
            "wall_mean_ms": round(1e3 * sum(wall) / len(wall), 3) if wall else None,
        })
    for name, wall in sorted(wall_s.items()):  # wall-only stages (the task step's Python)
        if name not in stages:
            rows.append({"stage": name + " (python)", "calls": len(wall),
                         "wall_mean_ms": round(1e3 * sum(wall) / len(wall), 3)})
    ranked = [r for r in rows if "share_max" in r and r["calls"]]
    first = max(ranked, key=lambda r: r["share_max"])["stage"] if ranked else None
    return rows, first


def calibration_rows(cal: dict | None, used: set[str] | None = None
                     ) -> tuple[list[dict], str | None]:
    """Per calibrated kernel (those in ``used`` when given: the run's): modelled µs now (at
    the calibrated frame size), the emulated figures of the last calibration and the ratio;
    and the kernel whose emulated maximum takes the largest share of the frame budget."""
    if not cal or not isinstance(cal.get("stages"), dict):
        return [], None
    from mobigrasp.calib.calibrate import PLANNING_STAGES, modelled_us

    h, w = cal.get("frame_shape") or (0, 0)  # none: a corpus of planner calls only
    rows = []
    for name, st in sorted(cal["stages"].items(), key=lambda kv: (kv[0] in PLANNING_STAGES,
                                                                   kv[0])):
        if used is not None and name not in used:
            continue
        try:
            if not h:
                raise KeyError(name)
            mod = modelled_us(name, h, w)
        except KeyError:  # a detector's stage: its cost depends on the frame, as calibrated
            mod = st.get("modelled_median_us")
            if not isinstance(mod, int | float):
                continue
        emu = st["emulated_median_us"]
        rows.append({"stage": name, "kind": "planning" if name in PLANNING_STAGES else "frame",
                     "modelled_us": round(mod, 1), "emulated_median_us": emu,
                     "emulated_p95_us": st["emulated_p95_us"],
                     "emulated_max_us": st["emulated_max_us"],
                     "ratio": round(mod / emu, 3) if emu else None,
                     "share_max": round(st["emulated_max_us"] / FRAME_BUDGET_US, 4)})
    first = max(rows, key=lambda r: r["share_max"])["stage"] if rows else None
    return rows, first
