"""000 with its target far from the start (generator v3 seed 1069, 4.2 m away): the look-around
sees nothing, the wander drives the first ring and the radial symbol is read from the last
ring (its legs sweeping outward alone); the object is grasped within the scene's 180 s, without
a contact (in process; docs/task.md "000: the sweep while driving")."""

from __future__ import annotations

import json
import math

import pytest

from mobigrasp.services.random_scenarios import random_scenario
from mobigrasp.services.run_job import RunOptions, execute


@pytest.mark.slow
def test_a_target_beyond_the_first_ring_is_found_and_grasped_in_time(tmp_path):
    scenario = random_scenario("000", 1069, "v3")
    assert math.hypot(scenario.target.x_m, scenario.target.y_m) > 4.0  # the far band
    out = tmp_path / "000-1069"
    summary, code = execute(RunOptions(scenario="random-v3-000-1069", scenario_obj=scenario,
                                       transport="inproc", out=out, plots=False, mcap=False,
                                       progress=False))
    assert summary["success"] and code == 0, (summary["task_state"], summary["end_reason"])
    assert summary["contacts"] == 0 and not summary["false_claim"]
    events = [json.loads(line) for line in (out / "trace.jsonl").open()]
    legs = [e for e in events if e.get("ev") == "detail" and "wander_mm" in e]
    seen = [e for e in events if e.get("ev") == "state" and e["to"] == "APPROACH"]
    assert len(legs) > 12 and seen and seen[0]["t_us"] > legs[12]["t_us"]  # from the last ring
