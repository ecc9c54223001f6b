"""Seeded fault injectors: same decisions for the same seed whatever the chunking."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.faults import FaultPlan, MotorFail, RunFaults, SonarFail, UartFaults, Window
from mobigrasp.mcu_sim.faults.injectors import CameraFaults, EncoderSlip


def _stream(n, seed=0):
    return np.random.default_rng(seed).integers(0, 256, n, dtype=np.uint8).tobytes()


@examples(100)
@given(data=st.binary(min_size=1, max_size=400), cuts=st.lists(st.integers(0, 400), max_size=8),
       seed=st.integers(0, 2**32))
def test_same_decisions_whatever_the_chunking(data, cuts, seed):
    plan = FaultPlan(uart_bit_error_rate=0.02, uart_drop_rate=0.05,
                     uart_burst=Window(0.005, 0.003))
    whole = UartFaults(plan, seed).apply(data, 0)
    u = UartFaults(plan, seed)
    pieces, lost, flipped = [], 0, 0
    bounds = sorted({0, len(data), *[c for c in cuts if c < len(data)]})
    for a, b in zip(bounds, bounds[1:], strict=False):
        # each chunk starts at the time its first byte would have on a continuous line
        out, n_lost, n_flip = u.apply(data[a:b], int(a * 10_000_000 // 115_200))
        pieces.append(out)
        lost += n_lost
        flipped += n_flip
    assert (b"".join(pieces), lost, flipped) == whole


def test_rates_match_the_plan():
    data = _stream(200_000)
    out, lost, flipped = UartFaults(FaultPlan(uart_bit_error_rate=1e-3), 7).apply(data, 0)
    assert lost == 0 and len(out) == len(data)
    # 1.6e6 bits at 1e-3: 1600 expected, 5 sigma is +-200
    assert 1400 < flipped < 1800
    diff = np.unpackbits(np.frombuffer(out, np.uint8) ^ np.frombuffer(data, np.uint8)).sum()
    assert diff == flipped
    out, lost, flipped = UartFaults(FaultPlan(uart_drop_rate=0.1), 7).apply(data, 0)
    assert 19_000 < lost < 21_000 and len(out) == len(data) - lost and flipped == 0


def test_seed_and_direction_change_the_draws():
    plan = FaultPlan(uart_bit_error_rate=0.01)
    data = _stream(5000)
    a = UartFaults(plan, 1, "host->mcu").apply(data, 0)
    assert UartFaults(plan, 1, "host->mcu").apply(data, 0) == a
    assert UartFaults(plan, 2, "host->mcu").apply(data, 0) != a
    assert UartFaults(plan, 1, "mcu->host").apply(data, 0) != a


def test_no_fault_passes_bytes_unchanged():
    data = _stream(3000)
    u = UartFaults(FaultPlan(), 3)
    assert u.apply(data, 123) == (data, 0, 0) and not u.active
    assert u.stats() == {"bytes_in": 3000, "bytes_lost": 0, "bits_flipped": 0}


def test_burst_loses_exactly_the_bytes_sent_inside_it():
    plan = FaultPlan(uart_burst=Window(start_s=0.010, duration_s=0.005))
    data = bytes(range(256)) * 2
    out, lost, _ = UartFaults(plan, 0).apply(data, 0)
    starts = [int(k * 10_000_000 // 115_200) for k in range(len(data))]
    inside = [k for k, t in enumerate(starts) if 10_000 <= t < 15_000]
    assert lost == len(inside) and 55 <= lost <= 59  # 5 ms / 86.8 µs per byte
    keep = bytes(b for k, b in enumerate(data) if k not in set(inside))
    assert out == keep


def test_latency_is_a_time_offset():
    u = UartFaults(FaultPlan(uart_latency_us=2500), 0)
    assert u.deliver_us(10_000) == 12_500 and u.active
    assert u.apply(b"abc", 0) == (b"abc", 0, 0)


def test_camera_drop_depends_only_on_capture_time():
    cam = CameraFaults(FaultPlan(camera_drop_rate=0.3), 11)
    times = [k * 1_000_000 // 15 for k in range(3000)]
    first = [cam.drop(t) for t in times]
    again = [cam.drop(t) for t in reversed(times)][::-1]
    assert first == again and cam.dropped == 2 * sum(first)
    assert 800 < sum(first) < 1000  # 30 % of 3000
    assert not any(CameraFaults(FaultPlan(), 11).drop(t) for t in times)


def test_camera_noise_is_seeded_and_has_the_asked_spread():
    cam = CameraFaults(FaultPlan(camera_noise_std=5.0), 4)
    img = np.full((60, 80, 3), 128, np.uint8)
    a, b = cam.noise(img, 1000), cam.noise(img, 1000)
    assert a.dtype == np.uint8 and np.array_equal(a, b)
    assert not np.array_equal(a, cam.noise(img, 2000))
    assert 4.5 < float(a.astype(float).std()) < 5.5
    assert CameraFaults(FaultPlan(), 4).noise(img, 1000) is img


@examples(100)
@given(deltas=st.lists(st.integers(-500, 500), min_size=1, max_size=50),
       slip=st.floats(0.0, 1.0))
def test_encoder_slip_loses_the_fraction_and_nothing_by_rounding(deltas, slip):
    s = EncoderSlip(slip)
    total = 0
    for d in deltas:
        total += d
        left, right = s.apply(total, -total)
    keep = round((1 - slip) * 65536)
    assert left == (total * keep) >> 16 and right == (-total * keep) >> 16


def test_schedules_of_host_mcu_motor_and_sonar():
    plan = FaultPlan(host_stall=Window(2.0, 0.5), host_crash_at_s=9.0, mcu_reset_at_s=4.0,
                     motor_fail=MotorFail("right", 3.0), sonar_fail=SonarFail(1, 1.0))
    f = RunFaults(plan, 5)
    assert not f.host_stalled(1_999_999) and f.host_stalled(2_000_000)
    assert f.host_stalled(2_499_999) and not f.host_stalled(2_500_000)
    assert f.host_stall_end_us() == 2_500_000
    assert not f.host_crashed(8_999_999) and f.host_crashed(9_000_000) and f.host_silent(10**8)
    steps = [(t, t + 1000) for t in range(0, 10_000_000, 1000)]
    assert sum(f.mcu_reset_due(a, b) for a, b in steps) == 1 and f.mcu_resets == 1
    assert f.wheel_duty(100, -100, 2_999_999) == (100, -100)
    assert f.wheel_duty(100, -100, 3_000_000) == (100, 0)
    assert f.sonar_range_m(1, 0.7, 999_999) == 0.7 and f.sonar_range_m(1, 0.7, 10**6) is None
    assert f.sonar_range_m(0, 0.7, 10**7) == 0.7
    assert f.stats()["plan"]["mcu_reset_at_s"] == 4.0
    assert f.recovery_points_us() == [2_500_000] and not f.line_dead(2_000_000)
    g = RunFaults(FaultPlan(uart_burst=Window(1.0, 0.25), host_stall=Window(3.0, 1.0)), 0)
    assert g.recovery_points_us() == [1_250_000, 4_000_000]
    assert g.line_dead(1_000_000) and not g.line_dead(1_250_000)


def test_frame_hook_drops_or_returns_the_noisy_frame():
    f = RunFaults(FaultPlan(camera_drop_rate=0.5, camera_noise_std=2.0), 9)
    img = np.zeros((8, 8, 3), np.uint8)
    outs = [f.frame(img, t * 66_666) for t in range(200)]
    dropped = sum(o is None for o in outs)
    assert 70 < dropped < 130 and f.stats()["camera_frames_dropped"] == dropped
    assert all(o.shape == img.shape for o in outs if o is not None)


@pytest.mark.parametrize("baud", [0, -9600])
def test_bad_baud_is_refused(baud):
    with pytest.raises(ValueError, match="baud"):
        UartFaults(FaultPlan(), 0, baud=baud)
