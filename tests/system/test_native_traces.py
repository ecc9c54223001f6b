"""The shipped scenarios give the same trace_sha256 with the C firmware as with the Python model
(in process here; all six, in process and over the pty, in the slow test)."""

import pytest

from mobigrasp.services.run_job import RunOptions, execute
from mobigrasp.tools.check_trace_baseline import SCENARIOS


def _sha(tmp_path, name, mcu, transport="inproc", limit_s=None):
    summary, _ = execute(RunOptions(scenario=name, transport=transport, mcu=mcu, speed=None,
                                    out=tmp_path / f"{name}-{mcu}-{transport}", progress=False,
                                    plots=False, time_limit_s=limit_s))
    assert not summary.get("error"), summary.get("error")
    assert summary["mcu_backend"] == mcu
    return summary["trace_sha256"]


def test_short_run_same_trace_on_both_backends(tmp_path):
    assert _sha(tmp_path, "paper002-marker", "native", limit_s=5.0) == \
        _sha(tmp_path, "paper002-marker", "python", limit_s=5.0)


def test_unknown_backend_is_bad_input(tmp_path):
    from mobigrasp.services.run_job import BadInput

    with pytest.raises(BadInput, match="--mcu must be one of native, python"):
        _sha(tmp_path, "paper002-marker", "fpga")


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENARIOS)
def test_shipped_scenario_same_trace(tmp_path, name):
    python = _sha(tmp_path, name, "python", limit_s=200.0)
    assert _sha(tmp_path, name, "native", limit_s=200.0) == python
    assert _sha(tmp_path, name, "native", transport="pty", limit_s=200.0) == python
