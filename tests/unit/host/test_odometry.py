"""Integer odometry against hand-worked cases and a float reference."""

import math

import numpy as np
import pytest

from mobigrasp.host.odometry import Odometry

TICK_M = 2 * math.pi * 0.040 / 1024  # 0.2454 mm


def test_straight_line_hand_worked():
    odo = Odometry()
    odo.update(0, 0, 0)
    n = 4096  # 4 revolutions = 4 · 2π · 40 mm = 1005.31 mm
    for i in range(1, 101):
        pose = odo.update(i * 20_000, n * i // 100, n * i // 100)
    assert pose.x_um == pytest.approx(4 * 2 * math.pi * 40_000, abs=2)
    assert pose.y_um == 0 and pose.heading_mrad == 0
    assert pose.speed_mm_s == pytest.approx(1005.31 / 2.0, abs=13)  # last step 40 or 41 ticks


def test_turn_in_place_hand_worked():
    odo = Odometry(heading_mrad=100)
    odo.update(0, 0, 0)
    # right wheel +n, left −n: Δθ = 2 n · tick / 0.3 m
    n = 300
    pose = odo.update(1_000_000, -n, n)
    assert pose.heading_mrad == round(100 + 1000 * 2 * n * TICK_M / 0.3)
    assert abs(pose.x_um) <= 1 and abs(pose.y_um) <= 1
    assert pose.yaw_rate_mrad_s == pytest.approx(1000 * 2 * n * TICK_M / 0.3, abs=1)


def float_reference(ticks_l, ticks_r, x0=0.0, y0=0.0, th0=0.0):
    """Same midpoint integration in float64 on the same tick sequence."""
    x, y = x0, y0
    sl = sr = 0.0
    th = th0
    for tl, tr in zip(ticks_l, ticks_r, strict=True):
        nl, nr = tl * TICK_M, tr * TICK_M
        dl, dr = nl - sl, nr - sr
        sl, sr = nl, nr
        th_new = th0 + (sr - sl) / 0.3
        mid = 0.5 * (th + th_new)
        d = 0.5 * (dl + dr)
        x += d * math.cos(mid)
        y += d * math.sin(mid)
        th = th_new
    return x, y, th


@pytest.mark.parametrize("seed", range(5))
def test_random_drive_matches_float_reference(seed):
    rng = np.random.default_rng(seed)
    vl = np.repeat(rng.uniform(-0.3, 0.4, 40), 50)  # m/s, piecewise constant, 50 Hz
    vr = np.repeat(rng.uniform(-0.3, 0.4, 40), 50)
    sl = np.cumsum(vl * 0.02)
    sr = np.cumsum(vr * 0.02)
    tl = np.floor(sl / TICK_M).astype(int).tolist()
    tr = np.floor(sr / TICK_M).astype(int).tolist()
    odo = Odometry(1_000_000, -2_000_000, 500)
    odo.update(0, 0, 0)
    for i, (a, b) in enumerate(zip(tl, tr, strict=True)):
        pose = odo.update((i + 1) * 20_000, a, b)
    fx, fy, fth = float_reference(tl, tr, 1.0, -2.0, 0.5)
    assert pose.x_um / 1e6 == pytest.approx(fx, abs=1e-3)  # < 1 mm after ~15 m of wheel travel
    assert pose.y_um / 1e6 == pytest.approx(fy, abs=1e-3)
    wrapped = (fth + math.pi) % (2 * math.pi) - math.pi
    assert pose.heading_mrad == pytest.approx(1000 * wrapped, abs=1)


def test_int32_counter_wrap_is_unwrapped():
    odo = Odometry()
    start = 2**31 - 100
    odo.update(0, start - 2**32, start - 2**32)  # as int32: just below +2^31
    pose = odo.update(100_000, -(2**31) + 100, -(2**31) + 100)  # wrapped: +200 ticks
    assert pose.x_um == round(200 * TICK_M * 1e6)
    assert odo.dropped == 0


def test_impossible_jump_and_old_samples_are_dropped():
    odo = Odometry()
    odo.update(0, 0, 0)
    odo.update(20_000, 10, 10)
    before = odo.pose
    after = odo.update(40_000, 50_000, 10)  # 12 m in 20 ms
    assert odo.dropped == 1 and after == before
    odo.update(30_000, 50_010, 20)  # time went backwards: ignored entirely
    assert odo.dropped == 2
    pose = odo.update(60_000, 50_020, 30)  # resynchronised on the jump: only these 20 ticks
    assert pose.x_um == pytest.approx(before.x_um + 20 * TICK_M * 1e6, abs=2)


def test_after_an_mcu_reset_the_pose_carries_on_from_where_it_was():
    # the MCU's clock and encoder counters restart at 0: without resync every later sample is
    # "from the past" and the pose freezes for good
    odo = Odometry()
    odo.update(0, 0, 0)
    for i in range(1, 51):
        odo.update(5_000_000 + i * 20_000, 20 * i, 30 * i)  # forward, turning left
    before = odo.pose
    frozen = Odometry()
    frozen.update(0, 0, 0)
    frozen.update(6_000_000, 1000, 1500)
    frozen.update(20_000, 0, 0)  # a reset seen without resync
    assert frozen.update(40_000, 40, 40) == frozen.pose and frozen.dropped == 2
    odo.resync()
    p = odo.pose  # nothing moves by itself; the speed is unknown until the next samples
    assert (p.x_um, p.y_um, p.heading_mrad, p.speed_mm_s) == (
        before.x_um, before.y_um, before.heading_mrad, 0)
    odo.update(20_000, 0, 0)  # first sample after the reset: the new reference only
    assert odo.pose.x_um == before.x_um and odo.pose.heading_mrad == before.heading_mrad
    pose = odo.update(40_000, 40, 40)  # 40 ticks straight on from the old heading
    step = 40 * TICK_M * 1e6
    h = before.heading_mrad / 1000
    assert pose.x_um == pytest.approx(before.x_um + step * math.cos(h), abs=3)
    assert pose.y_um == pytest.approx(before.y_um + step * math.sin(h), abs=3)
    assert pose.heading_mrad == before.heading_mrad
