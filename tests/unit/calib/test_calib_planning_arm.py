"""The Bezier candidate evaluation as ARM920T code (fixed point): the same results as the
host-built C bit for bit, and the planning stages in calibrate and profile."""

import math

import numpy as np
import pytest

from mobigrasp.calib import arm, calibrate, native, planning
from mobigrasp.host.planning.bezier000 import control_points_000
from mobigrasp.host.planning.bezier001 import control_points_001
from mobigrasp.host.planning.bezier_q import quantize_ctrl
from mobigrasp.host.planning.candidates import Limits
from mobigrasp.host.planning.grasp_circle import end_points
from mobigrasp.host.planning.sonar_regions import SonarConfig, infeasible_regions


@pytest.fixture(scope="module")
def planner():
    return arm.Planner(arm.Arm9(arm.build()))


def test_emulated_000_evaluation_equals_the_host_build(planner):
    p0, obj = np.array([0.1, -0.2]), np.array([1.3, 0.4])
    d3 = (obj - p0) / np.hypot(*(obj - p0))
    t3 = float(np.hypot(*(obj - p0))) / 0.12
    ctrl = quantize_ctrl(control_points_000(p0, np.array([1.0, 0.0]), obj, d3, t3, 37,
                                            0.12)[10:24])
    lim = Limits(0.25, 0.04, 0.1, accel_is_normal=False).words()
    k = planning.q16(0.5)
    (best, reason, first, cost), t = planner.bezier000(ctrl, 12, lim, k, k)
    want = native.bezier000(ctrl, 12, lim, k, k)
    assert best == want[0] and np.array_equal(reason, want[1])
    assert np.array_equal(first, want[2]) and np.array_equal(cost, want[3])
    assert best >= 0 and len(set(reason.tolist())) > 1  # some pass, some do not
    samples = int(np.minimum(first + 1, 12).sum())
    # six 64-bit quotients (libgcc's shift-subtract loop) and the bit-by-bit root dominate a
    # sample: well under the ~11 000 cycles of the same sample in double soft-float
    assert 1000 < t.cycles / samples < 6000


def test_emulated_001_passes_equal_the_host_build(planner):
    p0, obj, heading = np.array([0.0, 0.0]), np.array([2.0, 0.5]), 0.2
    regions = infeasible_regions(SonarConfig(arc_angle_bound=True), p0, heading,
                                 [2500, 900, 1200, 2500, 2500]).regions
    assert regions
    ends = end_points(obj, 0.35, 12)[[5, 6, 7]]
    dist = float(np.hypot(*(obj - p0)))
    ctrl, _, _ = control_points_001(p0, np.array([math.cos(heading), math.sin(heading)]), ends,
                                    obj, dist / 0.2, 4, dist, 0.2)
    ctrl = quantize_ctrl(ctrl)
    lim = Limits(0.4, 0.1, None, accel_is_normal=True).words()
    geo = planning.geometry(obj, 0.35, regions).words()
    args = (ctrl, 10, lim, geo, len(regions), 300, 100, 2000, planning.q16(0.8),
            planning.q16(0.2))
    (taken, reason, first, cost), t = planner.bezier001_coarse(*args)
    want = native.bezier001_coarse(*args)
    assert taken == want[0] and np.array_equal(reason, want[1])
    assert np.array_equal(first, want[2]) and np.array_equal(cost, want[3])
    assert 0 < taken < len(ctrl)  # the anytime cut fell inside the set
    fine = (ctrl[::-1], 16, lim, geo, len(regions), 300, 100, 5, 10_000)
    (got, tried), t_fine = planner.bezier001_fine(*fine)
    want_got, want_tried = native.bezier001_fine(*fine)
    assert got == want_got and np.array_equal(tried, want_tried) and len(tried) >= 1
    both = arm.Timing.sum(t, t_fine)
    assert both.cycles == t.cycles + t_fine.cycles
    assert both.instructions == t.instructions + t_fine.instructions


def _scene_001():
    p0, obj, heading = np.array([0.0, 0.0]), np.array([2.0, 0.5]), 0.2
    regions = infeasible_regions(SonarConfig(arc_angle_bound=True), p0, heading,
                                 [2500, 900, 1200, 2500, 2500]).regions
    ends = end_points(obj, 0.35, 12)[[5, 6, 7]]
    dist = float(np.hypot(*(obj - p0)))
    ctrl, _, _ = control_points_001(p0, np.array([math.cos(heading), math.sin(heading)]), ends,
                                    obj, dist / 0.2, 4, dist, 0.2)
    lim = Limits(0.4, 0.1, None, accel_is_normal=True).words()
    return quantize_ctrl(ctrl), lim, planning.geometry(obj, 0.35, regions).words(), len(regions)


