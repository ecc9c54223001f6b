"""summary.json's budget block and its verdict in words (host/budget_verdict.py), the profile's
calibrated stages limited to those the run used, and the report leading with the verdict."""

from mobigrasp.calib.calibrate import stages_used
from mobigrasp.host.budget_verdict import budget_block
from mobigrasp.services.profile import calibration_rows
from mobigrasp.services.report import answer


def _st(calls, max_us):
    return {"calls": calls, "mean_us": max_us / 2, "p95_us": max_us, "max_us": max_us,
            "total_us": calls * max_us // 2}


def _stats(**kw):
    stats = {"deadline_misses": 0, "frames_dropped": 0, "arm9_load_mean": 0.3,
             "arm9_load_max": 0.7,
             "stages": {"control": _st(500, 8_100), "protocol": _st(500, 20),
                        "radial_symbol": _st(90, 30_000)}}
    stats.update(kw)
    return stats


def test_a_run_within_every_budget_fits():
    b = budget_block(_stats())
    assert b["fits"] is True
    assert b["verdict"] == "fits: worst control step 8.1 ms of 20 ms"
    assert b["worst_stage"] == "radial_symbol"  # 30 of 66.7 ms beats 8.1 of 20 ms
    assert b["worst_stage_ms"] == 30.0 and round(b["worst_stage_budget_ms"], 1) == 66.7
    assert (b["deadline_misses"], b["frames_dropped_busy"]) == (0, 0)
    assert (b["load_mean"], b["load_max"]) == (0.3, 0.7)


def test_misses_drops_or_a_stage_over_budget_do_not_fit():
    b = budget_block(_stats(deadline_misses=3))
    assert b["fits"] is False and "3 control deadlines missed" in b["verdict"]
    assert b["verdict"].startswith("does not fit")
    b = budget_block(_stats(frames_dropped=2))
    assert b["fits"] is False and "2 frames dropped while busy" in b["verdict"]
    stages = _stats()["stages"] | {"control": _st(500, 25_000)}
    b = budget_block(_stats(stages=stages))
    assert b["fits"] is False and b["worst_stage"] == "control"
    assert "control 25.0 ms of 20.0 ms" in b["verdict"]


def test_stages_never_called_are_not_judged():
    stages = _stats()["stages"] | {"spoke": _st(0, 90_000)}
    b = budget_block(_stats(stages=stages))
    assert b["fits"] is True and b["worst_stage"] == "radial_symbol"
    empty = budget_block({})
    assert empty["worst_stage"] is None and empty["fits"] is True


def test_profile_lists_only_the_calibrated_stages_the_run_used():
    run = {"control": _st(5, 100), "radial_symbol": _st(5, 100), "dual_plus": _st(0, 0)}
    used = stages_used(run, "000")
    assert used == {"grey", "dark_threshold", "labelling", "radial_symbol", "bezier000"}
    st = {"emulated_median_us": 4000.0, "emulated_p95_us": 4100.0, "emulated_max_us": 5000.0,
          "modelled_median_us": 4000.0}
    cal = {"frame_shape": [240, 320], "stages": {
        "grey": st, "radial_symbol": st, "double_cross": st, "bezier000": st,
        "bezier001": dict(st, emulated_max_us=93_000.0)}}
    rows, first = calibration_rows(cal, used)
    assert [r["stage"] for r in rows] == ["grey", "radial_symbol", "bezier000"]
    assert first != "bezier001"
    assert stages_used({"double_cross": _st(3, 10)}, "002") == {"grey", "double_cross"}


def test_the_report_leads_with_the_verdict():
    summary = {"budget": budget_block(_stats(deadline_misses=1)), "grasped": True}
    first = answer(summary)[0]
    assert first[0] == "ARM9 budget" and first[1].startswith("does not fit: 1 control")
