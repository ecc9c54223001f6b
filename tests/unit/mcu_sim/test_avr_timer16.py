"""Timer1/3 model: fast PWM mode 14, pulse widths in ticks, double-buffered OCR, exact period."""

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.avr.signals import SignalBus
from mobigrasp.mcu_sim.avr.timer16 import Timer16

PERIOD = 40000 * 8  # cycles: (ICR + 1) x prescaler


def servo_timer(bus=None):
    bus = bus or SignalBus()
    t = Timer16("Timer1", bus, ("a", "b", "c"))
    t.write_tccra(0b1010_1010)
    t.write_icr(39999)
    return t, bus


@examples(100)
@given(st.integers(0, 39998), st.integers(0, 39998), st.integers(0, 39998))
def test_pulse_width_is_ocr_plus_one_tick(a, b, c):
    t, bus = servo_timer()
    for ch, v in enumerate((a, b, c)):
        t.write_ocr(ch, v)
    t.write_tccrb(0b0001_1010, 0)
    t.advance_to(PERIOD - 1)
    for ch, v in enumerate((a, b, c)):
        assert t.last_width_ns[ch] == (v + 1) * 500
        assert bus.port("abc"[ch] + ".pulse_ns").value == (v + 1) * 500


def test_period_is_exactly_20ms_and_edges_are_ordered():
    t, bus = servo_timer()
    t.write_ocr(0, 2999)
    edges = []
    pin = bus.port("a.pin")
    pin.subscribe(lambda t_us, v: edges.append((pin.last_cycle, v)))
    t.write_tccrb(0b0001_1010, 1000)
    t.advance_to(1000 + 5 * PERIOD)
    rises = [c for c, v in edges if v == 1]
    falls = [c for c, v in edges if v == 0]
    assert [b - a for a, b in zip(rises, rises[1:], strict=False)] == [PERIOD] * 5
    assert all(f - r == 3000 * 8 for r, f in zip(rises, falls, strict=False))
    assert t.overflows == 5


def test_ocr_write_takes_effect_at_next_bottom():
    t, _ = servo_timer()
    t.write_ocr(0, 2999)
    t.write_tccrb(0b0001_1010, 0)
    t.advance_to(100)
    t.write_ocr(0, 3999)  # mid-period: buffered
    t.advance_to(PERIOD - 1)
    assert t.last_width_ns[0] == 1_500_000
    t.advance_to(2 * PERIOD - 1)
    assert t.last_width_ns[0] == 2_000_000


def test_ocr_at_top_stays_high_and_disconnected_channel_is_silent():
    bus = SignalBus()
    t = Timer16("Timer3", bus, ("x", "y", "z"))
    t.write_tccra(0b1000_0010)  # only channel A connected
    t.write_icr(39999)
    t.write_ocr(0, 39999)
    t.write_tccrb(0b0001_1010, 0)
    t.advance_to(3 * PERIOD)
    assert t.last_width_ns == [0, 0, 0]  # no falling edge ever
    assert bus.port("x.pin").value == 1
    assert bus.port("y.pin").value == 0


def test_unsupported_modes_are_refused_with_a_clear_error():
    t, _ = servo_timer()
    t.write_tccra(0)
    with pytest.raises(ValueError, match="mode 14"):
        t.write_tccrb(0b0000_0010, 0)
    t2, _ = servo_timer()
    with pytest.raises(ValueError, match="external clock"):
        t2.write_tccrb(0b0001_1110, 0)


def test_stopping_the_clock_stops_edges():
    t, _ = servo_timer()
    t.write_tccrb(0b0001_1010, 0)
    t.write_tccrb(0b0001_1000, 10)
    assert t.next_event() is None
    assert t.advance_to(10 * PERIOD) == 0
