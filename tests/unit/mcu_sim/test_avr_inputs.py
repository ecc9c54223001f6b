"""Encoder and sonar models: edges spread over time, echo widths, timeouts, bad providers."""

import math

import pytest

from mobigrasp.mcu_sim.avr.encoder import QuadratureEncoder
from mobigrasp.mcu_sim.avr.sonar import MAX_RANGE_M, SonarArray, echo_width_us


def test_encoder_spreads_edges_linearly_and_loses_none():
    enc = QuadratureEncoder("left")
    enc.set_ticks(100, t_cycle=16_000, now_cycle=0)
    assert enc.take_edges(8_000) == 50
    assert enc.take_edges(12_000) == 25
    assert enc.take_edges(20_000) == 25
    enc.set_ticks(40, t_cycle=36_000, now_cycle=20_000)  # reversing
    assert enc.take_edges(28_000) == -30
    assert enc.take_edges(36_000) == -30
    assert enc.position_at(10**9) == 40


def test_encoder_past_time_applies_at_once_and_bad_input_is_counted():
    enc = QuadratureEncoder("right")
    enc.set_ticks(-7, t_cycle=0, now_cycle=500)
    assert enc.take_edges(500) == -7
    enc.set_ticks(3.5, t_cycle=600, now_cycle=500)
    enc.set_ticks(True, t_cycle=600, now_cycle=500)
    assert enc.bad_inputs == 2
    assert enc.take_edges(700) == 0


def test_echo_width_is_round_trip_time_of_sound():
    assert echo_width_us(1.0) == pytest.approx(2 / 343 * 1e6)
    sonars = SonarArray(5)
    sonars.provider = lambda i: 0.5 + i * 0.25
    sonars.trigger(2, 1000)
    (rise, i1, l1), (fall, i2, l2) = sonars.take_events_until(10**9)
    assert (i1, l1, i2, l2) == (2, 1, 2, 0)
    assert (fall - rise) / 16 == pytest.approx(echo_width_us(1.0), abs=0.07)


@pytest.mark.parametrize("value", [None, MAX_RANGE_M + 0.01, math.nan, -1.0, "far"])
def test_no_echo_beyond_range_or_for_bad_values(value):
    sonars = SonarArray(5)
    sonars.provider = lambda i: value
    sonars.trigger(0, 0)
    assert sonars.next_event() is None


def test_a_provider_that_raises_is_counted_not_fatal():
    def broken(i):
        raise RuntimeError("world exploded")

    sonars = SonarArray(5)
    sonars.provider = broken
    sonars.trigger(1, 0)
    assert sonars.next_event() is None and sonars.bad_readings == 1


def test_unfitted_sonars_never_echo():
    sonars = SonarArray(2)
    sonars.provider = lambda i: 1.0
    sonars.trigger(3, 0)
    assert sonars.next_event() is None
    with pytest.raises(ValueError, match="sonar count"):
        SonarArray(6)
