"""USART0 model: baud rate and error from UBRR/U2X, byte timing, bounded buffers."""

import pytest

from mobigrasp.mcu_sim.avr.usart import Usart, baud_error_pct, baud_rate
from mobigrasp.mcu_sim.mcu import Mcu, McuConfig


def test_baud_error_of_the_two_usual_settings():
    assert baud_rate(16, 1) == pytest.approx(117_647.06, abs=0.01)
    assert baud_error_pct(16, 1) == pytest.approx(2.124, abs=0.001)
    assert baud_rate(8, 0) == pytest.approx(111_111.11, abs=0.01)
    assert baud_error_pct(8, 0) == pytest.approx(-3.549, abs=0.001)
    assert Mcu(McuConfig(ubrr=8, u2x=0)).baud_error_pct == pytest.approx(-3.549, abs=0.001)


def test_bad_divisors_are_refused():
    with pytest.raises(ValueError, match="UBRR"):
        Usart(ubrr=5000)
    with pytest.raises(ValueError, match="U2X"):
        Usart(u2x=2)


@pytest.mark.parametrize(("ubrr", "u2x", "cycles"), [(16, 1, 1360), (8, 0, 1440)])
def test_a_byte_is_received_only_after_its_stop_bit(ubrr, u2x, cycles):
    u = Usart(ubrr, u2x)
    assert u.byte_cycles == cycles
    u.line_put(b"ab", 100)
    assert u.next_rx_cycle() == 100 + cycles
    assert u.rx_take_until(100 + cycles - 1) == b""
    assert u.rx_take_until(100 + cycles) == b"a"
    assert u.rx_take_until(100 + 2 * cycles) == b"b"
    assert u.next_rx_cycle() is None


def test_bytes_on_a_busy_line_queue_behind_each_other():
    u = Usart()
    u.line_put(b"abc", 0)
    u.line_put(b"d", 10)  # the line is still busy with abc
    assert u.rx_take_until(4 * 1360 - 1) == b"abc"
    assert u.rx_take_until(4 * 1360) == b"d"


def test_line_overflow_is_counted_not_raised():
    u = Usart(line_capacity=10)
    assert u.line_put(bytes(25), 0) == 10
    assert u.rx_line_dropped == 15
    assert u.rx_take_until(10**9) == bytes(10)
    assert u.line_put(b"x", 10**9) == 1


def test_wakeup_is_at_the_next_delimiter_or_when_the_ring_would_fill():
    u = Usart()
    u.line_put(b"\x01\x02\x00\x05", 0)
    assert u.next_rx_wakeup(127) == 3 * 1360
    u2 = Usart()
    u2.line_put(b"\x01" * 300, 0)
    assert u2.next_rx_wakeup(127) == 127 * 1360


def test_tx_timing_and_capacity():
    u = Usart(tx_capacity=8)
    assert u.tx_write(b"12345", 0)
    assert not u.tx_write(b"6789", 0)  # 5 + 4 > 8: refused whole
    assert u.tx_free(2 * 1360) == 5  # two bytes already left the line
    assert u.tx_take_until(2 * 1360) == [(2 * 1360, b"12")]
    assert u.tx_write(b"678", 2 * 1360)
    out = u.tx_take_until(10**6)
    assert out == [(5 * 1360, b"345"), (8 * 1360, b"678")]
    assert u.tx_bytes == 8
