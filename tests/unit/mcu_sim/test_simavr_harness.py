"""The avr-gcc ELF under simavr (mcu_sim/simavr): boots, keeps time, sends telemetry and gives
servo widths from the OCRnx latched at each Timer1 period start."""

import json
import shutil
from itertools import pairwise

import pytest

pytest.importorskip("cffi")
if shutil.which("avr-gcc") is None:
    pytest.skip("avr-gcc is missing (make firmware installs it)", allow_module_level=True)

from mobigrasp.mcu_sim.firmware.params import P_TELEMETRY_HZ  # noqa: E402
from mobigrasp.mcu_sim.mcu import McuConfig  # noqa: E402
from mobigrasp.mcu_sim.mcu_host import InProcessHost  # noqa: E402
from mobigrasp.mcu_sim.simavr.mcu import SimavrMcu  # noqa: E402
from mobigrasp.mcu_sim.simavr.profile import (  # noqa: E402
    RX_LATENCY_BUDGET_CYCLES,
    format_rows,
    profile_rows,
)
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
    # the first at the end of the start-up (the clock counts from the reset), the later ones
    # at the clock's multiples of 20 ms, where Timer1's overflow wakes the loop
    assert 1_000 <= tele[0].time_us <= 3_000
    assert all(t.time_us % 20_000 <= 100 for t in tele[1:])
    gaps = {b.time_us - a.time_us for a, b in zip(tele[1:], tele[2:], strict=False)}
    assert all(abs(g - 20_000) <= 100 for g in gaps)


def test_each_telemetry_frame_leaves_within_the_5_ms_after_its_tick():
    # the clock counts from the reset and the telemetry is sent at its multiples of 20 ms, so a
    # frame (some 4.4 ms on the line) leaves within the rig's 5 ms quantum that starts at its
    # tick, as with the models (one pty write a frame, docs/firmware.md "simavr")
    mcu = SimavrMcu()
    mcu.advance_to(300_000)
    byte_us = mcu.byte_cycles / 16
    ends = [(t - (len(d) - 1 - j) * byte_us, d[j]) for t, d in mcu.uart_tx_take()
            for j in range(len(d))]
    frames, start = [], None
    for t, byte in ends:  # COBS frames, each ending with its 0x00
        start = t - byte_us if start is None else start
        if byte == 0:
            frames.append((start, t))
            start = None
    assert len(frames) >= 14
    for first_bit, last_bit in frames[1:]:  # the first leaves at the start-up's end
        tick = first_bit // 20_000 * 20_000
        assert last_bit <= tick + 5_000, (first_bit, last_bit)


def test_servo_widths_come_from_the_latched_ocr_values(booted):
    # the firmware's boot widths (gripper 1000 µs, the others 1500 µs)
    assert booted.servo_pulses_us() == (1000.0, 1500.0, 1500.0, 1500.0, 1500.0, 1500.0)


def test_the_profile_counts_timer_interrupts_and_sleep(booted):
    p = booted.profile()
    assert p["isr_count"][14] >= 4  # TIMER1_OVF, one per 20 ms period
    assert 0 < p["sleep_cycles"] < p["total_cycles"]
    assert 0 < p["stack_depth_bytes"] < 4096


def _send_burst(mcu):
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    for seq in range(1, 21):
        mcu.uart_rx(m.encode_message(m.Heartbeat(seq), seq), 30_000)
    mcu.advance_to(200_000)


def test_the_shipped_firmware_keeps_every_timing_budget():
    mcu = SimavrMcu()
    _send_burst(mcu)
    stats = mcu.stats()
    assert stats["rx_line_dropped"] == 0 and stats["parser_frames_ok"] == 21
    rows = {r["figure"]: r for r in profile_rows(stats)}
    assert [name for name, r in rows.items() if r["exceeded"]] == []
    assert 0 < stats["avr_load_permille"] <= 300
    assert not rows["ISR USART0_RX"]["exceeded"]
    assert 0 < rows["UART RX latency"]["worst"] <= RX_LATENCY_BUDGET_CYCLES
    assert not rows["RX bytes lost on the line"]["exceeded"]
    assert 0 < rows["deepest stack"]["worst"] <= rows["deepest stack"]["budget"]


