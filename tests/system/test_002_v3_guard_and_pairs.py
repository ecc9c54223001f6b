"""002 on two generator v3 scenes (in process; docs/task.md "002: the false pairs of crosses
and the sonar guard's drive out"): a vertical pair of "crosses" far from the board does not
start ADJUST (seed 1049), and the approach looks back at the cylinder after the sonar guard
drove the base out of R_r rather than going LOST (seed 1054, whose drive out leaves the base
facing away from it). Both grasp, without a contact."""

from __future__ import annotations

import json

import pytest

from mobigrasp.services.random_scenarios import random_scenario
from mobigrasp.services.run_job import RunOptions, execute


def _run_v3(tmp_path, seed: int) -> list[dict]:
    """v3 002 ``seed`` run in process, having succeeded without a contact: its trace's events."""
    summary, code = execute(RunOptions(scenario=f"random-v3-002-{seed}",
                                       scenario_obj=random_scenario("002", seed, "v3"),
                                       transport="inproc", out=tmp_path / "run", plots=False,
                                       mcap=False, progress=False))
    assert summary["success"] and code == 0, (summary["task_state"], summary["end_reason"])
    assert summary["contacts"] == 0
    return [json.loads(line) for line in (tmp_path / "run" / "trace.jsonl").open()]


@pytest.mark.slow
def test_a_pair_far_from_level_does_not_start_adjust(tmp_path):
    events = _run_v3(tmp_path, 1049)
    pairs = [e["results"]["double_cross"] for e in events if e.get("ev") == "detect"
             and (e["results"].get("double_cross") or {}).get("d_pixel_q4", 0) >= 75 * 16]
    assert any(4 * abs(p["v2_q4"] - p["v1_q4"]) > p["u2_q4"] - p["u1_q4"] for p in pairs)
    into_adjust = [e["why"] for e in events if e.get("ev") == "state" and e["to"] == "ADJUST"]
    assert into_adjust and not any(why.startswith("crosses") for why in into_adjust)


@pytest.mark.slow
def test_the_approach_looks_back_after_the_sonar_guard(tmp_path):
    events = _run_v3(tmp_path, 1054)
    guard = [e["t_us"] for e in events if e.get("ev") == "detail" and "sonar_guard" in e]
    looks = [e["t_us"] for e in events if e.get("ev") == "detail" and "look_back" in e]
    assert guard and looks and looks[0] > guard[0]
    assert not [e for e in events if e.get("ev") == "state" and e["to"] == "LOST"]
