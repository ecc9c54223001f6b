"""Suite-wide test settings.

Hypothesis runs derandomized: the same examples on every run and every machine, so a red CI is a
real regression and never a lucky draw (docs/cosim.md: determinism; tests never depend on the
machine). Explore with fresh randomness locally by `HYPOTHESIS_PROFILE=explore pytest ...`.
"""

import os
import sys

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


# Modules marked ``pytestmark = pytest.mark.both_mcus`` run every test on each MCU backend: the
# module's ``Mcu`` is the Python model for ``python`` and the C firmware for ``native``.
def pytest_generate_tests(metafunc):
    if metafunc.definition.get_closest_marker("both_mcus") is not None:
        metafunc.fixturenames.append("mcu_backend")
        metafunc.parametrize("mcu_backend", ["python", "native"], indirect=True)


@pytest.fixture
def mcu_backend(request):
    return request.param


@pytest.fixture(autouse=True)
def _mcu_of_the_backend(request, monkeypatch):
    # a fixture appended to fixturenames in pytest_generate_tests is parametrized but never set
    # up, so the module's Mcu is swapped here, from the test's parameters
    callspec = getattr(request.node, "callspec", None)
    if callspec is not None and callspec.params.get("mcu_backend") == "native":
        from mobigrasp.mcu_sim.native.mcu import NativeMcu

        monkeypatch.setattr(request.module, "Mcu", NativeMcu)


# three short in-process runs (one per method) whose run folders several output tests read
SHORT_RUNS = {"paper000-exp1": None, "paper001-sim1": 8.0, "paper002-marker": 8.0}


@pytest.fixture(scope="session")
def short_runs(tmp_path_factory):
    """{scenario: run folder} of SHORT_RUNS (time limits in simulated s; None: the scenario's)."""
    from mobigrasp.tools.run_job import RunOptions, execute

    root = tmp_path_factory.mktemp("short-runs")
    folders = {}
    for name, limit_s in SHORT_RUNS.items():
        folders[name] = root / name
        summary, _ = execute(RunOptions(scenario=name, transport="inproc", out=folders[name],
                                        progress=False, time_limit_s=limit_s))
        assert_no_false_claim(summary)
    return folders


def assert_no_false_claim(summary: dict) -> None:
    """A run that ended DONE without the object in the gripper fails the test (docs/task.md)."""
    assert not summary.get("false_claim"), (
        f"{summary.get('scenario')} seed {summary.get('seed')}: false claim of success "
        f"({summary.get('task_state')}, {summary.get('end_reason')}, grasped "
        f"{summary.get('grasped')})")


@pytest.fixture(autouse=True)
def _no_false_claim(request, monkeypatch):
    """Every test that runs a scenario through tools.run_job.execute fails on a false claim."""
    run_job = sys.modules.get("mobigrasp.tools.run_job")
    if run_job is None:
        return
    real = run_job.execute

    def checked(*args, **kwargs):
        summary, code = real(*args, **kwargs)
        assert_no_false_claim(summary)
        return summary, code

    monkeypatch.setattr(run_job, "execute", checked)
    if getattr(request.module, "execute", None) is real:
        monkeypatch.setattr(request.module, "execute", checked)
