"""The ATmega128 program: start-up, interrupt handlers and the event-driven main loop.

Written to map one-to-one onto C: every buffer is allocated in ``__init__``/``setup`` (the C
globals) and reused; the loop does integer arithmetic only. The handlers are what the vectors
call; each only stores what happened: ``isr_usart_rx`` (USART0_RX: byte into the RX ring),
``isr_timer1_ovf`` (TIMER1_OVF: a servo period began, flag for the main loop), ``isr_encoder``
(INT0..3, quadrature edges) and ``isr_echo`` (sonar echo edges). ``loop`` is one pass of the main
loop: the servo period's OCR writes if one began, drain the RX ring into the frame parser and
dispatch frames, then only what is due: wheel PI (100 Hz), watchdog, sonar slot, telemetry. It
returns the earliest time (µs since reset) at which something will be due. The part then sleeps
until a handler leaves work (``work_pending``) or, at Timer0's 1.024 ms tick, that time has come
(firmware/hal_avr.c, wait_for_work); the emulator runs the next pass at the next such event.

What each command does is in ``dispatch.py`` (the C port's ``switch (msg_type)``).
"""

from __future__ import annotations

import struct

from mobigrasp.mcu_sim.firmware import params as P
from mobigrasp.mcu_sim.firmware.cycles import CycleMeter
from mobigrasp.mcu_sim.firmware.dispatch import handle_frame
from mobigrasp.mcu_sim.firmware.ring import ByteRing
from mobigrasp.mcu_sim.firmware.servo_table import (
    GRIPPER_OPEN_US,
    MECH_MAX_US,
    MECH_MIN_US,
    SERVO_COUNT,
    ServoBank,
)
from mobigrasp.mcu_sim.firmware.sonar_task import SonarTask
from mobigrasp.mcu_sim.firmware.sram import DUP_WINDOW, RX_RING_BYTES
from mobigrasp.mcu_sim.firmware.wheel_pi import CONTROL_PERIOD_US, WheelPi
from mobigrasp.protocol.frame import MAX_PAYLOAD, PROTOCOL_VERSION, FrameParser, encode_raw
from mobigrasp.protocol.messages import (
    FLAG_GRIPPER_CLOSED,
    FLAG_HANDSHAKE,
    FLAG_LIMIT,
    FLAG_RESET,
    FLAG_STOPPED,
    FLAG_WATCHDOG,
    Ack,
    Telemetry,
    encode_message,
)
from mobigrasp.protocol.reliable import DuplicateFilter, SequenceCounter

# Rows of Params.values the main loop reads on every pass: indexed directly instead of through
# Params.get's id look-up (the list is only ever written in place, by set and reset).
_I_WATCHDOG_MS = P.PARAM_INDEX[P.P_WATCHDOG_MS]
_I_SONAR_COUNT = P.PARAM_INDEX[P.P_SONAR_COUNT]
_I_SONAR_SLOT_MS = P.PARAM_INDEX[P.P_SONAR_SLOT_MS]
_I_TELEMETRY_HZ = P.PARAM_INDEX[P.P_TELEMETRY_HZ]
_I_WHEEL_KP = P.PARAM_INDEX[P.P_WHEEL_KP]
_I_WHEEL_KI = P.PARAM_INDEX[P.P_WHEEL_KI]

# the RX handler wakes the main loop at a frame's delimiter (COBS: 0x00 nowhere else) or once
# this many bytes wait without one, so garbage cannot fill the ring before the loop drains it
RX_WAKE_BYTES = 64
TELEMETRY_STRUCT = struct.Struct("<Iii6H5H5H")  # time, encoders, servos, sonars, flags+4 counters
TELEMETRY_TYPE = Telemetry.MSG_TYPE
ACK_TYPE = Ack.MSG_TYPE
assert TELEMETRY_STRUCT.size <= MAX_PAYLOAD  # what a Frame would check on every telemetry
ICR_20MS = 39999  # TOP for 20 ms at 0.5 µs ticks
TCCRA_SERVO = 0b1010_1010  # COMnA/B/C = 10 (non-inverting), WGMn1:0 = 10
TCCRB_SERVO = 0b0001_1010  # WGMn3:2 = 11 (mode 14), CSn = 010 (clk/8)