def test_001_passes_in_slices_give_the_whole_passes_results(planner):
    ctrl, lim, geo, n_reg = _scene_001()
    k1, k2 = planning.q16(0.8), planning.q16(0.2)
    want = native.bezier001_coarse(ctrl, 10, lim, geo, n_reg, 300, 100, 20_000, k1, k2)
    m = planner.start_pass(ctrl, lim, geo)
    taken, ends, spent = -1, [], []
    while taken < 0:  # slices of 2500 modelled cycles: a few curves each
        end = 2_500 * (len(ends) + 1)
        taken, t = planner.bezier001_coarse_slice(m, 10, n_reg, 300, 100, 20_000, k1, k2, end)
        ends.append(end)
        spent.append(planner.pass_state()[1])
        assert t.cycles > 0
    assert taken == want[0] and len(ends) > 2
    for got, exp in zip(planner.coarse_outputs(m), want[1:], strict=True):
        assert np.array_equal(got, exp)
    # each slice started its curves below its end: it overran it by one curve at most
    assert all(s - e < 10 * 300 + 100 for s, e in zip(spent[:-1], ends, strict=False))
    fine = (ctrl[::-1], 16, lim, geo, n_reg, 300, 100, 5, 10_000)
    whole = native.bezier001_fine(*fine)
    m = planner.start_pass(fine[0], lim, geo)
    got, k = -2, 0
    while got == -2:
        k += 1
        (got, tried), _ = planner.bezier001_fine_slice(m, 16, n_reg, 300, 100, 5, 10_000,
                                                       5_000 * k)
    assert got == whole[0] and np.array_equal(tried, whole[1]) and k > 1


@pytest.mark.slow
def test_a_recorded_001_plan_runs_in_slices_that_each_fit_a_control_step(planner, tmp_path):
    from mobigrasp.calib import plan_corpus
    from mobigrasp.host.planning.anytime import CYCLES_PER_US, PLAN_SLICE_US
    from mobigrasp.services.corpus import record

    record(tmp_path, ["paper001-sim1"], time_limit_s=3.0)
    call = next(c for c in plan_corpus.read_index(tmp_path)["calls"] if c["planner"] == "001")
    st = planning.setup(call, plan_corpus.load_arrays(tmp_path, call))
    ok, rows = calibrate.plan_slices(planner, st)
    assert ok and len(rows) >= 2  # the Python's reasons, first samples and chosen curve
    slice_cycles = PLAN_SLICE_US * CYCLES_PER_US
    # a slice's curves start within its 8 ms of the plan's count (which leaves out the ~1090
    # cycles of a curve's integrals and cost when it passes), the last may run past its end
    assert all(0 < modelled <= 1.1 * slice_cycles for modelled, _ in rows)
    # as emulated, each slice within 10 ms: with the step's own work within its 20 ms
    assert all(t.cycles <= 10_000 * CYCLES_PER_US for _, t in rows)
    assert sum(modelled for modelled, _ in rows) >= st.coarse.cycles


def test_profile_lists_planning_after_the_frame_stages_and_names_the_first_to_miss():
    from mobigrasp.services.profile import calibration_rows

    st = {"emulated_median_us": 4000.0, "emulated_p95_us": 4100.0, "emulated_max_us": 5000.0}
    cal = {"frame_shape": [240, 320], "commit": "abc", "stages": {
        "bezier001": dict(st, modelled_median_us=60000.0, emulated_max_us=93000.0),
        "grey": st, "bezier000": dict(st, modelled_median_us=3000.0),
        "radial_symbol": dict(st, modelled_median_us=2000.0)}}
    rows, first = calibration_rows(cal)
    assert [r["stage"] for r in rows] == ["grey", "radial_symbol", "bezier000", "bezier001"]
    assert [r["kind"] for r in rows] == ["frame", "frame", "planning", "planning"]
    assert first == "bezier001" and rows[3]["share_max"] > 1
    assert set(calibrate.PLANNING_STAGES) == {"bezier000", "bezier001"}


def test_profile_shows_a_calibration_of_planner_calls_only():
    from mobigrasp.services.profile import calibration_rows

    cal = {"frame_shape": None, "stages": {"bezier000": {
        "modelled_median_us": 7000.0, "emulated_median_us": 7400.0, "emulated_p95_us": 7500.0,
        "emulated_max_us": 7600.0}}}
    rows, first = calibration_rows(cal)
    assert [r["stage"] for r in rows] == ["bezier000"] and first == "bezier000"
    assert rows[0]["ratio"] == round(7000 / 7400, 3) and rows[0]["share_max"] < 1
