"""002 from a close start (generator v3 seed 1086, the cylinder 0.3-0.5 m away): the approach
finds the cylinder cut by the bottom of the frame where the crosses place it at the grasp's
reach, backs off, reads the rings and grasps, without a contact (in process; docs/task.md
"Close starts")."""

from __future__ import annotations

import json
import math

import pytest

from mobigrasp.services.random_scenarios import random_scenario
from mobigrasp.services.run_job import RunOptions, execute


def _run_close_start(tmp_path, seed: int) -> tuple[dict, list[dict]]:
    """v3 002 ``seed`` (a close start) run in process: its summary, having succeeded without a
    contact, and its trace's events."""
    scenario = random_scenario("002", seed, "v3")
    assert math.hypot(scenario.target.x_m, scenario.target.y_m) < 0.5  # a close start
    summary, code = execute(RunOptions(scenario=f"random-v3-002-{seed}", scenario_obj=scenario,
                                       transport="inproc", out=tmp_path / "run", plots=False,
                                       mcap=False, progress=False))
    assert summary["success"] and code == 0, (summary["task_state"], summary["end_reason"])
    assert summary["contacts"] == 0
    return summary, [json.loads(line) for line in (tmp_path / "run" / "trace.jsonl").open()]


@pytest.mark.slow
def test_a_cut_cylinder_is_backed_off_from_and_grasped(tmp_path):
    _, events = _run_close_start(tmp_path, 1086)
    back_offs = [e["back_off"] for e in events if e.get("ev") == "detail" and "back_off" in e]
    assert back_offs and back_offs[0]["n"] == 1
    into_adjust = [e["why"] for e in events if e.get("ev") == "state" and e["to"] == "ADJUST"]
    assert into_adjust and into_adjust[-1].startswith("red cylinder seen, d_pixel")  # its rings


@pytest.mark.slow
def test_an_oblique_board_places_the_cylinder_in_view(tmp_path):
    """v3 seed 1063: the crosses seen ~0.87 rad off the board's face. The board's plane places
    the cylinder before its face (the frontal model put it 0.2 m aside, at the post, and ADJUST
    turned away from it): ADJUST turns to it, its rings stop the base by d_pixel > T_d, and the
    grasp holds it, without a contact."""
    _, events = _run_close_start(tmp_path, 1063)
    states = [e for e in events if e.get("ev") == "state"]
    assert states[1]["to"] == "ADJUST" and states[1]["why"].startswith("crosses")
    assert states[2]["to"] == "ROUGH_GRASP" and states[2]["why"].startswith("stop rule")
