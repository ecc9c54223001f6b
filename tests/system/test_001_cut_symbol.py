"""001 searching for an object it came too near to read (generator v3, in process; docs/task.md
"001: away from a symbol cut by the frame", "001: away from an estimate too near to be read"):
the look before the grasp does not see it, the search after the loss sees the radial symbol
only cut by the frame's border, or not at all, the base faces away, drives off it (or off the
estimate), turns back, reads it and the object is grasped, without a contact."""

from __future__ import annotations

import json

import pytest


def _cut_then_read(events: list, back_offs: list) -> None:
    cut_frames = [e for e in events if e.get("ev") == "detect"
                  and (e.get("results") or {}).get("radial_cut")]
    assert back_offs and cut_frames and cut_frames[0]["t_us"] <= back_offs[0]["t_us"]
    lost = [e["t_us"] for e in events if e.get("ev") == "state" and e["to"] == "LOST"]
    assert lost and lost[0] < back_offs[0]["t_us"]  # a search after a loss near the object
    found = [e for e in events if e.get("ev") == "state" and e["from"] == "SEARCH"
             and e["why"].startswith("radial symbol seen")]
    assert found and found[0]["t_us"] > back_offs[-1]["t_us"]


@pytest.mark.slow
def test_a_close_start_whose_look_missed_the_object(close_start_done):
    """Seed 1011: the object 0.35 m from the start, its given place approached on odometry;
    the look at 0.13 m saw no pair (the turn's slip put it 44 mm aside)."""
    events, back_offs = close_start_done("001", 1011)
    _cut_then_read(events, back_offs)


def _run_v3_001(tmp_path, seed: int) -> list:
    """The v3 001 scene of ``seed`` run in process: DONE without a contact; its events."""
    from mobigrasp.services.random_scenarios import random_scenario
    from mobigrasp.services.run_job import RunOptions, execute

    scenario = random_scenario("001", seed, "v3")
    out = tmp_path / "run"
    summary, code = execute(RunOptions(scenario=f"random-v3-001-{seed}", scenario_obj=scenario,
                                       transport="inproc", out=out, plots=False, mcap=False,
                                       progress=False))
    assert summary["success"] and code == 0, (summary["task_state"], summary["end_reason"])
    assert summary["contacts"] == 0
    return [json.loads(line) for line in (out / "trace.jsonl").open()]


@pytest.mark.slow
def test_an_arrival_drifted_off_the_object_behind_obstacles(tmp_path):
    """Seed 1009: 2.2 m behind a box and a short wall, 5 % wheel slip: the curve ends on the grasp
    circle by odometry, 0.57 m from the object; the search after the look reads it only cut."""
    events = _run_v3_001(tmp_path, 1009)
    _cut_then_read(events, [e for e in events if e.get("ev") == "detail" and "back_off" in e])


@pytest.mark.slow
def test_an_object_never_read_whole_within_arms_length(tmp_path):
    """Held-out seed 2088: the turn on the spot at the start (5 % slip) left odometry 156 mrad
    off, the object 0.6 rad aside of the look from the grasp circle; the search where ADJUST
    stopped sees it cut in a few frames only. Its look-around over, the base moves off the
    estimate, reads the symbol whole and the object is grasped (docs/task.md "001: away from
    an estimate too near to be read")."""
    events = _run_v3_001(tmp_path, 2088)
    moves = [e for e in events if e.get("ev") == "detail" and "back_off_unseen" in e]
    lost = [e["t_us"] for e in events if e.get("ev") == "state" and e["to"] == "LOST"]
    found = [e["t_us"] for e in events if e.get("ev") == "state" and e["from"] == "SEARCH"
             and e["why"].startswith("radial symbol seen")]
    assert len(moves) == 1 and lost and found and lost[0] < moves[0]["t_us"] < found[0]
