"""The C host program equals the Python one on random scenes: generator v2's seeds of the
acceptance campaign (docs/cosim.md, seeds 1000 onward) give the same trace_sha256 and the same
summary (the outcome, the world's figures, the BYE's) with ``--host c`` as with ``--host python``
(in process; one seed a method over the pty too). Random scenes reach what the shipped scenarios
do not: the search when the object is lost, the board alone, faults, obstacles under the sonar
guard.

Every method of the task is a row of the test; one the C program's table has not fails at
once, naming it (services/loop_campaign.run_campaign refuses the campaign: "method NNN is not
in the C host yet")."""

import json
from pathlib import Path

import pytest

from mobigrasp.host.task import METHODS
from mobigrasp.services.loop_campaign import LoopCampaign, run_campaign
from mobigrasp.services.run_job import RunOptions, execute

EQUAL_SEEDS = 30  # per method, generator v2 from seed 1000, as the acceptance campaign
# what differs by nature: the host's name, the wall clock, the path of each campaign's copy of
# the scene
NOT_COMPARED = ("host", "wall_time_s", "wall_host_s", "realtime_factor", "scenario_file")


def _campaign(tmp_path, method: str, host: str) -> dict[int, dict]:
    cfg = LoopCampaign(methods=(method,), runs=EQUAL_SEEDS, out=tmp_path / host, version="v2",
                       transport="inproc", jobs=1, host=host)
    return {row["seed"]: row for row in run_campaign(cfg)["rows"]}


@pytest.mark.slow
# 60 whole runs one at a time, and one over the pty: tens of minutes on two busy cores
@pytest.mark.timeout(3 * 3600)
@pytest.mark.parametrize("method", sorted(METHODS))
def test_random_scenes_same_trace_in_the_c_host(tmp_path, method):
    c_rows = _campaign(tmp_path, method, "c")  # first: a method not in the C fails at once
    py_rows = _campaign(tmp_path, method, "python")
    assert sorted(c_rows) == sorted(py_rows) == list(range(1000, 1000 + EQUAL_SEEDS))
    differ = []
    for seed, py in sorted(py_rows.items()):
        c = c_rows[seed]
        assert py["trace_sha256"], (seed, py["error"])
        # the whole summary: trace, outcome, world figures, the BYE's figures and budget
        want, got = (json.loads((Path(r["folder"]) / "summary.json").read_text())
                     for r in (py, c))
        keys = sorted(k for k in want.keys() | got.keys()
                      if k not in NOT_COMPARED and want.get(k) != got.get(k))
        if keys:
            differ.append(f"seed {seed}: {', '.join(keys)} differ (python "
                          f"{py['trace_sha256'][:16]} {py['task_state']}, c "
                          f"{str(c['trace_sha256'])[:16]} {c['task_state']} {c['error'] or ''};"
                          f" {c['folder']} against {py['folder']})")
    assert not differ, f"method {method}: " + "; ".join(differ)
    # over the pty too: the program as its own process gives the same trace
    seed = min(py_rows)
    pty, _ = execute(RunOptions(scenario=py_rows[seed]["scene"], transport="pty", host="c",
                                out=tmp_path / "c-pty", progress=False, plots=False,
                                mcap=False))
    assert pty["trace_sha256"] == py_rows[seed]["trace_sha256"], (seed, pty.get("error"))