def test_a_slow_rx_handler_loses_bytes_and_names_the_budget_it_broke():
    # a firmware variant whose RX handler busy-waits 3000 cycles (2.2 byte times)
    mcu = SimavrMcu(defines={"FW_TEST_RX_ISR_BUSY_CYCLES": 3000})
    _send_burst(mcu)
    stats = mcu.stats()
    assert stats["rx_line_dropped"] > 0
    assert stats["avr_isr_max_cycles_USART0_RX"] >= 3000
    rows = {r["figure"]: r for r in profile_rows(stats)}
    assert rows["ISR USART0_RX"]["exceeded"] and rows["RX bytes lost on the line"]["exceeded"]
    assert not rows["ISR TIMER1_OVF"]["exceeded"]
    text = format_rows(profile_rows(stats))
    assert "ISR USART0_RX" in text.splitlines()[-1] and "EXCEEDED" in text


def test_servo_widths_follow_an_ocr_write_at_the_next_period():
    mcu = SimavrMcu()
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    mcu.advance_to(60_000)
    target = (1500, 1700, 1500, 1500, 1500, 1500)
    mcu.uart_rx(m.encode_message(m.SetServos(0, target, 0), 1))
    mcu.advance_to(200_000)
    assert mcu.servo_pulses_us()[1] == 1700.0


def test_sonar_echoes_on_int6_give_the_ranges_within_the_isr_latency():
    mcu = SimavrMcu()
    mcu.set_sonar_provider(lambda i: 0.5 + 0.25 * i)
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    mcu.advance_to(600_000)
    data = b"".join(d for _, d in mcu.uart_tx_take())
    tele = [x for x in map(m.decode_frame, FrameParser().feed(data)) if isinstance(x, m.Telemetry)]
    # the echo is timed by INT6 and hal_micros(): the handler's entry latency (a few µs, under
    # 2 mm of range) is in every measured width, which the Python model times exactly
    for i, got in enumerate(tele[-1].sonar_mm):
        assert abs(got - (500 + 250 * i)) <= 2


def test_simavr_16_pins_keep_their_boot_widths_which_is_why_the_registers_are_latched():
    mcu = SimavrMcu()
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    mcu.advance_to(60_000)
    mcu.uart_rx(m.encode_message(m.SetServos(0, (1500, 1700, 1500, 1500, 1500, 1500), 0), 1))
    mcu.advance_to(200_000)
    pins_us = mcu.oc1_pin_widths_us()
    # what OC1A..C show: the widths of the OCR1x in force when Timer1 was configured (the
    # clock starts in .init3, OCR1x 0 then: one 0.5 µs tick, within two cycles), not the
    # widths written since
    assert all(abs(p - 0.5) <= 2 / 16 for p in pins_us)
    assert mcu.servo_pulses_us()[:3] == (1500.0, 1700.0, 1500.0)


def _telemetry(mcu):
    data = b"".join(d for _, d in mcu.uart_tx_take())
    return [x for x in map(m.decode_frame, FrameParser().feed(data)) if isinstance(x, m.Telemetry)]


def test_after_a_reset_the_elf_starts_again_and_keeps_talking():
    mcu = SimavrMcu()
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    mcu.advance_to(100_000)
    assert _telemetry(mcu)[-1].flags & m.FLAG_HANDSHAKE
    mcu.reset()
    mcu.advance_to(300_000)
    tele = _telemetry(mcu)
    # a new start-up (about 2.2 ms; the first telemetry at its end), then telemetry at every
    # 20 ms of the firmware's new clock to the end: the UDRE interrupt keeps coming after the
    # first byte
    assert len(tele) >= 9 and tele[-1].time_us >= 160_000
    assert 1_000 <= tele[0].time_us <= 3_000
    assert all(abs(b.time_us - a.time_us - 20_000) <= 100 for a, b in pairwise(tele[1:]))
    assert tele[0].flags & m.FLAG_RESET and not tele[0].flags & m.FLAG_HANDSHAKE
    assert not tele[1].flags & m.FLAG_RESET
    # the encoder pins rest low across the reset and no edge was given: INT0..3 never ran
    counts = mcu.profile()["isr_count"]
    assert all(counts.get(v, 0) == 0 for v in (1, 2, 3, 4))


