"""summary.json's claim fields: claimed_success (the host ended DONE), grasped (world truth),
false_claim (DONE without the object held at the end); the suite fails a run with a false claim."""

from types import SimpleNamespace

import pytest
from conftest import assert_no_false_claim

from mobigrasp.cosim.summary import figures as _figures
from mobigrasp.services.run_job import execute  # by name, as the scenario tests import it


def _summary(state: str, held: bool, grasps: int) -> dict:
    res = SimpleNamespace(host_stats={}, end_us=1_000_000, wall_s=1.0, host_state=state,
                          state_enter_us={}, state_durations_us={}, reason="task_done",
                          error=None)
    plant = SimpleNamespace(final=lambda: {
        "grasped": held, "grasps": grasps, "grasp_us": None, "final_error_mm": None,
        "collisions": {}, "min_obstacle_clearance_m": None, "path_length_m": 0.0})
    trace = SimpleNamespace(sha256=lambda: "0" * 64, lines=0, dropped_events=0)
    return _figures(res, plant, trace, SimpleNamespace(written=0), 10.0)


@pytest.mark.parametrize(("state", "held", "grasps", "claimed", "false"), [
    ("DONE", True, 1, True, False),
    ("DONE", False, 0, True, True),  # closed on air, said DONE
    ("DONE", False, 1, True, True),  # held once, dropped, still said DONE
    ("FAILED", False, 0, False, False),
    ("FAILED", True, 1, False, False),
])
def test_claim_fields(state, held, grasps, claimed, false):
    s = _summary(state, held, grasps)
    assert s["claimed_success"] is claimed and s["false_claim"] is false
    assert s["success"] is (claimed and not false)
    if false:
        with pytest.raises(AssertionError, match="false claim"):
            assert_no_false_claim(s)
    else:
        assert_no_false_claim(s)


def test_execute_is_checked_in_every_test_also_when_imported_late():
    from conftest import checked_execute

    from mobigrasp.services import run_job
    from mobigrasp.services.run_job import execute  # imported by name inside a test

    assert execute is run_job.execute and execute.__wrapped__ is not None
    liar = checked_execute(lambda opts: (_summary("DONE", False, 0), 0))
    with pytest.raises(AssertionError, match="false claim"):
        liar(None)
    honest = checked_execute(lambda opts: (_summary("FAILED", False, 0), 1))
    assert honest(None)[1] == 1


def test_execute_imported_by_name_at_the_top_of_a_test_module_is_checked():
    from mobigrasp.services import run_job

    assert execute is run_job.execute and execute.__wrapped__ is not None


def test_run_folders_made_elsewhere_are_read_for_false_claims(tmp_path):
    """A run in a subprocess or another worker writes only its summary.json; the suite reads
    those under the test's tmp_path after the test (tests/conftest.py)."""
    import json

    from conftest import false_claims_under

    for name, state, held in (("a", "DONE", True), ("b", "FAILED", False)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "summary.json").write_text(json.dumps(_summary(state, held, 1)))
    (tmp_path / "torn").mkdir()
    (tmp_path / "torn" / "summary.json").write_text('{"false_cl')
    assert false_claims_under(tmp_path) == []
    (tmp_path / "c" / "deep").mkdir(parents=True)
    lie = tmp_path / "c" / "deep" / "summary.json"
    lie.write_text(json.dumps(_summary("DONE", False, 0)))
    claims = false_claims_under(tmp_path)
    assert len(claims) == 1 and str(lie) in claims[0] and "DONE without the object" in claims[0]
    lie.unlink()  # else this test's own teardown fails it, as it should for a real run


def test_a_false_claim_written_by_any_run_fails_the_test_that_made_it(tmp_path,
                                                                     tmp_path_factory):
    """The suite's own conftest, on a test whose 'run' (a subprocess, say) left a summary.json
    of a false claim in its tmp_path: that test errors; an honest one passes."""
    import json
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    suite = tmp_path / "suite"
    suite.mkdir()
    shutil.copy(Path(__file__).resolve().parents[1] / "conftest.py", suite / "conftest.py")
    lie, honest = _summary("DONE", False, 0), _summary("FAILED", False, 0)
    (suite / "test_inner.py").write_text(
        "import json\n"
        f"def test_lying_run(tmp_path):\n    (tmp_path / 'summary.json').write_text("
        f"{json.dumps(json.dumps(lie))})\n"
        f"def test_honest_run(tmp_path):\n    (tmp_path / 'summary.json').write_text("
        f"{json.dumps(json.dumps(honest))})\n")
    inner = tmp_path_factory.mktemp("inner")  # outside this test's tmp_path
    ran = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                          "--basetemp", str(inner), "--rootdir", str(suite), str(suite)],
                         capture_output=True, text=True, timeout=120, cwd=suite)
    assert ran.returncode == 1, ran.stdout + ran.stderr
    assert "2 passed, 1 error" in ran.stdout, ran.stdout  # the lie passes its body, not after
    assert "ERROR at teardown of test_lying_run" in ran.stdout and "false claim" in ran.stdout
