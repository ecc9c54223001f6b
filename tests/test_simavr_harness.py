"""The avr-gcc ELF under simavr (mcu_sim/simavr): boots, keeps time, sends telemetry and gives
servo widths from the OCRnx latched at each Timer1 period start."""

import shutil

import pytest

pytest.importorskip("cffi")
if shutil.which("avr-gcc") is None:
    pytest.skip("avr-gcc is missing (make firmware installs it)", allow_module_level=True)

from mobigrasp.mcu_sim.simavr.mcu import SimavrMcu  # noqa: E402
from mobigrasp.protocol import messages as m  # noqa: E402
from mobigrasp.protocol.frame import FrameParser  # noqa: E402


@pytest.fixture(scope="module")
def booted():
    mcu = SimavrMcu()
    mcu.advance_to(100_000)
    return mcu


def test_the_elf_boots_and_sends_telemetry_every_20_ms(booted):
    chunks = booted.uart_tx_take()
    msgs = [m.decode_frame(f) for f in FrameParser().feed(b"".join(d for _, d in chunks))]
    tele = [x for x in msgs if isinstance(x, m.Telemetry)]
    assert len(tele) >= 3
    gaps = {b.time_us - a.time_us for a, b in zip(tele, tele[1:], strict=False)}
    assert all(abs(g - 20_000) <= 100 for g in gaps)


def test_servo_widths_come_from_the_latched_ocr_values(booted):
    # the firmware's boot widths (gripper 1000 µs, the others 1500 µs)
    assert booted.servo_pulses_us() == (1000.0, 1500.0, 1500.0, 1500.0, 1500.0, 1500.0)


def test_the_profile_counts_timer_interrupts_and_sleep(booted):
    p = booted.profile()
    assert p["isr_count"][14] >= 4  # TIMER1_OVF, one per 20 ms period
    assert 0 < p["sleep_cycles"] < p["total_cycles"]
    assert 0 < p["stack_depth_bytes"] < 4096
