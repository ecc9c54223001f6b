"""Vision-based approaching adjustment of 000: distance from the "+" pair, closed loop."""

import math

import numpy as np
import pytest

from mobigrasp.host.control.approach_adjust import (
    AdjustParams,
    ApproachAdjust,
    plus_pair_distance_mm,
)


def test_plus_pair_distance_hand_worked():
    # centres 40 px apart horizontally: D_is = 47.3 mm · 611 / 40 = 722.5 mm
    assert plus_pair_distance_mm(100 * 16, 50 * 16, 140 * 16, 50 * 16) == pytest.approx(722.5,
                                                                                         abs=0.6)
    # 3-4-5 triangle in Q4: 80 px
    assert plus_pair_distance_mm(0, 0, 48 * 16, 64 * 16) == pytest.approx(47.3 * 611 / 80, abs=0.6)
    with pytest.raises(ValueError, match="coincide"):
        plus_pair_distance_mm(5, 5, 5, 5)


def test_turns_toward_an_object_on_the_right_and_stops_when_lost():
    adj = ApproachAdjust()
    cmd = adj.step((400 * 16, 300 * 16))  # right and ahead, bearing 0.93 rad: face it first
    assert cmd.left_mm_s > 0 > cmd.right_mm_s  # clockwise on the spot
    cmd = adj.step((20 * 16, 600 * 16))  # almost straight ahead: drive, veer right
    assert cmd.left_mm_s > cmd.right_mm_s > 0
    lost = adj.step(None)
    assert lost.lost and (lost.left_mm_s, lost.right_mm_s) == (0, 0) and adj.lost_steps == 1


def test_done_inside_the_tolerance_and_backs_off_when_too_close():
    adj = ApproachAdjust()
    assert adj.step((0, 150 * 16)).done
    cmd = adj.step((0, 100 * 16))
    assert not cmd.done and cmd.left_mm_s < 0 and cmd.right_mm_s < 0


def closed_loop(seed, p=None):
    """Object at the origin; platform frame from the base pose (waist axis at the base centre)."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.2, 0.6)
    ang = rng.uniform(-math.pi, math.pi)
    x, y = r * math.cos(ang), r * math.sin(ang)
    th = ang + math.pi + rng.uniform(-0.6, 0.6)
    adj = ApproachAdjust(p or AdjustParams())
    for _ in range(1500):  # 30 s at 50 Hz
        dx, dy = -x, -y
        fwd = dx * math.cos(th) + dy * math.sin(th)
        right = dx * math.sin(th) - dy * math.cos(th)
        noise = rng.normal(0, 2.0, 2)  # mm of vision noise
        cmd = adj.step((round((right * 1000 + noise[0]) * 16), round((fwd * 1000 + noise[1]) * 16)))
        if cmd.done:
            return math.hypot(x, y), abs(math.atan2(right, fwd))
        vl, vr = cmd.left_mm_s / 1000, cmd.right_mm_s / 1000
        v, w = (vl + vr) / 2, (vr - vl) / 0.3
        x += v * 0.02 * math.cos(th)
        y += v * 0.02 * math.sin(th)
        th += w * 0.02
    return None, None


def test_closed_loop_ends_within_grasp_range_facing_the_object():
    ok = 0
    for seed in range(100):
        d, b = closed_loop(seed)
        ok += d is not None and abs(d - 0.150) <= 0.02 and b <= 0.05
    assert ok >= 95
