"""000 whose wander leg is stopped by the object itself (generator v3 seed 2083, never used for
tuning; the target 2.5 m away): the symbol shows only cut by the frame's bottom just before a
front sonar stops the leg; the base faces the cut, looks there at rest, reads the symbol and
grasps the object in time, without a contact; ``--host c`` gives the same trace (in process;
docs/task.md "000: a ring's leg stopped by an obstacle")."""

from __future__ import annotations

import json

import pytest

from mobigrasp.services.random_scenarios import random_scenario
from mobigrasp.services.run_job import RunOptions, execute


@pytest.mark.slow
def test_a_leg_stopped_by_the_object_looks_at_it_and_the_c_host_agrees(tmp_path):
    scenario = random_scenario("000", 2083, "v3")
    runs = {}
    for host in ("python", "c"):
        out = tmp_path / host
        summary, code = execute(RunOptions(scenario="random-v3-000-2083", scenario_obj=scenario,
                                           transport="inproc", host=host, out=out, plots=False,
                                           mcap=False, progress=False))
        runs[host] = summary
        assert summary["success"] and code == 0, (host, summary["task_state"],
                                                  summary["end_reason"])
        assert summary["contacts"] == 0 and not summary["false_claim"]
    assert runs["c"]["trace_sha256"] == runs["python"]["trace_sha256"]
    events = [json.loads(line) for line in (tmp_path / "python" / "trace.jsonl").open()]
    look = next(e for e in events if e.get("ev") == "detail" and "wander_look_mrad" in e)
    seen = next(e for e in events if e.get("ev") == "state" and e["to"] == "APPROACH")
    assert look["wander_blocked"] is True and look["t_us"] < seen["t_us"] < look["t_us"] + 10**7
