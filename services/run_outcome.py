"""The short cause of a campaign run's end (a row of ``bench loop``'s campaign): what its figure
counts and its failure list names."""

from __future__ import annotations


def outcome(row: dict) -> str:
    """A short cause of the run's end, for the figure and the failure list."""
    if row["false_claim"]:
        return "false claim"
    if row["status"] in ("raised", "crashed"):
        return "crashed"
    if row["contacts"] and row["success"]:
        return "success with contact"
    if row["success"]:
        return "success"
    if not row["graspable"] and row["task_state"] == "FAILED":
        return "board alone: FAILED"
    if row["end_reason"] == "time_limit":
        return f"time limit in {row['task_state']}"
    reason = str(row.get("reason") or "no reason given")
    return f"{row['task_state']}: {reason.split(' (')[0].split(':')[0][:40]}"
