"""The ARM9 budget verdict of a run: did the host's work fit the S3C2440 (docs/budget.md)?

From the host's figures (:meth:`mobigrasp.host.app.HostApp.stats`): control deadlines missed,
frames dropped because vision was still busy with an earlier one (frames the task asked for no
detector on are not dropped, they are idle), the stage nearest its budget (control stages
against the 20 ms control period, vision stages against the 66.7 ms frame period), the load.
The run fits when no deadline was missed, no frame was dropped for lack of time and every stage
stayed within its budget.
"""

from __future__ import annotations

CONTROL_BUDGET_US = 20_000
FRAME_BUDGET_US = 1_000_000 // 15  # 15 frames a second
CONTROL_STAGES = ("control", "protocol", "task")


def stage_budget_us(stage: str) -> int:
    """The budget a stage's worst call is set against."""
    return CONTROL_BUDGET_US if stage in CONTROL_STAGES else FRAME_BUDGET_US


def budget_block(host_stats: dict) -> dict:
    """summary.json's ``budget``: deadline_misses, frames_dropped_busy, worst_stage,
    worst_stage_ms, worst_stage_budget_ms, control_step_max_ms, load_mean, load_max, fits and
    the verdict in words. Stages with no call are not considered."""
    stages = {k: v for k, v in (host_stats.get("stages") or {}).items() if v.get("calls")}
    worst, share = None, 0.0
    for name, st in sorted(stages.items()):
        s = st["max_us"] / stage_budget_us(name)
        if worst is None or s > share:
            worst, share = name, s
    misses = int(host_stats.get("deadline_misses", 0))
    dropped = int(host_stats.get("frames_dropped", 0))
    ctl = stages.get("control", {}).get("max_us", 0)
    block = {
        "deadline_misses": misses, "frames_dropped_busy": dropped,
        "worst_stage": worst,
        "worst_stage_ms": None if worst is None else stages[worst]["max_us"] / 1000,
        "worst_stage_budget_ms": None if worst is None else stage_budget_us(worst) / 1000,
        "control_step_max_ms": ctl / 1000,
        "load_mean": float(host_stats.get("arm9_load_mean", 0.0)),
        "load_max": float(host_stats.get("arm9_load_max", 0.0)),
        "fits": misses == 0 and dropped == 0 and share <= 1.0,
    }
    block["verdict"] = verdict(block)
    return block


def verdict(block: dict) -> str:
    """"fits: worst control step 8.1 ms of 20 ms", or what did not fit."""
    head = (f"worst control step {block['control_step_max_ms']:.1f} ms of "
            f"{CONTROL_BUDGET_US // 1000} ms")
    if block["fits"]:
        return f"fits: {head}"
    why = []
    if block["deadline_misses"]:
        why.append(f"{block['deadline_misses']} control deadlines missed")
    if block["frames_dropped_busy"]:
        why.append(f"{block['frames_dropped_busy']} frames dropped while busy")
    if block["worst_stage"] is not None and block["worst_stage_ms"] > block[
            "worst_stage_budget_ms"]:
        why.append(f"{block['worst_stage']} {block['worst_stage_ms']:.1f} ms of "
                   f"{block['worst_stage_budget_ms']:.1f} ms")
    return f"does not fit: {', '.join(why)}; {head}"
