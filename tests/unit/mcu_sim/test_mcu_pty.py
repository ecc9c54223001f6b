"""The emulated MCU over a real pty, through the pytest plugin's ``emulated_mcu`` fixture."""

from mobigrasp.protocol import (
    FLAG_HANDSHAKE,
    FLAG_RESET,
    FLAG_WATCHDOG,
    NACK_BAD_VERSION,
    NACK_NOT_READY,
    PROTOCOL_VERSION,
    Ack,
    Hello,
    HelloAck,
    Nack,
    SetServos,
    SetWheels,
    Telemetry,
    encode_message,
)

TARGETS = (1200, 1000, 1800, 2000, 1000, 2100)


def replies(msgs, cls):
    return [m for m in msgs if isinstance(m, cls)]


def wait_for(emu, wanted, tries=3):
    """Messages received by the host end until ``wanted`` shows up (bounded)."""
    got = []
    for _ in range(tries):
        got.extend(emu.receive(1, timeout_s=0.2))
        if wanted in got:
            break
    return got


def handshake(emu):
    seq = emu.send(Hello(PROTOCOL_VERSION, "pytest", 0))
    emu.advance_ms(12)  # the t=0 telemetry frame occupies the line for 4.4 ms first
    got = emu.receive(3)
    assert Ack(seq) in got
    acks = replies(got, HelloAck)
    assert acks and acks[0].proto_version == PROTOCOL_VERSION
    return got


def test_handshake_over_pty(emulated_mcu):
    assert emulated_mcu.port.startswith("/dev/")
    handshake(emulated_mcu)
    emulated_mcu.advance_ms(40)
    tel = emulated_mcu.telemetry()
    assert tel[0].flags & FLAG_RESET and not tel[-1].flags & FLAG_RESET
    assert tel[-1].flags & FLAG_HANDSHAKE
    # The host end received the same telemetry over the pty.
    assert replies(emulated_mcu.receive(1), Telemetry)


def test_bad_version_and_not_ready_are_nacked(emulated_mcu):
    emu = emulated_mcu
    seq = emu.send(SetServos(0, TARGETS, 0))
    emu.advance_ms(8)
    assert Nack(seq, NACK_NOT_READY) in emu.receive(2)
    seq = emu.send(Hello(PROTOCOL_VERSION + 1, "future", 0))
    emu.advance_ms(8)
    assert Nack(seq, NACK_BAD_VERSION) in emu.receive(1)
    emu.advance_ms(60)
    assert emu.servo_pulses_us() == (1000.0, 1500.0, 1500.0, 1500.0, 1500.0, 1500.0)


def test_set_servos_gives_measured_pulses_and_exact_period(emulated_mcu):
    emu = emulated_mcu
    handshake(emu)
    rises = []
    emu.mcu.servo_pin(3).subscribe(lambda t, v: rises.append(emu.mcu.servo_pin(3).last_cycle)
                                   if v else None)
    seq = emu.send(SetServos(0, TARGETS, 0))
    emu.advance_ms(45)  # the command lands mid-period; double buffering applies it next period
    assert Ack(seq) in emu.receive(1)
    lo_hi = [emu.mcu.firmware.servos.min_us[ch] for ch in range(6)], \
        [emu.mcu.firmware.servos.max_us[ch] for ch in range(6)]
    for ch, want in enumerate(TARGETS):
        want = min(max(want, lo_hi[0][ch]), lo_hi[1][ch])
        assert abs(emu.servo_pulses_us()[ch] - want) <= 0.5, ch
    periods = {b - a for a, b in zip(rises, rises[1:], strict=False)}
    assert periods == {20_000 * 16}  # exactly 20 ms in 16 MHz cycles


def test_watchdog_stops_wheels_within_250ms_plus_one_period(emulated_mcu):
    emu = emulated_mcu
    handshake(emu)
    emu.send(SetWheels(400, 400))
    emu.advance_ms(1)
    last_valid_us = emu.mcu.firmware.last_valid_us
    emu.advance_ms(100)
    assert emu.wheel_duty()[0] > 0 and emu.wheel_duty()[1] > 0
    stopped_at = None
    for _ in range(400):
        emu.advance_us(500)
        if emu.wheel_duty() == (0, 0):
            stopped_at = emu.now_us
            break
    assert stopped_at is not None
    assert stopped_at - last_valid_us <= 250_000 + 10_000
    assert stopped_at - last_valid_us >= 250_000
    emu.advance_ms(25)
    tel = emu.telemetry()[-1]
    assert tel.flags & FLAG_WATCHDOG and tel.watchdog_trips == 1
    # The next valid command clears it and drives again.
    emu.send(SetWheels(200, 200))
    emu.advance_ms(60)
    assert not emu.telemetry()[-1].flags & FLAG_WATCHDOG
    assert emu.wheel_duty()[0] > 0


def test_flood_faster_than_line_rate_counts_overruns_and_recovers(emulated_mcu):
    emu = emulated_mcu
    handshake(emu)
    flood = bytes(range(1, 256)) * 40  # 10 200 bytes of zero-free garbage in one burst
    emu.send_raw(flood)
    emu.advance_ms(10)
    assert emu.stats["overruns"] > 0
    emu.advance_ms(400)  # the line drains what it could carry
    cmd = SetServos(0, (1500, 1600, 1700, 1800, 1400, 1300), 0)
    # The garbage has no delimiter, so the first frame after it is glued to it and lost (COBS
    # resyncs at the next 0x00); the host's retransmission with the same seq gets through.
    seq, acked = None, False
    for _ in range(3):
        seq = emu.send(cmd, seq=seq if seq is not None else 1)
        emu.advance_ms(30)
        if Ack(seq) in wait_for(emu, Ack(seq)):
            acked = True
            break
    assert acked
    emu.advance_ms(40)
    assert emu.servo_pulses_us()[1] == 1600.0
    assert emu.telemetry()[-1].overruns == emu.stats["overruns"] & 0xFFFF


def test_corrupted_frames_never_actuate(emulated_mcu):
    emu = emulated_mcu
    handshake(emu)
    emu.advance_ms(30)
    before = emu.servo_pulses_us()
    wire = bytearray(encode_message(SetServos(0, (2000,) * 6, 0), 9))
    wire[5] ^= 0x40  # one flipped bit inside the frame
    emu.send_raw(bytes(wire))
    wheels = bytearray(encode_message(SetWheels(500, 500), 10))
    wheels[3] ^= 0x01
    emu.send_raw(bytes(wheels))
    emu.advance_ms(60)
    assert emu.servo_pulses_us() == before
    assert emu.wheel_duty() == (0, 0)
    assert emu.stats["corrupt_frames"] == 2
    assert emu.telemetry()[-1].crc_errors == 2


def test_plugin_example_of_docs_firmware_md(emulated_mcu):
    seq = emulated_mcu.send(Hello(1, "me", 0))
    emulated_mcu.advance_ms(12)
    assert Ack(seq) in emulated_mcu.receive(2)
    emulated_mcu.send(SetServos(0, (1500,) * 6, 0))
    emulated_mcu.advance_ms(45)
    assert emulated_mcu.servo_pulses_us()[1] == 1500.0
    assert emulated_mcu.telemetry()[-1].flags & 4
