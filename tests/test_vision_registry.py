"""The detector table (host/vision/registry.py) is what every list of detectors reads."""

import numpy as np
import pytest

from mobigrasp.host import app_factory
from mobigrasp.host.task import DETECTORS as STATE_DETECTORS
from mobigrasp.host.vision import cost_report, registry


def _frame() -> np.ndarray:
    rng = np.random.default_rng(3)
    return rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)


@pytest.mark.parametrize("name", sorted(registry.DETECTORS))
def test_each_row_resolves_and_returns_its_own_result_type(name):
    row = registry.DETECTORS[name]
    assert row.name == name and row.call in registry.CALLS
    kind = row.result_type()
    assert kind.__dataclass_params__.frozen
    res, ops = row.host_call(_frame(), (611, 160, 120), (0, 0, -1571, 0, 0, 0))
    assert res is None or isinstance(res, kind)
    assert ops.time_us() >= row.min_ops_fn()(240, 320).time_us()
    with pytest.raises(TypeError, match=name):
        registry.check(name, {"u_q4": 1})


def test_host_app_cost_report_and_states_read_the_table():
    assert list(app_factory._detectors({}, [])) == list(registry.DETECTORS)
    assert set(app_factory.vision_bounds(registry.DETECTORS)) == set(registry.DETECTORS)
    for states in STATE_DETECTORS.values():
        for names in states.values():
            assert all(registry.row(n) for n in names)
    rep, results = cost_report.frame_cost(_frame(), list(registry.DETECTORS))
    assert set(results) == set(registry.DETECTORS)
    assert [s.name for s in rep.stages][0] == "grey"
    with pytest.raises(ValueError, match="unknown detector"):
        registry.row("nope")