def test_a_fault_plans_mcu_reset_under_simavr_leaves_the_board_talking(tmp_path):
    from mobigrasp.services.run_job import RunOptions, execute

    summary, _ = execute(RunOptions(scenario="paper000-exp1", mcu="simavr", out=tmp_path / "run",
                                    progress=False, plots=False, mcap=False, time_limit_s=2.0,
                                    faults=("mcu_reset_at_s=0.8",)))
    assert summary["faults"]["mcu_resets"] == 1
    safety = summary["safety"]
    assert safety["unsafe_actuations"] == 0 and safety["unrecovered"] == 0
    # the host saw the reset in the telemetry and opened the session again once the firmware's
    # start-up was over: more than that start-up, well under the watchdog period
    assert len(safety["recovery_ms"]) == 1 and 15.0 < safety["recovery_ms"][0] <= 100.0
    # the firmware's counter starts again at the reset: 1.2 s of 50 Hz telemetry after it
    assert 55 <= summary["mcu"]["telemetry_sent"] <= 61


def test_the_closed_loop_opens_its_session_without_losing_a_byte(tmp_path):
    # the host's first HELLO waits for the MCU's first telemetry: nothing meets the start-up
    from mobigrasp.services.run_job import RunOptions, execute

    summary, _ = execute(RunOptions(scenario="paper000-exp1", mcu="simavr", out=tmp_path / "run",
                                    progress=False, plots=False, mcap=False, time_limit_s=1.0,
                                    transport="inproc"))
    mcu = summary["mcu"]
    assert mcu["overruns"] == mcu["avr_rx_line_lost"] == mcu["corrupt_frames"] == 0
    assert summary["protocol"]["retransmits"] == 0
    events = [json.loads(line) for line in (tmp_path / "run" / "trace.jsonl").open()]
    hello_ack = [e["t_us"] for e in events if e["ev"] == "hello_ack"]
    assert len(hello_ack) == 1 and hello_ack[0] <= 40_000


def test_with_telemetry_off_the_idle_line_lasts_until_something_arrives():
    mcu = SimavrMcu()
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    mcu.uart_rx(m.encode_message(m.ParamSet(2, 0), 1), 60_000)  # telemetry_hz = 0
    mcu.advance_to(150_000)
    data = b"".join(d for _, d in mcu.uart_tx_take())
    assert m.ParamValue(2, 0) in [m.decode_frame(f) for f in FrameParser().feed(data)]
    assert mcu.tx_idle_through_us() > 10**15
    mcu.uart_rx(m.encode_message(m.Heartbeat(1), 2))
    assert mcu.tx_idle_through_us() == 150_000


def test_closing_a_sonar_slot_keeps_interrupts_off_within_budget():
    # an echo heard in every slot: the range's 32-bit division runs after the stamps are read
    mcu = SimavrMcu()
    mcu.set_sonar_provider(lambda i: 1.0)
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 20_000)
    mcu.advance_to(400_000)
    stats = mcu.stats()
    assert stats["avr_isr_max_cycles_INT6"] > 0  # the echoes were timed
    rows = {r["figure"]: r for r in profile_rows(stats)}
    off = rows["interrupts off"]
    assert 0 < off["worst"] <= off["budget"] and off["where"].startswith("pc 0x")
    assert "(pc 0x" in format_rows([off])


def test_the_start_up_and_a_param_set_take_no_32_bit_divisions():
    # reset to the main loop: the C runtime's .bss clearing (about 0.4 ms) and fw_setup, about
    # 2.2 ms; the receiver runs from .init3 and its handler from the sei before fw_setup, so a
    # frame sent during fw_setup is kept whole
    mcu = SimavrMcu()
    mcu.uart_rx(m.encode_message(m.Heartbeat(7), 7), 500)
    booted = mcu.run_until_booted(step_us=10)
    assert 1_000 <= booted <= 3_000
    mcu.advance_to(booted + 1_000)
    stats = mcu.stats()
    assert stats["overruns"] == 0 and stats["parser_frames_ok"] == 1
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0))
    mcu.advance_to(booted + 30_000)
    mcu.uart_tx_take()
    frame = m.encode_message(m.ParamSet(P_TELEMETRY_HZ, 25), 1)
    start = mcu.now_us
    mcu.uart_rx(frame)
    frame_end = start + len(frame) * mcu.byte_cycles // 16
    mcu.advance_to(start + 10_000)
    parser, acked = FrameParser(), []
    for t, data in mcu.uart_tx_take():
        acked += [t for f in parser.feed(data) if m.decode_frame(f) == m.Ack(1)]
    # the ACK's last stop bit within 3 ms of the frame's (its 7 bytes take 0.6 ms of that)
    assert len(acked) == 1 and acked[0] - frame_end <= 3_000


