"""The straight-way test (host/planning/escape.py) in integers against its float reference:
a segment found clear is clear with R_r shrunk by 3 mm, one found blocked is blocked with R_r
grown by 3 mm (positions in 1/16 mm, Q12 heading trigonometry)."""

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import Ref, any_region_contains, grown_m, region_m
from test_planning_clearance import clearance_float

from mobigrasp.host.planning.escape import (
    LEAVE_TOL_M,
    REGION_WORDS_OPS,
    escape_heading,
    segment_clear,
)

TOL_M = 0.003


def segment_clear_float(regions, pos, heading, length, samples=16, leave_ok=False) -> bool:
    px, py = pos
    dist = length * np.arange(1, samples + 1) / samples
    xs, ys = px + dist * math.cos(heading), py + dist * math.sin(heading)
    if not leave_ok:
        return not bool(any_region_contains(regions, xs, ys).any())
    for reg in regions:
        inside = Ref(reg).contains(xs, ys)
        if not inside.any():
            continue
        if not bool(Ref(reg).contains(px, py)):
            return False
        start = float(clearance_float(reg, px, py))
        if (inside & (clearance_float(reg, xs, ys) < start - LEAVE_TOL_M)).any():
            return False
    return True


region = st.builds(
    lambda ox, oy, lo, width, eta: region_m(ox, oy, lo, lo + width, eta, 0.2),
    st.floats(-2, 2), st.floats(-2, 2), st.floats(-4, 4), st.floats(0.1, 1.0),
    st.floats(0.3, 2.4))


@examples(300)
@given(st.lists(region, min_size=1, max_size=4), st.floats(-2, 2), st.floats(-2, 2),
       st.integers(-3141, 3141), st.floats(0.05, 2.0), st.integers(1, 20))
def test_segment_test_within_3mm_of_float(regs, px, py, heading_mrad, length, samples):
    clear, ops = segment_clear(regs, (px, py), heading_mrad / 1000, length, samples)
    assert ops.cycles() > 0
    if clear:
        shrunk = [grown_m(r, -TOL_M) for r in regs]
        assert segment_clear_float(shrunk, (px, py), heading_mrad / 1000, length, samples)
    else:
        grown = [grown_m(r, TOL_M) for r in regs]
        assert not segment_clear_float(grown, (px, py), heading_mrad / 1000, length, samples)


def test_leaving_a_region_matches_the_float_test_away_from_its_edges():
    # the robot 0.15 m from an echo 0.3 m ahead (inside R_r): back out yes; forward or
    # sideways along the arc (coming closer than the start) no
    reg = region_m(0.0, 0.0, -0.4, 0.4, 0.3, 0.2)
    for heading, want in ((math.pi, True), (2.0, True), (0.0, False), (math.pi / 2, False)):
        got, _ = segment_clear([reg], (0.15, 0.0), heading, 0.5, leave_ok=True)
        assert got == want == segment_clear_float([reg], (0.15, 0.0), heading, 0.5,
                                                  leave_ok=True)


def test_escape_heading_agrees_with_the_float_search():
    # echoes ahead and right: the first clear heading nearest the goal, both ways (no sample
    # within 1 cm of a region edge here)
    regs = [region_m(0.0, 0.0, -0.8, -0.2, 0.62, 0.2),
            region_m(0.0, 0.0, -0.2, 0.2, 0.5, 0.2)]
    head, ops = escape_heading(regs, (0.0, 0.0), 0.0, -0.3, 0.8)
    assert head is not None and ops.cycles() > 0
    assert ops.float_ops == 0 and REGION_WORDS_OPS.cycles() > 0  # set-up in integers
    step = math.pi / 12
    cands = sorted((j * step for j in range(-6, 7)), key=lambda h: (abs(h + 0.3), h))
    want = next(h for h in cands if segment_clear_float(regs, (0.0, 0.0), h, 0.8,
                                                        leave_ok=True))
    assert abs(head - want) < 2e-3
