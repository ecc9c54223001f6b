import json
import os
import subprocess
import sys

import numpy as np
import pytest

from mobigrasp.calib import corpus
from mobigrasp.calib import plan_corpus as pc
from mobigrasp.services.corpus import record


@pytest.fixture(scope="module")
def plan_folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("plancorpus")
    record(out, ["paper000-exp1", "paper001-sim1"], time_limit_s=3.0)
    return out


def test_both_planners_are_recorded_and_replay_to_the_same_plan(plan_folder):
    idx = pc.read_index(plan_folder)
    assert {c["planner"] for c in idx["calls"]} == {"000", "001"}
    for call in idx["calls"]:
        arrays = pc.load_arrays(plan_folder, call)
        assert arrays["ctrl"].shape == (call["result"]["candidates"], 4, 3)
        plan = pc.replay(call)  # the recorded inputs are the whole input of the planner
        assert plan.reason == call["result"]["reason"]
        assert plan.ops.cycles() == call["result"]["cycles"]
        assert np.array_equal(plan.candidates.ctrl, arrays["ctrl"])
        assert [pc.REASONS[r] for r in arrays["reasons"]] == list(plan.candidates.reasons)
        np.testing.assert_array_equal(plan.candidates.cost, arrays["cost"])
        best = call["result"]["best"]
        if best is not None:
            assert (plan.best_candidate.u, plan.best_candidate.endpoint) == \
                (best["u"], best["endpoint"])
            assert plan.best_candidate.cost == best["cost"]


def test_planning_corpus_is_reproducible_and_cleared_with_the_corpus(plan_folder, tmp_path):
    again = tmp_path / "again"
    record(again, ["paper000-exp1", "paper001-sim1"], time_limit_s=3.0)
    a = json.loads((plan_folder / pc.INDEX).read_text())
    b = json.loads((again / pc.INDEX).read_text())
    assert a == b
    for call in a["calls"]:
        x, y = pc.load_arrays(plan_folder, call), pc.load_arrays(again, call)
        assert x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x)
    (again / "keep.txt").write_text("mine")
    record(again, ["paper000-exp1"], time_limit_s=1.0)  # before any plan
    assert pc.read_index(again)["calls"] == []
    assert not (again / pc.FOLDER).exists()
    assert (again / "keep.txt").read_text() == "mine"


def test_the_tap_watches_the_planners_only_inside_its_block():
    from mobigrasp.host.planning import bezier000

    rec = pc.PlanRecorder()
    with pc.tap_planners(rec):
        plan = bezier000.plan_000((0.0, 0.0), (0.0, 0.0), (1.0, 0.5))
    bezier000.plan_000((0.0, 0.0), (0.0, 0.0), (1.0, 0.5))
    assert len(rec.calls) == 1
    planner, inputs, kept = rec.calls[0]
    assert planner == "000" and kept is plan
    assert inputs["target_xy_m"] == (1.0, 0.5) and inputs["start_vel_xy_mps"] == (0.0, 0.0)


@pytest.mark.parametrize("text", [b"\xff", b"{}", b'{"format": "mobigrasp-planning/1", '
                                  b'"calls": []}', b'{"format": "mobigrasp-planning/2", '
                                  b'"calls": [{"file": "../x", "planner": "000", "inputs": {}}]}'])
def test_a_bad_planning_index_is_refused_naming_it(tmp_path, text):
    (tmp_path / pc.INDEX).write_bytes(text)
    with pytest.raises(pc.PlanCorpusError, match="planning.json"):
        pc.read_index(tmp_path)


@pytest.mark.parametrize("broken", ["index", "arrays"])
def test_calibrate_refuses_a_broken_planning_corpus_naming_the_file(tmp_path, broken):
    (tmp_path / corpus.INDEX).write_text(json.dumps({"format": corpus.FORMAT, "scenarios": [],
                                                      "frames": []}))
    call = {"file": "planning/x/0000.npz", "scenario": "x", "planner": "000",
            "inputs": {"params": {}}, "result": {"n_samples": 8}}
    (tmp_path / pc.INDEX).write_text(
        "{not json" if broken == "index"
        else json.dumps({"format": pc.FORMAT, "calls": [call]}))
    (tmp_path / "planning" / "x").mkdir(parents=True)
    (tmp_path / "planning" / "x" / "0000.npz").write_bytes(b"not an npz")
    r = subprocess.run([sys.executable, "-m", "mobigrasp", "calibrate", "--corpus",
                        str(tmp_path), "--quiet", "--json", str(tmp_path / "cal.json")],
                       capture_output=True, text=True, timeout=600,
                       env={**os.environ, "XDG_CACHE_HOME": str(tmp_path / "c")})
    assert r.returncode == 2 and "Traceback" not in r.stderr
    name = "planning.json" if broken == "index" else "0000.npz"
    assert name in r.stderr and len(r.stderr.strip().splitlines()) == 1
