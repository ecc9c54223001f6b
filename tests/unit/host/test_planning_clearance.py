"""D_m of eq. (18) of 001 in fixed point (host/planning/clearance_q.py) against its float
reference: the distance to the echo arc less R_r, within 1 mm."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import Ref, region_m

from mobigrasp.host.planning.bezier001 import Params001, plan_001
from mobigrasp.host.planning.bezier_q import POS_PER_M
from mobigrasp.host.planning.clearance_q import (
    NO_REGION_Q4,
    clearance_words,
    path_clearance_q4,
    point_clearance_q4,
)
from mobigrasp.host.planning.sonar_regions import InfeasibleRegion, SonarConfig, infeasible_regions

BOUND_Q4 = 16  # 1 mm


def clearance_float(region: InfeasibleRegion, x, y) -> np.ndarray:
    """Float reference: |OP| − η within the arc's angles (by the bearing), else the distance to
    the nearer end of the arc; less R_r."""
    reg = Ref(region)
    dx, dy = np.asarray(x) - reg.ox, np.asarray(y) - reg.oy
    r = np.hypot(dx, dy)
    mid = 0.5 * (reg.lo_rad + reg.hi_rad)
    off = np.abs((np.arctan2(dy, dx) - mid + math.pi) % (2 * math.pi) - math.pi)
    ends = [np.hypot(np.asarray(x) - reg.ox - reg.eta_m * math.cos(a),
                     np.asarray(y) - reg.oy - reg.eta_m * math.sin(a))
            for a in (reg.lo_rad, reg.hi_rad)]
    d = np.where(off <= reg.half_angle, np.abs(r - reg.eta_m), np.minimum(*ends))
    return d - reg.r_r_m


region = st.builds(
    lambda ox, oy, lo, width, eta, r_r: region_m(ox, oy, lo, lo + width, eta, r_r),
    st.floats(-5, 5), st.floats(-5, 5), st.floats(-4, 4), st.floats(0.05, 2.5),
    st.floats(0.05, 2.5), st.floats(0.0, 0.4))
coord = st.floats(-8, 8)


@examples(300)
@given(region, st.lists(st.tuples(coord, coord), min_size=1, max_size=8))
def test_point_clearance_within_1mm_of_float(reg, pts):
    x = np.array([p[0] for p in pts])
    y = np.array([p[1] for p in pts])
    xq, yq = np.rint(x * POS_PER_M).astype(np.int64), np.rint(y * POS_PER_M).astype(np.int64)
    got = point_clearance_q4(clearance_words([reg]), xq, yq)[0]
    want = clearance_float(reg, xq / POS_PER_M, yq / POS_PER_M) * POS_PER_M
    assert np.all(np.abs(got - want) <= BOUND_Q4), (got, want)


@examples(100)
@given(st.lists(region, min_size=1, max_size=5), st.integers(2, 12), st.integers(1, 4),
       st.integers(0, 2**32 - 1))
def test_path_clearance_is_least_over_samples_and_regions(regs, n, rows, seed):
    rng = np.random.default_rng(seed)
    xq = rng.integers(-6 * POS_PER_M, 6 * POS_PER_M, size=(rows, n))
    yq = rng.integers(-6 * POS_PER_M, 6 * POS_PER_M, size=(rows, n))
    got = path_clearance_q4(clearance_words(regs), xq, yq)
    want = np.min([clearance_float(r, xq / POS_PER_M, yq / POS_PER_M) for r in regs],
                  axis=(0, 2)) * POS_PER_M
    assert got.shape == (rows,)
    assert np.all(np.abs(got - want) <= BOUND_Q4)


def test_known_distances_exactly():
    # a region straight ahead (+x) at η = 1 m, R_r = 0.2 m, ±0.3 rad
    reg = region_m(0.0, 0.0, -0.3, 0.3, 1.0, 0.2)
    w = clearance_words([reg])
    q = POS_PER_M
    # on the bisector 2 m out: 1 m beyond the arc, less R_r
    assert point_clearance_q4(w, 2 * q, 0)[0] == round(0.8 * q)
    # at the origin: outside the angles (a = 0), η from either end (its rounded position)
    assert point_clearance_q4(w, 0, 0)[0] == pytest.approx(0.8 * q, abs=1)
    # behind: the nearer end of the arc
    end = (math.cos(0.3), math.sin(0.3))
    want = math.hypot(-1 - end[0], 0.5 - end[1]) - 0.2
    assert point_clearance_q4(w, -q, q // 2)[0] == pytest.approx(want * q, abs=1)


def test_no_regions_gives_the_sentinel():
    xq = np.zeros((3, 5), dtype=np.int64)
    assert np.all(path_clearance_q4(clearance_words([]), xq, xq) == NO_REGION_Q4)


def test_plan_001_clearance_matches_the_float_reference():
    """The D_m that eq. (18) ranks by, for every curve it was computed for."""
    sonar = [2500, 1000, 2500, 2500, 2500]  # an obstacle 1 m away at 45° right
    plan = plan_001((0.0, 0.0), (0.2, 0.0), 0.0, (3.0, 0.5), sonar)
    regions = infeasible_regions(SonarConfig(), (0.0, 0.0), 0.0, sonar).regions
    assert regions and plan.best is not None
    cands = plan.candidates
    known = np.nonzero(np.isfinite(cands.clearance) & (cands.clearance > 0))[0]
    assert known.size > 0
    for i in known[:20]:
        s = cands[int(i)].curve.sample(plan.n_samples)
        xq = np.rint(s.x[1:] * POS_PER_M) / POS_PER_M
        yq = np.rint(s.y[1:] * POS_PER_M) / POS_PER_M
        want = min(float(clearance_float(r, xq, yq).min()) for r in regions)
        assert cands.clearance[i] == pytest.approx(want, abs=2e-3)
    assert plan.best_candidate.clearance_m > Params001().t_d_m
