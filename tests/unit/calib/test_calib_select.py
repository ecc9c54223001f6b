"""Which corpus frames and planner calls a calibration times: per scenario, spread evenly, and
only those of the scenarios asked for."""

from __future__ import annotations

from mobigrasp.calib.calibrate import STAGES, select_frames, select_plans

DETECTOR = next(d for s in STAGES for d in s.detectors)


def _index(per: dict[str, int]) -> dict:
    return {"frames": [{"scenario": sc, "file": f"{sc}/{k}.png",
                        "calls": [{"detector": DETECTOR}]}
                       for sc, n in per.items() for k in range(n)]}


def test_frames_are_spread_evenly_per_scenario():
    got = select_frames(_index({"a": 10, "b": 3}), 4)
    assert [f["file"] for f in got] == ["a/0.png", "a/2.png", "a/5.png", "a/7.png",
                                        "b/0.png", "b/1.png", "b/2.png"]
    assert len(select_frames(_index({"a": 10, "b": 3}), None)) == 13


def test_frames_without_a_timed_detector_are_left_out():
    index = _index({"a": 2})
    index["frames"][0]["calls"] = [{"detector": "no-such-detector"}]
    assert [f["file"] for f in select_frames(index, None)] == ["a/1.png"]


def test_only_the_scenarios_asked_for():
    index = _index({"a": 10, "b": 3, "c": 5})
    got = select_frames(index, 2, {"b", "c"})
    assert [f["file"] for f in got] == ["b/0.png", "b/1.png", "c/0.png", "c/2.png"]
    calls = {"calls": [{"scenario": sc, "file": f"{sc}{k}"} for sc in "abc" for k in range(3)]}
    assert [c["file"] for c in select_plans(calls, None, {"a"})] == ["a0", "a1", "a2"]
    assert len(select_plans(calls, 1, None)) == 3
