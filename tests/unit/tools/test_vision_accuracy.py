"""Issue 6's accuracy thresholds on a small fixed set of rendered frames per detector.

The full runs (>= 1000 frames per detector) are ``mobigrasp bench vision --frames 1000``. Here:
60 clean target frames, 20 degraded ones (noise 8, 2 px blur, brightness ±30 %) and 40
target-free frames with clutter, fixed seed. With 60 frames, "detection >= 99 %" means all 60
and "false positives <= 0.1 %" means none. Detectors not written yet are skipped.
"""
import pytest

pytest.importorskip("mobigrasp.mcu_sim.world.camera")
va = pytest.importorskip("mobigrasp.tools.vision_accuracy")

FAST = ["double_cross", "red_cylinder"]
SLOW = ["radial_symbol", "dual_plus", "spoke"]  # the 000 detectors: slower frames


def _check(name: str) -> None:
    fig = va.evaluate(name, frames=60, seed=20261126, empty_frames=40, degraded_frames=20)
    if not fig["available"]:
        pytest.skip(f"{name}: {fig['why']}")
    assert fig["detection_rate"] >= 0.99, fig
    assert fig["wrong_results"] == 0, fig
    assert fig["false_positive_rate"] <= 0.001, fig
    assert fig["degraded_detection_rate"] >= 0.95, fig
    if fig["dist_err_median_pct"] is not None:
        assert fig["dist_err_median_pct"] <= 2.0, fig
        assert fig["dist_err_p95_pct"] <= 5.0, fig
    assert fig["bearing_err_p95_deg"] <= 0.5, fig
    assert fig["arm9_ms_max"] <= 33.0, fig  # modelled ARM9 time per frame, half the budget


@pytest.mark.parametrize("name", FAST)
def test_002_detectors_meet_issue_6(name):
    _check(name)


@pytest.mark.slow
@pytest.mark.parametrize("name", SLOW)
def test_000_detectors_meet_issue_6(name):
    _check(name)


def test_meets_and_table():
    fig = {"detector": "x", "range": "r", "detection_rate": 0.995, "false_positive_rate": 0.002,
           "dist_err_median_pct": 1.0, "dist_err_p95_pct": 6.0, "bearing_err_p95_deg": 0.1,
           "degraded_detection_rate": 0.9, "wall_ms_p50": 2.0, "arm9_ms_max": 40.0}
    assert va.meets(fig) == {"detection_rate": True, "false_positive_rate": False,
                             "dist_err_median_pct": True, "dist_err_p95_pct": False,
                             "bearing_err_p95_deg": True, "degraded_detection_rate": False,
                             "wall_ms_p50": True, "arm9_ms_max": False}
    text = va.table([fig | {"wrong_results": 0, "bearing_err_max_deg": 0.2}])
    assert "99.5%" in text and "x" in text
