"""host/search: the search pattern of 000 Fig. 5, its coverage, order and timing (simulated)."""

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import search as se

P = se.SearchParams(dense_cycles=1)  # the paper's pattern (000 Fig. 5) in the first cycle


def levels_of(poses):
    out = []
    for th2, _ in poses:
        if not out or out[-1] != th2:
            out.append(th2)
    return out


def test_cycle_from_the_middle_hand_worked():
    poses = se.search_cycle(P, -2450, 0)
    # first sweep from theta5s = 0 to the far end (+0.8 here: both ends equally far -> up)
    assert poses[:5] == [(-2450, 0), (-2450, 200), (-2450, 400), (-2450, 600), (-2450, 800)]
    lv = levels_of(poses)
    # climbs to theta2_max first, then the levels below the start down to theta2_min
    assert lv[:7] == [-2450, -2390, -2330, -2270, -2210, -2150, -2100]
    assert lv[7:9] == [-2510, -2570] and lv[-1] == -2800
    # the second level sweeps back from +0.8 to -0.8
    second = [t5 for th2, t5 in poses if th2 == -2390]
    assert second == [800, 600, 400, 200, 0, -200, -400, -600, -800]


@examples(100)
@given(th2=st.integers(-3000, 0), th5=st.integers(-1400, 1400), up=st.booleans())
def test_cycle_covers_the_ranges(th2, th5, up):
    poses = se.search_cycle(P, th2, th5, up)
    lv = levels_of(poses)
    assert len(lv) == len(set(lv))  # every level swept once per cycle
    s = sorted(lv)
    assert s[0] == P.theta2_min_mrad and s[-1] == P.theta2_max_mrad
    assert all(b - a <= P.d_theta2_mrad for a, b in zip(s, s[1:], strict=False))
    for a, b in zip(poses, poses[1:], strict=False):
        assert P.theta2_min_mrad <= b[0] <= P.theta2_max_mrad
        assert P.theta5_min_mrad <= b[1] <= P.theta5_max_mrad
        if a[0] == b[0]:
            assert 0 < abs(a[1] - b[1]) <= P.d_theta5_mrad  # one step along a sweep
        else:
            assert a[1] == b[1]  # a theta2 step happens at a sweep end
    # every level after the first sweeps end to end, alternating direction
    for level in lv[1:]:
        sweep = [t5 for t2, t5 in poses if t2 == level]
        assert {sweep[0], sweep[-1]} == {P.theta5_min_mrad, P.theta5_max_mrad}


def test_dwell_holds_each_pose_for_two_frames_plus_travel():
    s = se.ArmSearch(P, -2450, 0, now_us=1_000)
    assert s.dwell_us((-2450, 0), (-2450, 0)) == 2 * se.FRAME_PERIOD_US
    assert s.dwell_us((-2450, 0), (-2450, 200)) == 40_000 + 2 * se.FRAME_PERIOD_US
    c = s.step(1_000)
    assert (c.theta2_mrad, c.theta5_mrad, c.base_turn_mrad) == (-2450, 0, 0)
    assert (c.theta3_mrad, c.theta4_mrad) == (P.theta3_mrad, P.theta4_mrad)
    d0 = 2 * se.FRAME_PERIOD_US
    assert s.step(1_000 + d0 - 1).theta5_mrad == 0
    assert s.step(1_000 + d0).theta5_mrad == 200
    d1 = s.dwell_us((-2450, 0), (-2450, 200))
    assert s.step(1_000 + d0 + d1 - 1).theta5_mrad == 200
    assert s.step(1_000 + d0 + d1).theta5_mrad == 400


def test_full_cycle_then_base_turn_then_new_cycle():
    s = se.ArmSearch(P, -2100, -800, now_us=0)
    n = len(se.search_cycle(P, -2100, -800))
    t = 0
    seen = []
    while True:
        c = s.step(t)
        if c.base_turn_mrad:
            break
        if not seen or seen[-1] != (c.theta2_mrad, c.theta5_mrad):
            seen.append((c.theta2_mrad, c.theta5_mrad))
        t += 10_000
        assert t < 60_000_000
    assert len(seen) == n and c.base_turn_mrad == P.base_turn_mrad and c.cycle == 1
    # a full cycle lasts at least n poses x 2 frames
    assert t >= n * 2 * se.FRAME_PERIOD_US
    # the request stays until the caller reports the turn done, whatever the time
    assert s.step(t + 10_000_000).base_turn_mrad == P.base_turn_mrad and s.turning
    s.base_turn_done(t + 10_000_000)
    c2 = s.step(t + 10_000_000)
    assert c2.base_turn_mrad == 0 and c2.pose_index == 0 and not s.turning
    # we ended at theta2_min: the next (coarse, host.search wandering) cycle starts at the
    # coarse level nearest to it
    assert c2.theta2_mrad == min(P.coarse_theta2_mrad)


def test_bad_params():
    with pytest.raises(ValueError, match="theta2_min"):
        se.SearchParams(theta2_min_mrad=-2000, theta2_max_mrad=-2100)
    with pytest.raises(ValueError, match="d_theta5"):
        se.SearchParams(d_theta5_mrad=0)
