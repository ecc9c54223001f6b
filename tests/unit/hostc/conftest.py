"""The shipped scenarios several hostc replay tests record: each run once a session, with every
test's recorder attached at once (each fills its own list and only reads the run), instead of
once per test file. The replays only read what was recorded."""

from __future__ import annotations

import pytest


def _paper001() -> dict:
    from test_hostc_plan001 import record_plans
    from test_hostc_replan import record_replans
    from test_hostc_task001 import record001_steps

    return {"plans": record_plans, "replans": record_replans, "task": record001_steps}


def _paper002_marker() -> dict:
    from test_hostc_task import record002, record002_approach
    from test_hostc_task_states import record_steps

    return {"calls": record002, "approach": record002_approach, "steps": record_steps}


def _paper000_exp1() -> dict:
    from test_hostc_task000 import record000
    from test_hostc_task_states import record_steps

    return {"calls": record000, "steps": record_steps}


# scenario -> its recorders by name
SHARED = {"paper000-exp1": _paper000_exp1, "paper001-sim1": _paper001,
          "paper001-sim2": _paper001, "paper002-marker": _paper002_marker}


@pytest.fixture(scope="session")
def shared_recording(tmp_path_factory):
    """``get(scenario, name)``: what recorder ``name`` recorded in the session's one run of
    ``scenario`` (made at the first ``get``)."""
    from test_hostc_task import recorded_runs

    runs: dict[str, dict[str, list]] = {}

    def get(scenario: str, name: str) -> list:
        if scenario not in runs:
            runs[scenario] = recorded_runs(tmp_path_factory.mktemp(scenario), scenario,
                                           SHARED[scenario]())
        return runs[scenario][name]
    return get
