"""summary.json's claim fields: claimed_success (the host ended DONE), grasped (world truth),
false_claim (DONE without the object held at the end); the suite fails a run with a false claim."""

from types import SimpleNamespace

import pytest
from conftest import assert_no_false_claim

from mobigrasp.cosim.summary import figures as _figures


def _summary(state: str, held: bool, grasps: int) -> dict:
    res = SimpleNamespace(host_stats={}, end_us=1_000_000, wall_s=1.0, host_state=state,
                          state_enter_us={}, state_durations_us={}, reason="task_done",
                          error=None)
    plant = SimpleNamespace(final=lambda: {
        "grasped": held, "grasps": grasps, "grasp_us": None, "final_error_mm": None,
        "collisions": {}, "min_obstacle_clearance_m": None, "path_length_m": 0.0})
    trace = SimpleNamespace(sha256=lambda: "0" * 64, lines=0)
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