def test_bytes_sent_into_the_start_up_leave_the_rx_latency_to_the_bytes_received():
    # a HELLO at the reset instant: its first byte starts while the receiver is still off, the
    # USART holds three through the C runtime and the rest are lost; later frames come 100 ms
    # apart, and each byte's latency is its own (not the gap to an earlier, lost byte, nor the
    # start-up's wait of the bytes held)
    mcu = SimavrMcu()
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "t", 0), 0), 0)
    for seq, t in enumerate((100_000, 200_000), start=1):
        mcu.uart_rx(m.encode_message(m.Heartbeat(seq), seq), t)
    mcu.advance_to(300_000)
    stats = mcu.stats()
    assert stats["avr_rx_line_lost"] > 0 and stats["parser_frames_ok"] >= 2
    assert 0 < stats["avr_rx_latency_max_cycles"] <= RX_LATENCY_BUDGET_CYCLES


def test_encoder_edges_wake_their_handler_not_the_main_loop():
    # 6000 edges a second on each wheel (some 740 mm/s) for one second: the main loop runs only
    # for what falls due (PI at 100 Hz, telemetry at 50 Hz, a sonar slot every 30 ms, a servo
    # period every 20 ms, each at most once per Timer0 tick) and the core sleeps in between
    mcu = SimavrMcu()
    t0 = mcu.run_until_booted()
    passes0 = mcu.stats()["avr_loop_passes"]
    for k in range(1, 101):
        t = t0 + k * 10_000
        mcu.set_encoder_ticks(60 * k, -60 * k, t)
        mcu.advance_to(t)
    stats = mcu.stats()
    edges = sum(mcu.profile()["isr_count"].get(v, 0) for v in (1, 2, 3, 4))
    assert edges >= 11_000
    assert stats["avr_loop_passes"] - passes0 < 300
    assert stats["avr_load_permille"] <= 300


def test_encoder_edges_and_line_bytes_each_end_one_run_of_the_core():
    # four edges of the left wheel spread over 1 ms, then a 3-byte chunk on a line that holds
    # two: the core runs to each edge (250 us apart) and to each byte's start bit, the third
    # byte is dropped at the line, and each edge toggles one of A/B (INT0/INT1) once
    mcu = SimavrMcu(McuConfig(line_capacity_bytes=2))
    t0 = mcu.run_until_booted()
    mcu.advance_to(t0 + 1_000)
    t0 += 1_000
    before = mcu.stats()
    isr0 = mcu.profile()["isr_count"]
    mcu.set_encoder_ticks(4, 0, t0 + 1_000)
    mcu.advance_to(t0 + 1_100)
    isr1 = mcu.profile()["isr_count"]
    assert sum(isr1.get(v, 0) - isr0.get(v, 0) for v in (1, 2)) == 4
    assert mcu.stats()["events"] - before["events"] == 4 + 1  # to each edge, then the target
    assert mcu.uart_rx(b"\x00\x01\x02", t0 + 2_000) == 2
    mcu.advance_to(t0 + 3_000)
    after = mcu.stats()
    assert after["rx_line_dropped"] - before["rx_line_dropped"] == 1
    assert after["rx_bytes"] - before["rx_bytes"] == 2
    assert after["events"] - before["events"] == 5 + 3  # two start bits, then the target
    assert mcu.tx_idle_through_us() >= mcu.now_us  # the line is empty again


def test_a_coupling_step_reports_the_duties_the_wheel_registers_hold():
    # advance_outputs takes the wheel duties from the harness's report at the end of its one
    # call (sh_advance_to), wheel_duty() reads the timer and port registers: they agree at
    # every step, through the stop and a drive command that turns the wheels opposite ways
    mcu = SimavrMcu()
    host = InProcessHost(mcu)
    host.run_us(mcu.run_until_booted() - mcu.now_us)
    host.send(m.Hello(m.PROTOCOL_VERSION, "t", 0))
    seen = set()
    for k in range(80):
        if k % 8 == 4:
            host.send(m.SetWheels(200, -150))
        pulses, duty = mcu.advance_outputs(mcu.now_us + 2_500)
        host.collect()
        assert duty == mcu.wheel_duty()
        assert pulses == mcu.servo_pulses_us()
        seen.add(duty)
    assert (0, 0) in seen
    assert any(left > 0 > right for left, right in seen)
