"""The MCU's per-coupling-step shortcuts (perf round 5) give exactly what the general code gives.

``Mcu`` answers the common do-nothing cases of a coupling step without the general calls (no TX
byte finished, a standing wheel, no edge due on a timer, an idle RX line, a tuple of servo widths
that did not change), and ``Timer16`` keeps ``next_edge`` and precomputes pulse widths. Each
reference class below is the general code as it was before, kept here to compare with: the same
inputs must give the same bytes, widths, duties, signal samples and counters.
"""

from __future__ import annotations

import random

from mobigrasp.cosim.faulted_host import wrap_for_faults
from mobigrasp.mcu_sim.avr.board import CYCLES_PER_US
from mobigrasp.mcu_sim.avr.signals import SignalBus
from mobigrasp.mcu_sim.avr.timer8 import WheelPwm
from mobigrasp.mcu_sim.avr.timer16 import NS_PER_CYCLE_NUM, Timer16
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.safety import _RANGES, PWM_LATCH_US, STOP_MARGIN_US, SafetyMonitor
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import (
    PROTOCOL_VERSION,
    Ack,
    Gripper,
    Hello,
    ParamSet,
    SetServos,
    SetWheels,
    Stop,
    encode_message,
)


class ReferenceMcu(Mcu):
    """The coupling-step calls of ``Mcu`` without their shortcuts (the code before round 5)."""

    def advance_to(self, t_us: int) -> None:
        target = int(t_us) * CYCLES_PER_US
        if target < self._cycle:
            raise ValueError("back in time")
        b = self.board
        usart, timer1, sonars = b.usart0, b.timer1, b.sonars
        while True:
            nxt = self._deadline
            r = usart.next_rx_wakeup(self._rx_batch)
            if r is not None and r < nxt:
                nxt = r
            tb = timer1.next_bottom
            if tb is not None and tb < nxt:
                nxt = tb
            s = sonars.next_event()
            if s is not None and s < nxt:
                nxt = s
            if nxt > target:
                break
            self._step(nxt)
        self._cycle = target
        b.cycle = target
        self._peripherals_to(target)

    def _peripherals_to(self, cycle: int) -> int:
        b = self.board
        bottoms = 0
        for t in (b.timer1, b.timer3):
            nb = t.next_bottom
            if nb is not None and (nb <= cycle or (t._falls and t._falls[0][0] <= cycle)):
                n = t.advance_to(cycle)
                if t is b.timer1:
                    bottoms = n
        for wheel in (b.wheel_left, b.wheel_right):
            wheel.advance_to(cycle)
        return bottoms

    def _step(self, cycle: int) -> None:
        self.events += 1
        b = self.board
        fw = self.firmware
        self._cycle = cycle
        b.cycle = cycle
        for _ in range(self._peripherals_to(cycle)):
            fw.isr_timer1_ovf()
        data = b.usart0.rx_take_until(cycle)
        if data:
            fw.isr_usart_rx_bytes(data)
        if b.sonars.next_event() is not None:
            for _, index, level in b.sonars.take_events_until(cycle):
                fw.isr_echo(index, level)
        for side, enc in ((0, b.enc_left), (1, b.enc_right)):
            edges = enc.take_edges(cycle)
            if edges:
                fw.isr_encoder(side, edges)
        due = b.reset_cycle + fw.loop() * CYCLES_PER_US
        self._deadline = due if due > cycle else cycle + CYCLES_PER_US

    def uart_tx_take(self) -> list[tuple[int, bytes]]:
        out = self._tx_out + self._take_tx()
        self._tx_out = []
        return out

    def tx_idle_through_us(self) -> int:
        usart = self.board.usart0
        now = self._cycle // CYCLES_PER_US
        if usart.next_tx_cycle() is not None or usart.next_rx_cycle() is not None \
                or len(self.firmware.rx):
            return now
        due = self.firmware.next_unprompted_send_us()
        if due is None:
            return 1 << 62
        return max(now, (self.board.reset_cycle + due * CYCLES_PER_US) // CYCLES_PER_US)

    def servo_pulses_us(self) -> tuple[float, ...]:
        w1, w3 = self.board.timer1.last_width_ns, self.board.timer3.last_width_ns
        return tuple(w / 1000.0 for w in (*w1, *w3))

    def set_encoder_ticks(self, left, right, t_us=None) -> None:
        t = self._cycle if t_us is None else int(t_us) * CYCLES_PER_US
        self.board.enc_left.set_ticks(left, t, self._cycle)
        self.board.enc_right.set_ticks(right, t, self._cycle)

    def wheel_duty(self) -> tuple[int, int]:
        return self.board.wheel_left.signed_duty, self.board.wheel_right.signed_duty


def _commands(rng: random.Random) -> dict[int, bytes]:
    """Host bytes by send time (µs): a handshake, then wheels, servos, gripper, PARAMs, STOPs,
    line noise, and a silence long enough for the watchdog."""
    out: dict[int, bytes] = {2_000: encode_message(Hello(PROTOCOL_VERSION, "t", 0), 0)}
    seq = 1
    for t in range(20_000, 1_400_000, 20_000):
        if 700_000 <= t < 1_000_000:
            continue  # host silent: the watchdog stops the wheels
        v = rng.choice((0, 0, rng.randrange(-900, 900)))
        wire = encode_message(SetWheels(v, -v // 2), 0)
        r = rng.random()
        if r < 0.3:
            targets = tuple(rng.randrange(600, 2400) for _ in range(6))
            wire += encode_message(SetServos(0, targets, rng.choice((0, 500, 3000))), seq)
        elif r < 0.4:
            wire += encode_message(Gripper(rng.randrange(0, 1001)), seq)
        elif r < 0.45:
            wire += encode_message(ParamSet(2, rng.choice((0, 25, 50, 100))), seq)
        elif r < 0.48:
            wire += encode_message(Stop(), seq)
        elif r < 0.52:
            wire += bytes(rng.randrange(256) for _ in range(rng.randrange(1, 40)))
        seq = (seq + 1) & 0xFF
        out[t + rng.randrange(0, 5_000)] = wire
    return out


def _drive(cls: type[Mcu], seed: int, wrapped: bool = False) -> list:
    """Couple an MCU of class ``cls`` like the rig does (1 ms steps, some off the grid), with
    encoder counts from its duties (standing wheels included) and sonar ranges by time; returns
    everything observable."""
    rng = random.Random(seed)
    mcu = cls()
    log: list = []
    for name in sorted(f"servo{ch}.{kind}" for ch in range(6) for kind in ("pin", "pulse_ns")):
        mcu.board.bus.port(name).subscribe(lambda t, v, name=name: log.append((name, t, v)))
    for name in ("wheel_left.duty", "wheel_right.duty"):
        mcu.board.bus.port(name).subscribe(lambda t, v, name=name: log.append((name, t, v)))
    target = mcu
    fault_rig = None
    if wrapped:
        fault_rig, target, _, _ = wrap_for_faults(FaultPlan(), seed, mcu, object(), None)
    target.set_sonar_provider(lambda i: None if (mcu.now_us // 7_000 + i) % 4 == 0
                              else 0.3 + 0.1 * i + (mcu.now_us % 900) / 1000)
    commands = _commands(rng)
    pos = [0.0, 0.0]
    t = 0
    while t < 1_500_000:
        t += rng.choice((1_000, 1_000, 1_000, 333, 2_500))
        for send in [s for s in commands if s <= t]:
            target.uart_rx(commands.pop(send), send)
        pulses, duty = target.advance_outputs(t)
        log.append(("out", t, pulses, duty))
        for side in (0, 1):
            pos[side] += duty[side] * 0.01
        counts = [round(p) for p in pos]
        if rng.random() < 0.01:
            counts[0] = float(counts[0])  # not an int: counted as a bad input, ignored
        target.set_encoder_ticks(counts[0], counts[1], t + rng.choice((0, 1_000)))
        log.append(("tx", target.uart_tx_take()))
        log.append(("idle", target.tx_idle_through_us()))
        if t // 100_000 != (t - 1_000) // 100_000 and rng.random() < 0.3:
            log.append(("pulse", [mcu.servo_pulse_us(ch) for ch in range(6)]))
        if 1_200_000 <= t < 1_201_000:
            mcu.reset()  # bytes in flight are handed over once (the _tx_out path)
    # the firmware's counters; not the AVR load the model reports, which charges each main-loop
    # pass and the reference runs one at every event
    counters = {k: v for k, v in mcu.stats().items() if k != "avr_load_permille"}
    log.append(("stats", counters, mcu.board.enc_left.bad_inputs, mcu.firmware.enc_count))
    if fault_rig is not None:
        log.append(("faults", fault_rig.summary()))
    return log


def test_fast_coupling_paths_equal_the_general_ones():
    for seed in (1, 2, 3):
        fast = _drive(Mcu, seed)
        assert fast == _drive(ReferenceMcu, seed)
        assert any(entry[0] == "tx" and entry[1] for entry in fast)  # bytes did go out


def test_fast_paths_through_the_fault_wrapper_with_an_empty_plan():
    assert _drive(Mcu, 4, wrapped=True) == _drive(ReferenceMcu, 4, wrapped=True)


def _replies_every_us(cls: type[Mcu]) -> list:
    """A HELLO and a PARAM write answered while the caller looks every µs: hits the exact
    cycle each stop bit leaves (the edge of uart_tx_take's shortcut) and every RX wake-up."""
    mcu = cls()
    mcu.uart_rx(encode_message(Hello(PROTOCOL_VERSION, "t", 0), 0), 100)
    mcu.uart_rx(encode_message(ParamSet(2, 100), 1), 3_000)
    log = []
    for t in range(0, 12_000):
        mcu.advance_to(t)
        log.append((mcu.uart_tx_take(), mcu.tx_idle_through_us(), mcu.servo_pulses_us()))
    return log


def test_tx_taken_at_every_us_equals_the_general_path():
    fast = _replies_every_us(Mcu)
    assert sum(len(taken) for taken, _, _ in fast) > 4  # ACKs, HELLO_ACK, PARAM_VALUE, telemetry
    assert fast == _replies_every_us(ReferenceMcu)


class ReferenceTimer16(Timer16):
    """Timer16's event engine before round 5: widths from the stored rising edges."""

    def _start_period(self, cycle: int) -> None:
        if not hasattr(self, "_rise"):
            self._rise = [0, 0, 0]
        self._icr_active = self.icr
        self.ocr_active = list(self.ocr_buffer)
        self._period_start = cycle
        self.next_bottom = cycle + self.period_cycles
        falls = []
        for ch in range(3):
            if not self._channel_enabled(ch):
                continue
            self._rise[ch] = cycle
            self._pins[ch].emit(cycle, 1, self.cycles_per_us)
            if self.ocr_active[ch] < self._icr_active:
                falls.append((cycle + (self.ocr_active[ch] + 1) * self._prescale, ch))
        falls.sort()
        self._falls = falls

    def advance_to(self, cycle: int) -> int:
        bottoms = 0
        while self.next_bottom is not None:
            if self._falls and self._falls[0][0] <= cycle:
                fall, ch = self._falls.pop(0)
                width_ns = (fall - self._rise[ch]) * NS_PER_CYCLE_NUM // self.cycles_per_us
                self.last_width_ns[ch] = width_ns
                self._pins[ch].emit(fall, 0, self.cycles_per_us)
                self._pulses[ch].emit(fall, width_ns, self.cycles_per_us)
                continue
            if self.next_bottom <= cycle:
                self.overflows += 1
                bottoms += 1
                self._start_period(self.next_bottom)
                continue
            break
        return bottoms


def _timer_program(cls: type[Timer16], seed: int, subscribed: bool = True) -> tuple[list, list]:
    rng = random.Random(seed)
    bus = SignalBus()
    t = cls("T", bus, ("a", "b", "c"))
    seen: list = []
    ports = [bus.port(name) for name in bus.names()]
    if subscribed:
        for port in ports:
            port.subscribe(lambda time, v, name=port.name: seen.append((name, time, v)))
    state = []
    cycle = 0
    t.write_tccra(0b1010_1010)  # WGMn1:0 of mode 14 (every write below keeps them)
    t.write_icr(39_999)  # (TOP 0 would give a period of one prescaled tick)
    for _ in range(400):
        op = rng.random()
        if op < 0.05:
            t.write_tccra(rng.choice((0b1010_1010, 0b1000_0010, 0b0010_1010, 0b0000_0010)))
        elif op < 0.08:
            t.write_icr(rng.choice((39_999, 20_000, 9_999)))
        elif op < 0.1:
            t.write_tccrb(rng.choice((0b0001_1010, 0b0001_1000, 0b0001_1001)), cycle)
        elif op < 0.4:
            t.write_ocr(rng.randrange(3), rng.choice((999, 2_999, 4_999, 39_999, 50_000)))
        else:
            cycle += rng.choice((1, 997, 16_000, 64_000, 320_000, 1_000_000))
            state.append(t.advance_to(cycle))
        if cls is Timer16:
            assert t.next_edge == t.next_event()
        state.append((list(t.last_width_ns), t.overflows, t.next_event(), t.tcnt(cycle)))
        state.append([(p.value, p.t_us, p.last_cycle) for p in ports])
    return seen, state


def test_timer16_engine_equals_the_general_one_and_next_edge_is_next_event():
    for seed in range(6):
        assert _timer_program(Timer16, seed) == _timer_program(ReferenceTimer16, seed)


def test_timer16_ports_without_subscribers_hold_what_emit_would_set():
    for seed in range(6):
        seen, state = _timer_program(Timer16, seed)
        assert seen  # the subscribed run did call back
        assert _timer_program(Timer16, seed, subscribed=False) == ([], state)


def test_send_ack_puts_the_bytes_of_send_ack_message_on_the_line():
    fast, general = Mcu(), Mcu()
    for acked in (0, 1, 127, 128, 254, 255):
        for _ in range(300):  # every TX sequence number, wrapping
            fast.firmware.send_ack(acked)
            general.firmware.send(Ack(acked))
            fast.board.usart0.reset()
            general.board.usart0.reset()
        fast.firmware.send_ack(acked)
        general.firmware.send(Ack(acked))
        assert fast.board.usart0.tx_queue == general.board.usart0.tx_queue
    assert fast.firmware.tx_seq.peek() == general.firmware.tx_seq.peek()


def test_write_all_ocrs_equals_write_ocr_of_each_channel():
    rng = random.Random(5)
    fast, general = Mcu(), Mcu()
    for _ in range(200):
        targets = [(rng.randrange(400, 2600), rng.choice((0, 100, 5000))) for _ in range(6)]
        latched = [rng.randrange(500 << 8, 2500 << 8) for _ in range(6)]
        for mcu in (fast, general):
            servos = mcu.firmware.servos
            for ch, (pulse, slew) in enumerate(targets):
                servos.set_target_us(ch, pulse, slew)
            servos.latched_q8[:] = latched
        fast.firmware.write_all_ocrs()
        for ch in range(6):
            general.firmware.write_ocr(ch)
        for a, b in ((fast.board.timer1, general.board.timer1),
                     (fast.board.timer3, general.board.timer3)):
            assert a.ocr_buffer == b.ocr_buffer and a.ocr_active == b.ocr_active
        assert fast.firmware.servos.pending_q8 == general.firmware.servos.pending_q8


def test_wheel_duty_now_is_signed_duty_after_every_write():
    rng = random.Random(6)
    wheel = WheelPwm("w", SignalBus())
    cycle = 0
    for _ in range(2_000):
        op = rng.random()
        if op < 0.1:
            wheel.reset()
        elif op < 0.2:
            wheel.start(cycle)
        elif op < 0.5:
            wheel.write_ocr(rng.randrange(-10, 300), cycle)
        elif op < 0.7:
            wheel.write_direction(rng.random() < 0.5, cycle)
        else:
            cycle += rng.choice((1, 5_000, 16_384, 40_000))
            wheel.advance_to(cycle)
        assert wheel.duty_now == wheel.signed_duty


class ReferenceMonitor(SafetyMonitor):
    """observe before round 5: whether the wheels move computed at every step."""

    def observe(self, t_us: int, duty: tuple[int, int], pulses_us, watchdog_tripped: bool,
                handshake: bool, host_silent: bool = False) -> None:
        moving = duty[0] != 0 or duty[1] != 0
        if pulses_us != self._pulses:  # pulses change a few times per second: judge them then
            self._pulses = tuple(pulses_us)
            self._pulses_out = sum(1 for ch, p in enumerate(pulses_us)
                                   if p and not _RANGES[ch][0] <= p <= _RANGES[ch][1])
        self.servo_out_of_limits += self._pulses_out
        if watchdog_tripped and not self._tripped:
            self.watchdog_trips += 1
            self._tripped_us = t_us
        self._tripped = watchdog_tripped
        if watchdog_tripped and moving and t_us - self._tripped_us > PWM_LATCH_US:
            self.motion_in_watchdog_stop += 1
        if host_silent:
            if self._silent_since is None:
                self._silent_since, self._stopped = t_us, False
            if not self._stopped and not moving:
                self._stopped = True
                self.stop_latency_us.append(t_us - self._silent_since)
            if not self._stopped and t_us - self._silent_since > self.watchdog_us + STOP_MARGIN_US:
                self._stopped = True  # counted once per silence
                self.late_stops += 1
        elif self._silent_since is not None:
            self._silent_since = None
        if self._fault_us is not None and handshake and not watchdog_tripped and not host_silent:
            self.recovery_us.append(t_us - self._fault_us)
            self._fault_us = None


def test_monitor_equals_the_general_observe():
    rng = random.Random(7)
    fast, general = SafetyMonitor(), ReferenceMonitor()
    t = 0
    for _ in range(5_000):
        t += 1_000
        duty = (rng.choice((0, 0, 40, -255)), rng.choice((0, 0, 17)))
        pulses = tuple(rng.choice((0.0, 1500.0, 400.0, 2600.0)) for _ in range(6))
        args = (t, duty, pulses, rng.random() < 0.3, rng.random() < 0.8, rng.random() < 0.3)
        if rng.random() < 0.01:
            fast.fault(t)
            general.fault(t)
        fast.observe(*args)
        general.observe(*args)
        assert fast.summary() == general.summary()
