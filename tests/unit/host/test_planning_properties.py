"""Properties of the planners over random inputs: never crash, always within the ARM9 budget,
and whatever they return as best satisfies the constraints they claim."""

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import Ref, grown_m

from mobigrasp.host.planning.bezier000 import Params000, plan_000
from mobigrasp.host.planning.bezier001 import Params001, plan_001
from mobigrasp.host.planning.grasp_circle import grasp_radius

coord = st.floats(-6.0, 6.0, allow_nan=False)
speed = st.floats(-0.3, 0.3, allow_nan=False)
sonar = st.lists(st.one_of(st.integers(0, 3000), st.just(0xFFFF)), min_size=5, max_size=5)


@examples(60)
@given(coord, coord, speed, speed, coord, coord, st.floats(-math.pi, math.pi))
def test_plan_000_budget_and_claims(x, y, vx, vy, ox, oy, heading):
    plan = plan_000((x, y), (vx, vy), (ox, oy), heading_rad=heading)
    assert plan.ops.time_us() <= 100_000
    if plan.best is not None:
        prm = Params000()
        s = plan.best.sample(plan.n_samples)
        assert np.all(s.t_tau > 0)
        assert np.all(s.speed <= prm.v_max + 1e-9)
        assert np.all(np.abs(s.kappa) <= 1 / prm.r_min + 1e-9)
        end = np.array(plan.best.ctrl[3][:2])
        # the integer set-up: P3 within two counts of 1/16 mm of the stand-off
        assert abs(np.hypot(*(end - (ox, oy))) - prm.standoff_m) < 2 / 16000
    else:
        assert plan.reason != "ok"


@examples(40)
@given(coord, coord, speed, speed, st.floats(-math.pi, math.pi), coord, coord, sonar)
def test_plan_001_budget_and_claims(x, y, vx, vy, heading, ox, oy, ranges):
    plan = plan_001((x, y), (vx, vy), heading, (ox, oy), ranges)
    assert plan.ops.time_us() <= 100_000
    if plan.best is not None:
        prm = Params001()
        s = plan.best.sample(prm.n_fine)
        assert np.all(s.t_tau > 0)
        assert np.all(s.speed <= prm.v_max + 1e-9)
        # the integer check floors s = |P_τ| and κ ∝ 1/s³: at the slowest samples (~2000
        # counts) the float a_t = v²κ may exceed what the integers found by a few tenths of a %;
        # near a cusp (below 0.02 m/s, the base all but turning in place) by up to ~5 %, an open
        # limitation of the integer check (docs/budget.md, "The Bezier planning")
        slow = s.speed < 0.02
        assert np.all(s.accel_normal[~slow] <= prm.a_max * 1.005)
        assert np.all(s.accel_normal[slow] <= prm.a_max * 1.10)
        l_e = grasp_radius(prm.arm).l_e_m
        d = np.hypot(s.x - ox, s.y - oy)
        # the integer end points: l_e times the Q12 table's cos and sin, within 2 counts
        assert abs(d[-1] - l_e) < 2 / 16000 and np.all(d >= l_e - 1e-3)
        for reg in plan.extra["regions"]:
            assert not Ref(grown_m(reg, -0.003)).contains(s.x[1:], s.y[1:]).any()
