"""The figures of a run's summary.json, from the session result, the plant's ground truth, the
trace and the snapshots (docs/cosim.md, "The run folder")."""

from __future__ import annotations

from typing import Any

from mobigrasp.host.budget_verdict import budget_block


def world_figures(fin: dict) -> dict:
    """What the world says of a run, whoever the host was: the grasp, the final error, the
    contacts and the path (from the plant's ``final()``)."""
    grasp_us = fin.get("grasp_us")
    contact_s = fin.get("contact_time_s") or {}
    obstacle = int(fin["collisions"].get("obstacle", 0))
    target = int(fin["collisions"].get("target", 0))
    return {
        "grasped": bool(fin["grasped"] or fin["grasps"]),
        "time_to_grasp_s": grasp_us / 1e6 if grasp_us is not None else None,
        "final_error_mm": fin.get("final_error_mm"),
        # contact episodes of the base (docs/task.md "The run's counts"): none is the grasp's,
        # so every one counts, with obstacles and marker posts and with the target
        "contacts": obstacle + target,
        "contacts_obstacle": obstacle,
        "contacts_target": target,
        "contact_time_s": round(float(contact_s.get("obstacle", 0.0))
                                + float(contact_s.get("target", 0.0)), 3),
        "min_clearance_m": fin["min_obstacle_clearance_m"],
        "path_length_m": fin["path_length_m"],
        "stand_still_max_s": fin.get("stand_still_max_s"),
    }


def figures(res: Any, plant: Any, trace: Any, snaps: Any, limit_s: float) -> dict:
    """The summary's figures from the session's result, the plant's truth and the run folder."""
    fin = plant.final()
    hs = (res.host_stats if res else {}) or {}
    proto = hs.get("protocol", {})
    mcu_t = hs.get("mcu", {})
    end_us = res.end_us if res else 0
    wall = res.wall_s if res else 0.0
    state = res.host_state if res else "INIT"
    claimed = state == "DONE"
    success = claimed and bool(fin["grasped"])  # DONE with the object held at the end
    enter = res.state_enter_us if res else {}
    return {
        "success": success, **world_figures(fin), "task_state": state,
        # the host ended DONE; a DONE without the object in the gripper at the end (world
        # truth) is a false claim
        "claimed_success": claimed, "false_claim": claimed and not fin["grasped"],
        "end_reason": res.reason if res else "crashed",
        "replans": int(hs.get("replans", 0)),
        "path_updates": int(hs.get("path_updates", 0)),
        "grasp": {"close_reason": hs.get("close_reason"),
                  "circle_error_mm": hs.get("circle_error_mm"),
                  "alpha_rad": (None if fin.get("close_alpha_rad") is None
                                else round(fin["close_alpha_rad"], 4)),
                  "final_error_mm": fin.get("final_error_mm")},
        "frames_captured": int(hs.get("frames_received", 0)),
        "frames_processed": int(hs.get("frames_processed", 0)),
        "frames_dropped": int(hs.get("frames_dropped", 0)),
        "deadline_misses": int(hs.get("deadline_misses", 0)),
        "arm9_load_max": hs.get("arm9_load_max", 0.0),
        "arm9_load_mean": hs.get("arm9_load_mean", 0.0),
        "sim_time_s": end_us / 1e6, "time_limit_s": limit_s,
        "wall_time_s": wall, "realtime_factor": (end_us / 1e6 / wall) if wall > 0 else None,
        "protocol": {"tx_frames": proto.get("tx_frames", 0),
                     "rx_frames": proto.get("rx_frames", 0),
                     "crc_errors": proto.get("crc_errors", 0),
                     "retransmits": proto.get("retransmits", 0),
                     "watchdog_trips": mcu_t.get("watchdog_trips", 0),
                     "nacks": proto.get("nacks", 0),
                     "rejected_outputs": proto.get("rejected_outputs", 0)},
        "state_durations_s": {k: v / 1e6 for k, v in
                              (res.state_durations_us if res else {}).items()},
        "state_enter_s": {k: v / 1e6 for k, v in enter.items()},
        "snapshots": snaps.written,
        "trace_sha256": trace.sha256(), "trace_lines": trace.lines,
        "trace_dropped_events": trace.dropped_events,
        "host_steps": {k: hs.get(k) for k in ("control_steps", "ticks_skipped", "frames_idle")},
        "stages": hs.get("stages", {}),
        "budget": budget_block(hs),
        "error": res.error if res and res.error else None,
    }
