"""A grasp again after a grasp check with no evidence, on held-out generator v3 scenes run in
process (docs/task.md "The task's claim of success", a grasp again on a new sighting only):
the grasp went where the camera did not see the object, the retry's look sees nothing either,
so the task searches instead of repeating the same blind grasp, finds the object and grasps it,
without a contact."""

from __future__ import annotations

import json

import pytest

from mobigrasp.host.task.grasp import REGRASP_UNSEEN


def _run_v3(tmp_path, method: str, seed: int) -> list:
    """The v3 scene of ``method`` and ``seed`` run in process: DONE without a contact; its
    state events."""
    from mobigrasp.services.random_scenarios import random_scenario
    from mobigrasp.services.run_job import RunOptions, execute

    scenario = random_scenario(method, seed, "v3")
    out = tmp_path / "run"
    summary, code = execute(RunOptions(scenario=f"random-v3-{method}-{seed}",
                                       scenario_obj=scenario, transport="inproc", out=out,
                                       plots=False, mcap=False, progress=False))
    assert summary["success"] and code == 0, (summary["task_state"], summary["end_reason"])
    assert summary["contacts"] == 0 and not summary["false_claim"]
    events = (json.loads(line) for line in (out / "trace.jsonl").open())
    return [e for e in events if e.get("ev") == "state"]


@pytest.mark.slow
@pytest.mark.parametrize("method, seed", [
    # odometry 110 mrad and 216 mm off after the start's turn (5 % slip): the object 0.46 rad
    # aside of the look from the grasp circle, ADJUST closed in blind on the estimate
    ("001", 2066),
    # the cylinder dragged 144 mm across the view after its last sighting in the approach
    ("002", 2071)])
def test_no_blind_grasp_again(tmp_path, method, seed):
    states = _run_v3(tmp_path, method, seed)
    misses = [e for e in states if e["from"] == "LIFT" and e["to"] == "ADJUST"]
    assert len(misses) == 1 and "no evidence" in misses[0]["why"]
    lost = [e for e in states if e["to"] == "LOST" and e["why"] == REGRASP_UNSEEN]
    assert len(lost) == 1 and misses[0]["t_us"] < lost[0]["t_us"]
    grasps = [e for e in states if e["to"] == "LIFT"]
    assert len(grasps) == 2 and grasps[1]["t_us"] > lost[0]["t_us"]  # on the new sighting