def _i32(x: int) -> int:
    return ((x + 0x8000_0000) & 0xFFFF_FFFF) - 0x8000_0000


class Firmware:
    """Globals of the C program plus its handlers; ``hw`` is a :class:`mcu_sim.avr.board.Board`."""

    def __init__(self, hw, param_overrides: dict[int, int] | None = None) -> None:
        self.hw = hw
        self.rx = ByteRing(RX_RING_BYTES)
        self.parser = FrameParser()
        self.servos = ServoBank()
        self.params = P.Params()
        self.wheels = (WheelPi(), WheelPi())
        self.sonar = SonarTask()
        self.enc_count = [0, 0]
        self.duty_out = [0, 0]  # last duty written to the bridge registers
        self.cycles = CycleMeter()  # the AVR cycles this work would take (a report only)
        for pid, value in dict(param_overrides or {}).items():
            # build-time power-on values: the same checks as a PARAM_SET, so no build can
            # widen a safety limit either
            reason = self.params.check(pid, value)
            if reason:
                raise ValueError(f"parameter {pid}={value} refused (NACK reason {reason})")
            self.params.set_default(pid, value)
        self.setup()

    # -- start-up ------------------------------------------------------------------------------
    def setup_rx(self) -> None:
        """The receiving side, first of all (``fw_setup_rx``): on the part the receiver and
        interrupts are enabled right after it, so bytes are kept while the rest starts up."""
        self.rx.clear()
        self.rx.overruns = 0
        self.parser.reset()
        self.parser.stats.__init__()
        self.rx_frame_due = False

    def setup(self) -> None:
        """``main()`` before the loop: :meth:`setup_rx`, then (``fw_setup``) state to power-on
        values, peripherals configured."""
        hw = self.hw
        self.cycles.charge("startup")
        self.cycles.soft_pwm(False, hw.cycle)  # the reset stops Timer2's interrupts
        self.setup_rx()
        # a reset zeroes the C globals: the TX sequence counter and the duplicate filter's
        # counters start again too
        self.dup = DuplicateFilter(DUP_WINDOW)
        self.tx_seq = SequenceCounter()
        self.params.reset()
        self.servos.reset()
        self.apply_servo_limits()
        self.enc_count[0] = self.enc_count[1] = 0
        self.duty_out[0] = self.duty_out[1] = 0
        for wheel in self.wheels:
            wheel.reset(0)
        self.drive_enabled = False
        self.handshake = False
        self.stopped = False
        self.limit_flag = False
        self.reset_flag = True
        self.watchdog_tripped = False
        self.limit_hits = 0
        self.watchdog_trips = 0
        self.bad_frames = 0
        self.not_ready = 0
        self.unexpected = 0
        self.tx_dropped = 0
        self.telemetry_sent = 0
        self.servo_period_due = False
        for timer in (hw.timer1, hw.timer3):
            timer.write_tccra(TCCRA_SERVO)
            timer.write_icr(ICR_20MS)
        for ch in range(SERVO_COUNT):
            self.write_ocr(ch)
        self.servos.latch()
        for timer in (hw.timer1, hw.timer3):
            timer.write_tccrb(TCCRB_SERVO, hw.cycle)
        for wheel in (hw.wheel_left, hw.wheel_right):
            wheel.start(hw.cycle)
            wheel.write_direction(False, hw.cycle)
            wheel.write_ocr(0, hw.cycle)
        now = hw.micros()
        self.last_valid_us = now
        self.next_control_us = now + CONTROL_PERIOD_US
        # the first telemetry at once, the later ones on multiples of their period (program.c)
        hz = self.params.values[_I_TELEMETRY_HZ]
        self.next_telemetry_us = now - now % (1_000_000 // hz) if hz else now
        self.sonar.reset(now)

    # -- interrupt handlers --------------------------------------------------------------------
    def isr_usart_rx(self, byte: int) -> None:
        """USART0 RX complete: into the ring (overrun counted when full); a delimiter, or
        ``RX_WAKE_BYTES`` waiting, is work for the main loop."""
        self.cycles.charge("isr_usart0_rx")
        self.rx.put(byte)
        if byte == 0 or len(self.rx) >= RX_WAKE_BYTES:
            self.rx_frame_due = True

    def isr_usart_rx_bytes(self, data: bytes) -> None:
        """Several RX-complete interrupts in a row (the emulator batches them), oldest first."""
        self.cycles.charge("isr_usart0_rx", len(data))
        self.rx.put_bytes(data)
        # the ring only fills between passes: at or past the mark after the batch means at or
        # past it after its last byte
        if 0 in data or len(self.rx) >= RX_WAKE_BYTES:
            self.rx_frame_due = True

    def isr_timer1_ovf(self) -> None:
        """Timer1 (and 3, started together) period start: work for the main loop."""
        self.cycles.charge("isr_timer1_ovf")
        self.servo_period_due = True

    def _servo_period(self) -> None:
        """A period began: the pending widths are in force; step every moving channel and write
        its OCR for the period after (latched at the next BOTTOM)."""
        servos = self.servos
        servos.latch()
        target, latched = servos.target_q8, servos.latched_q8
        if target == latched:  # the whole arm at rest (most periods): no channel to write
            return
        for ch in range(SERVO_COUNT):
            # A channel at rest keeps its OCR value: nothing to write (saves ISR time in C too).
            if target[ch] != latched[ch]:
                self.write_ocr(ch)

    def isr_encoder(self, side: int, edges: int) -> None:
        """Encoder edges of wheel ``side`` (0 left, 1 right): ``edges`` ISR calls of +-1."""
        self.cycles.charge("isr_encoder", abs(edges))
        self.enc_count[side] += edges

    def isr_echo(self, index: int, level: int) -> None:
        """Echo pin of sonar ``index`` changed to ``level``."""
        self.cycles.charge("isr_echo")
        self.sonar.on_echo(index, level, self.hw.micros())

    # -- main loop -----------------------------------------------------------------------------
    def loop(self) -> int:
        """One pass of the main loop; returns the next time (µs since reset) something is due."""
        hw = self.hw
        cycles = self.cycles
        cycles.charge("loop_pass")
        now = hw.micros()
        if self.servo_period_due:
            self.servo_period_due = False
            self._servo_period()
        self.rx_frame_due = False  # the drain below takes every byte received so far
        rx = self.rx
        if rx.head != rx.tail:  # take_all() of an empty ring is b"" (most passes: timed work)
            data = rx.take_all()
            cycles.charge("rx_byte_decode", len(data))
            for frame in self.parser.feed(data):
                cycles.charge("frame_dispatch")
                handle_frame(self, frame, now)
        pv = self.params.values
        if now >= self.next_control_us:
            cycles.charge("wheel_pi_drive" if self.drive_enabled else "wheel_pi")
            self._control()
            self.next_control_us += CONTROL_PERIOD_US
            if self.next_control_us <= now:
                self.next_control_us = now + CONTROL_PERIOD_US
        wd_us = pv[_I_WATCHDOG_MS] * 1000
        if wd_us and not self.watchdog_tripped and now - self.last_valid_us >= wd_us:
            self._trip_watchdog()
        if now >= self.sonar.next_slot_us:
            cycles.charge("sonar_slot")
            self.sonar.end_slot()
            index = self.sonar.start_slot(pv[_I_SONAR_COUNT], now, pv[_I_SONAR_SLOT_MS] * 1000)
            if index is not None:
                hw.sonars.trigger(index, hw.cycle)
        hz = pv[_I_TELEMETRY_HZ]
        if hz and now >= self.next_telemetry_us:
            cycles.charge("telemetry")
            self._send_telemetry(now)
            period = 1_000_000 // hz
            self.next_telemetry_us += period
            if self.next_telemetry_us <= now:
                self.next_telemetry_us = now + period
        due = min(self.next_control_us, self.sonar.next_slot_us)
        if hz and self.next_telemetry_us < due:
            due = self.next_telemetry_us
        if wd_us and not self.watchdog_tripped and self.last_valid_us + wd_us < due:
            due = self.last_valid_us + wd_us
        return due

    def load_stats(self, elapsed_cycles: int) -> dict[str, int]:
        """The AVR load this work would make over ``elapsed_cycles`` since power-on, as simavr's
        ``avr_load_permille`` (mcu_sim/firmware/cycles.py)."""
        return {"avr_load_permille": self.cycles.load_permille(elapsed_cycles)}

    def work_pending(self) -> bool:
        """True while a handler left work for the main loop (a frame's end in the RX ring, or
        ``RX_WAKE_BYTES`` without one; a servo period): what ends the part's sleep besides a
        due time."""
        return self.rx_frame_due or self.servo_period_due

    def next_unprompted_send_us(self) -> int | None:
        """When the main loop next sends something nobody asked for (µs since reset): the next
        telemetry; None if telemetry is off. Every other message answers a received frame
        (dispatch.handle_frame). The rig uses it to hand the host a grant early (mcu.py
        tx_idle_through_us)."""
        return self.next_telemetry_us if self.params.values[_I_TELEMETRY_HZ] else None

    # -- outputs -------------------------------------------------------------------------------
    def write_ocr(self, ch: int) -> None:
        """Step channel ``ch`` towards its target and write its OCR (latched at BOTTOM)."""
        timer, idx = self.hw.servo_timer(ch)
        timer.write_ocr(idx, self.servos.next_pending(ch))

    def write_all_ocrs(self) -> None:
        """:meth:`write_ocr` of channels 0..5 in order (after a command that sets them all)."""
        next_pending = self.servos.next_pending
        hw = self.hw
        for ch in range(3):  # Board.servo_timer: channels 0..2 on Timer1, 3..5 on Timer3
            hw.timer1.write_ocr(ch, next_pending(ch))
        for ch in range(3):
            hw.timer3.write_ocr(ch, next_pending(ch + 3))

    def _set_duty(self, side: int, duty: int) -> None:
        if duty == self.duty_out[side]:
            return
        self.duty_out[side] = duty
        wheel = self.hw.wheel_right if side else self.hw.wheel_left
        cycle = self.hw.cycle
        if side:
            self.cycles.soft_pwm(0 < abs(duty) < 255, cycle)
        wheel.write_direction(duty < 0, cycle)
        wheel.write_ocr(-duty if duty < 0 else duty, cycle)

    def stop_wheels(self) -> None:
        """Bridges off now, PI state cleared, drive disabled until the next SET_WHEELS."""
        self.drive_enabled = False
        for side in (0, 1):
            self.wheels[side].stop(self.enc_count[side])
            self._set_duty(side, 0)

    def hold_arm(self) -> None:
        """Every servo stays at the width in force."""
        self.servos.hold()
        self.write_all_ocrs()

    def _trip_watchdog(self) -> None:
        self.watchdog_tripped = True
        self.watchdog_trips += 1
        self.stop_wheels()
        self.hold_arm()

    def _control(self) -> None:
        pv = self.params.values
        kp = pv[_I_WHEEL_KP]
        ki = pv[_I_WHEEL_KI]
        for side in (0, 1):
            if self.drive_enabled:
                duty = self.wheels[side].update(self.enc_count[side], kp, ki)
            else:
                self.wheels[side].last_count = self.enc_count[side]
                duty = 0
            self._set_duty(side, duty)

    def send(self, msg) -> None:
        """Queue a message for the host (dropped and counted if the TX ring is full)."""
        wire = encode_message(msg, self.tx_seq.next())
        self.cycles.charge("tx_byte_encode", len(wire))
        self._tx(wire)

    def send_ack(self, acked_seq: int) -> None:
        """``send(Ack(acked_seq))`` for the seq of a received frame (a u8), its one-byte
        payload filled directly as the C port does: the reply to every reliable command."""
        wire = encode_raw(PROTOCOL_VERSION, self.tx_seq.next(), ACK_TYPE, bytes((acked_seq,)))
        self.cycles.charge("tx_byte_encode", len(wire))
        self._tx(wire)

    def _tx(self, wire: bytes) -> None:
        # into the TX ring, one UDRE interrupt a byte sends it (dropped and counted when full)
        if self.hw.usart0.tx_write(wire, self.hw.cycle):
            self.cycles.charge("isr_usart0_udre", len(wire))
        else:
            self.tx_dropped += 1

    def _flags(self) -> int:
        flags = FLAG_HANDSHAKE if self.handshake else 0
        if self.watchdog_tripped:
            flags |= FLAG_WATCHDOG
        if self.limit_flag:
            flags |= FLAG_LIMIT
        if self.stopped:
            flags |= FLAG_STOPPED
        if self.reset_flag:
            flags |= FLAG_RESET
        if self.servos.target_q8[0] >= (GRIPPER_OPEN_US + 500) << 8:
            flags |= FLAG_GRIPPER_CLOSED
        return flags

    def corrupt_frames(self) -> int:
        """Frames the parser rejected as damaged (CRC, COBS, runt, oversize, wrong version)."""
        s = self.parser.stats
        return s.crc_errors + s.cobs_errors + s.truncated + s.oversize + s.bad_version

    def overruns(self) -> int:
        """Bytes lost on reception: RX ring full, or more than the line could carry."""
        return self.rx.overruns + self.hw.usart0.rx_line_dropped

    def _send_telemetry(self, now: int) -> None:
        # Packed field by field into the frame buffer, as the C port fills a packed struct; the
        # layout is Telemetry's (tests check the bytes against Telemetry.encode()).
        servos = self.servos
        sonar = self.sonar.range_mm
        payload = TELEMETRY_STRUCT.pack(
            now & 0xFFFF_FFFF, _i32(self.enc_count[0]), _i32(self.enc_count[1]),
            servos.latched_us(0), servos.latched_us(1), servos.latched_us(2),
            servos.latched_us(3), servos.latched_us(4), servos.latched_us(5),
            sonar[0], sonar[1], sonar[2], sonar[3], sonar[4],
            self._flags(), self.corrupt_frames() & 0xFFFF, self.overruns() & 0xFFFF,
            self.limit_hits & 0xFFFF, self.watchdog_trips & 0xFFFF,
        )
        # what encode_frame(Frame(...)) gives, without building the Frame: its checks hold by
        # construction (version and type are constants, seq comes from the 8-bit counter and
        # the payload is TELEMETRY_STRUCT.size = 44 bytes)
        wire = encode_raw(PROTOCOL_VERSION, self.tx_seq.next(), TELEMETRY_TYPE, payload)
        self._tx(wire)
        self.telemetry_sent += 1
        self.limit_flag = False
        self.reset_flag = False

    # -- helpers the command dispatch (dispatch.py) calls ----------------------------------------
    def count_limit(self) -> None:
        """A command was clamped: count it and flag the next telemetry."""
        self.limit_hits += 1
        self.limit_flag = True

    def apply_servo_limits(self) -> None:
        """Copy the servo limit PARAMs into the servo bank and rewrite the OCRs (clamped)."""
        servos = self.servos
        for ch in range(SERVO_COUNT):
            # the PARAM checks keep these inside the mechanical limits; clamping again here
            # keeps the servo bank inside them whatever reaches the PARAM array
            lo = self.params.get(P.P_SERVO_MIN_BASE + ch)
            hi = self.params.get(P.P_SERVO_MAX_BASE + ch)
            servos.min_us[ch] = min(max(lo, MECH_MIN_US[ch]), MECH_MAX_US[ch])
            servos.max_us[ch] = min(max(hi, servos.min_us[ch]), MECH_MAX_US[ch])
            self.write_ocr(ch)

    def set_wheels(self, left_mmps: int, right_mmps: int) -> None:
        """New wheel speed targets (mm/s), clamped to ``wheel_max_mmps``; enables the drive."""
        limit = self.params.get(P.P_WHEEL_MAX_MMPS)
        for side, mmps in ((0, left_mmps), (1, right_mmps)):
            clamped = min(max(mmps, -limit), limit)
            if clamped != mmps:
                self.count_limit()
            if not self.drive_enabled:
                self.wheels[side].reset(self.enc_count[side])
            self.wheels[side].set_target(clamped)
        self.drive_enabled = True
        self.stopped = False
