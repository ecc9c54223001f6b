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


def test_a_toy_detector_row_reaches_the_cost_report_the_host_app_and_the_task(monkeypatch):
    """Adding a detector is its own module plus one row (docs/architecture.md, "Adding a
    detector")."""
    from mobigrasp.host.kinematics import PAPER_000
    from mobigrasp.host.task.sense import CAMERA_000, object_in_platform

    row = registry.DetectorRow("bright_spot", "toy_detector", "detect_bright_spot",
                               "BrightSpot", uses_grey=False)
    monkeypatch.setitem(registry.DETECTORS, "bright_spot", row)
    rgb = np.zeros((240, 320, 3), np.uint8)
    rgb[100, 200] = 255
    # the cost report runs it and charges its counts as one stage
    rep, results = cost_report.frame_cost(rgb, ["bright_spot"])
    assert [s.name for s in rep.stages] == ["bright_spot"]
    assert rep.stages[0].ops == row.min_ops_fn()(240, 320)
    assert (results["bright_spot"].u_q4, results["bright_spot"].v_q4) == (3200, 1600)
    # the host app has it, with its modelled-time bound
    app = app_factory.build_host_app({"method": "000"})
    assert "bright_spot" in app.detectors
    res, ops = app.detectors["bright_spot"](rgb)
    assert res == results["bright_spot"] and ops == rep.stages[0].ops
    assert app_factory.vision_bounds(["bright_spot"])["bright_spot"](240, 320) == \
        row.min_ops_fn()(240, 320).time_us()
    # and its result becomes a target of the task through the module's sighting
    p = object_in_platform("bright_spot", res, PAPER_000, (0, 0, 0, 0, 0, 0), CAMERA_000)
    assert p is not None and abs(p[1] / 16 - (281.5 + 500)) < 2
    with pytest.raises(TypeError, match="bright_spot"):
        object_in_platform("bright_spot", results["bright_spot"].__dict__, PAPER_000,
                           (0,) * 6, CAMERA_000)


def test_a_shared_front_end_is_within_what_each_of_its_detectors_charges():
    shared = app_factory.front_ends(registry.DETECTORS)
    # the 000 detectors start from one front end (grey, dark mask, components); 002's do not
    assert sorted(shared) == ["dual_plus", "radial_cut", "radial_symbol", "spoke"]
    assert len({ref for ref, _ in shared.values()}) == 1
    for name, (_, us) in shared.items():
        row = registry.DETECTORS[name]
        assert 0 < us(240, 320) <= row.min_ops_fn()(240, 320).time_us()
        _, ops = row.host_call(_frame(), (611, 160, 120), (0, 0, -1571, 0, 0, 0))
        assert us(240, 320) <= ops.time_us()
