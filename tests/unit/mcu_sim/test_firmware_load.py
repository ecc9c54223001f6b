"""The Python firmware model charges the AVR cycles of its work by the events the C program runs
on (mcu_sim/firmware/cycles.py) and reports the load as simavr does (``avr_load_permille``)."""

import shutil

import pytest

from mobigrasp.mcu_sim.firmware.cycles import (
    CYCLES,
    CYCLES_PER_TIMER0_TICK,
    CYCLES_PER_TIMER2_PERIOD,
    CycleMeter,
)
from mobigrasp.mcu_sim.mcu import Mcu, McuConfig
from mobigrasp.mcu_sim.simavr.profile import profile_rows
from mobigrasp.protocol import messages as m

# the model's load against simavr's on the same slice (docs/firmware.md, "AVR load of the
# Python model")
LOAD_TOLERANCE = 0.25


def _slice(mcu, heartbeats: int, end_us: int):
    """HELLO at 20 ms, then ``heartbeats`` heartbeats 1 ms apart from 31 ms, run to ``end_us``."""
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    for seq in range(1, heartbeats + 1):
        mcu.uart_rx(m.encode_message(m.Heartbeat(seq), seq), 30_000 + seq * 1000)
    mcu.advance_to(end_us)
    return mcu


def test_the_load_is_in_the_stats_and_follows_the_traffic():
    quiet = _slice(Mcu(), 0, 200_000)
    busy = _slice(Mcu(), 60, 200_000)
    q, b = quiet.firmware.cycles.counts, busy.firmware.cycles.counts
    wire = len(m.encode_message(m.Heartbeat(1), 1))
    # one RX interrupt a byte, one decode a byte, one dispatch a frame
    assert b["isr_usart0_rx"] - q["isr_usart0_rx"] == 60 * wire
    assert b["rx_byte_decode"] - q["rx_byte_decode"] == 60 * wire
    assert b["frame_dispatch"] - q["frame_dispatch"] == 60
    assert b["telemetry"] == busy.stats()["telemetry_sent"] == q["telemetry"]
    elapsed = 200_000 * 16
    added = (busy.firmware.cycles.busy_cycles(elapsed)
             - quiet.firmware.cycles.busy_cycles(elapsed))
    assert added >= 60 * wire * (CYCLES["isr_usart0_rx"] + CYCLES["rx_byte_decode"])
    assert 0 < quiet.stats()["avr_load_permille"] < busy.stats()["avr_load_permille"] < 1000


def test_driving_costs_the_pi_and_the_soft_pwm():
    # SET_WHEELS every 50 ms from 40 ms on: the PI runs with the drive on, and while the right
    # wheel's duty ramps through 1..254 Timer2's interrupts run too (the wheels stand: it
    # saturates at 255 after that, Timer2 off again)
    busy, pwm = [], []
    for mmps in (0, 100):
        mcu = Mcu()
        mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
        for k in range(1 if mmps else 0, 6 if mmps else 0):  # streamed, inside the watchdog
            mcu.uart_rx(m.encode_message(m.SetWheels(mmps, mmps), k), k * 50_000 - 10_000)
        mcu.advance_to(300_000)
        meter = mcu.firmware.cycles
        assert (meter.counts["wheel_pi_drive"] > 20) == bool(mmps)
        busy.append(meter.busy_cycles(300_000 * 16))
        pwm.append(meter.pwm_on_cycles)
    assert pwm[0] == 0 and pwm[1] >= CYCLES_PER_TIMER2_PERIOD
    assert busy[1] - busy[0] >= (20 * (CYCLES["wheel_pi_drive"] - CYCLES["wheel_pi"])
                                 + pwm[1] // CYCLES_PER_TIMER2_PERIOD * CYCLES["timer2_period"])


def test_the_meter_charges_each_event_its_cycles():
    meter = CycleMeter()
    assert meter.load_permille(0) == 0
    ticks = 10
    elapsed = ticks * CYCLES_PER_TIMER0_TICK
    assert meter.busy_cycles(elapsed) == ticks * CYCLES["timer0_tick"]
    meter.charge("isr_encoder", 7)
    meter.charge("telemetry")
    assert meter.busy_cycles(elapsed) == (ticks * CYCLES["timer0_tick"]
                                          + 7 * CYCLES["isr_encoder"] + CYCLES["telemetry"])
    meter.charge("startup", 100)  # more work than time: the load is at most all of it
    assert meter.load_permille(elapsed) == 1000


def test_the_profile_shows_the_models_load_alone():
    stats = _slice(Mcu(), 5, 100_000).stats()
    rows = profile_rows(stats)
    assert [(r["figure"], r["worst"]) for r in rows] == [("AVR load (model)",
                                                         stats["avr_load_permille"])]


def test_the_load_is_a_report_only():
    # the same slice gives the same bytes to the host whatever the meter counted before
    a, b = Mcu(), Mcu()
    b.firmware.cycles.charge("startup", 1000)
    assert _slice(a, 5, 100_000).uart_tx_take() == _slice(b, 5, 100_000).uart_tx_take()


@pytest.mark.parametrize(("heartbeats", "end_us", "params"), [
    (20, 200_000, {}),
    (100, 200_000, {}),
    (0, 1_000_000, {"telemetry_hz": 0}),
])
def test_the_models_load_is_near_simavrs(heartbeats, end_us, params):
    pytest.importorskip("cffi")
    if shutil.which("avr-gcc") is None:
        pytest.skip("avr-gcc is missing (make firmware installs it)")
    from mobigrasp.mcu_sim.simavr.mcu import SimavrMcu

    cfg = McuConfig(params=params)
    model = _slice(Mcu(cfg), heartbeats, end_us).stats()["avr_load_permille"]
    avr = _slice(SimavrMcu(cfg), heartbeats, end_us).stats()["avr_load_permille"]
    assert abs(model - avr) <= LOAD_TOLERANCE * avr, (model, avr)
