"""The emulated ATmega128: firmware plus peripheral models, driven by the caller's clock.

``Mcu`` owns no clock of its own: the caller (a test, ``mobigrasp mcu``, the rig) moves it with
``advance_to(t_us)``. Between two calls it runs an event loop in 16 MHz cycles. The next event is
the earliest of: the stop bit of a frame delimiter on the RX line (or of the byte that would fill
the RX ring; see ``Usart.next_rx_wakeup`` for why bytes may be batched up to a delimiter), a
Timer1 BOTTOM (servo period start), a sonar echo edge, and the firmware's own next due time. At
each event the peripherals are brought up to that cycle, the interrupt handlers run in a fixed
order (timer overflow, USART RX, echo edges, encoder edges), then one main-loop pass if a handler
left work for it or its due time has come (otherwise the part sleeps on).
Everything is integer and deterministic: the same inputs at the same simulated times give the
same outputs, whatever the wall clock does.

Outputs: servo pulse edges and widths on signal ports (``servo_port``, ``servo_pulse_us``), wheel
duties (``wheel_duty``), bytes the firmware sent (``uart_tx_take``). Inputs: bytes on the RX line
(``uart_rx``), encoder counts (``set_encoder_ticks``), sonar ranges (``set_sonar_provider``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from mobigrasp.mcu_sim.avr.board import CYCLES_PER_US, Board
from mobigrasp.mcu_sim.avr.signals import SignalPort
from mobigrasp.mcu_sim.avr.usart import baud_error_pct, baud_rate
from mobigrasp.mcu_sim.firmware.params import param_id
from mobigrasp.mcu_sim.firmware.program import Firmware
from mobigrasp.mcu_sim.firmware.sram import RX_RING_BYTES, TX_RING_BYTES


@dataclass(frozen=True)
class McuConfig:
    """Build-time choices: UART divisor, fitted sonars, line buffer, PARAM defaults to override."""

    ubrr: int = 16
    u2x: int = 1
    sonar_count: int = 5
    line_capacity_bytes: int = 4096
    params: Mapping[str | int, int] = field(default_factory=dict)


class Mcu:
    """One emulated ATmega128 running the mobigrasp firmware."""

    # the program that runs on the board: the Python model here, the C firmware in
    # mcu_sim/native (NativeMcu); called as firmware_class(board, param_overrides)
    firmware_class: Callable[..., Firmware] = Firmware

    def __init__(self, config: McuConfig | None = None) -> None:
        self.config = config or McuConfig()
        cfg = self.config
        self.board = Board(cfg.ubrr, cfg.u2x, TX_RING_BYTES, cfg.line_capacity_bytes,
                           cfg.sonar_count)
        overrides = {param_id(k): int(v) for k, v in cfg.params.items()}
        self._cycle = 0
        self._tx_out: list[tuple[int, bytes]] = []
        self.events = 0
        self._rx_batch = RX_RING_BYTES - 1  # what the ring holds: a batch can never overrun it
        self.firmware = self.firmware_class(self.board, overrides)
        self._deadline = 0
        # servo_pulses_us's tuple and the Timer16.width_serial values it was built from
        self._pulses_us: tuple[float, ...] = ()
        self._width_serials = (-1, -1)
        self._step(0)

    # -- time ----------------------------------------------------------------------------------
    @property
    def now_us(self) -> int:
        """Current simulated time in µs."""
        return self._cycle // CYCLES_PER_US

    def advance_to(self, t_us: int) -> None:
        """Run the MCU until simulated time ``t_us`` (inclusive of events at exactly ``t_us``)."""
        target = int(t_us) * CYCLES_PER_US
        if target < self._cycle:
            raise ValueError(f"cannot go back in time from {self.now_us} to {t_us} us")
        b = self.board
        usart, timer1, sonars = b.usart0, b.timer1, b.sonars
        batch = self._rx_batch
        while True:
            nxt = self._deadline
            if usart.rx_queue:  # next_rx_wakeup is None exactly when nothing is on the RX line
                r = usart.next_rx_wakeup(batch)
                if r < nxt:
                    nxt = r
            tb = timer1.next_bottom
            if tb is not None and tb < nxt:
                nxt = tb
            echoes = sonars.echo_events  # sonars.next_event(), written out
            if echoes and echoes[0][0] < nxt:
                nxt = echoes[0][0]
            if nxt > target:
                break
            self._step(nxt)
        self._cycle = target
        b.cycle = target
        self._peripherals_to(target)

    def advance_outputs(self, t_us: int) -> tuple[tuple[float, ...], tuple[int, int]]:
        """:meth:`advance_to` ``t_us``, then (:meth:`servo_pulses_us`, :meth:`wheel_duty`): what
        the rig's coupling step reads right after advancing, in one call."""
        self.advance_to(t_us)
        return self.servo_pulses_us(), self.wheel_duty()

    def _peripherals_to(self, cycle: int) -> int:
        # Each part is called only when it has something due by ``cycle`` (Timer16.next_edge is
        # its next_event(); a wheel has an event only while an OCR write waits for its BOTTOM):
        # most calls, two per coupling step, find nothing due.
        b = self.board
        bottoms = 0
        edge = b.timer1.next_edge
        if edge is not None and edge <= cycle:
            bottoms = b.timer1.advance_to(cycle)
        edge = b.timer3.next_edge
        if edge is not None and edge <= cycle:
            b.timer3.advance_to(cycle)
        if b.wheel_left.next_event() is not None:
            b.wheel_left.advance_to(cycle)
        if b.wheel_right.next_event() is not None:
            b.wheel_right.advance_to(cycle)
        return bottoms

    def _step(self, cycle: int) -> None:
        self.events += 1
        b = self.board
        fw = self.firmware
        self._cycle = cycle
        b.cycle = cycle
        for _ in range(self._peripherals_to(cycle)):
            fw.isr_timer1_ovf()
        usart = b.usart0
        if usart.rx_queue:  # rx_take_until takes nothing (and counts nothing) from an idle line
            data = usart.rx_take_until(cycle)
            if data:
                fw.isr_usart_rx_bytes(data)
        if b.sonars.echo_events:
            for _, index, level in b.sonars.take_events_until(cycle):
                fw.isr_echo(index, level)
        enc = b.enc_left
        # take_edges is 0 (and changes nothing) once the shaft stands where the ISR last saw it
        if enc.edges_pending(cycle):
            edges = enc.take_edges(cycle)
            if edges:
                fw.isr_encoder(0, edges)
        enc = b.enc_right
        if enc.edges_pending(cycle):
            edges = enc.take_edges(cycle)
            if edges:
                fw.isr_encoder(1, edges)
        if cycle < self._deadline and not fw.work_pending():
            return  # an echo edge: its handler's work only, the main loop sleeps on
        due = b.reset_cycle + fw.loop() * CYCLES_PER_US
        self._deadline = due if due > cycle else cycle + CYCLES_PER_US

    def reset(self) -> None:
        """MCU reset now: bytes in flight are lost, the firmware starts again (FLAG_RESET)."""
        self._tx_out.extend(self._take_tx())
        self.board.reset(self._cycle)
        self.firmware.setup()
        self._deadline = self._cycle  # everything is due at once after the start-up
        self._step(self._cycle)

    # -- UART ----------------------------------------------------------------------------------
    def uart_rx(self, data: bytes, start_us: int | None = None) -> int:
        """Put ``data`` on the RX line starting at ``start_us`` (default and minimum: now);
        returns the bytes accepted (the rest overflowed the line buffer and is counted)."""
        start = self._cycle if start_us is None else max(int(start_us) * CYCLES_PER_US,
                                                          self._cycle)
        return self.board.usart0.line_put(bytes(data), start)

    def _take_tx(self) -> list[tuple[int, bytes]]:
        sent = self.board.usart0.tx_take_until(self._cycle)
        if not sent:
            return sent
        return [((c + CYCLES_PER_US - 1) // CYCLES_PER_US, d) for c, d in sent]

    def uart_tx_take(self) -> list[tuple[int, bytes]]:
        """Bytes the firmware sent since the last call: ``(t_us their last bit left, bytes)``."""
        usart = self.board.usart0
        queued = usart.tx_queue
        # Called once per coupling step, and mostly no byte has finished since the last call:
        # nothing queued, or the first queued byte's stop bit still to come (what makes
        # tx_take_until return []; the TX ring fill it would recount is recounted by tx_free
        # before it is ever used).
        if (not queued or self._cycle < queued[0][0] + usart.byte_cycles) and not self._tx_out:
            return []
        sent = self._take_tx()
        if not self._tx_out:  # no reset since the last call (always but once)
            return sent
        out = self._tx_out + sent
        self._tx_out = []
        return out

    def tx_idle_through_us(self) -> int:
        """Simulated µs through which no byte the firmware sends can finish leaving the TX pin,
        provided nothing more arrives on the RX line: now while bytes are on their way out or
        received bytes may still be answered; else the next telemetry time (a message queued
        then needs at least one byte time to leave). Lets the rig hand the host a grant one
        quantum early when it would be the same (cosim/rig.py, docs/cosim.md)."""
        b = self.board
        usart = b.usart0
        now = self._cycle // CYCLES_PER_US
        # next_tx_cycle() / next_rx_cycle() are not None exactly while their queue holds a
        # chunk; bytes in the RX ring without a frame's end wait for more from the line (asked
        # once per quantum)
        if usart.tx_queue or usart.rx_queue or self.firmware.work_pending():
            return now
        due = self.firmware.next_unprompted_send_us()
        if due is None:
            return 1 << 62
        return max(now, (b.reset_cycle + due * CYCLES_PER_US) // CYCLES_PER_US)

    @property
    def baud(self) -> float:
        """Actual USART0 baud rate."""
        return baud_rate(self.config.ubrr, self.config.u2x)

    @property
    def baud_error_pct(self) -> float:
        """Baud error against 115200 in percent (+2.1 for UBRR 16, U2X 1)."""
        return baud_error_pct(self.config.ubrr, self.config.u2x)

    # -- outputs -------------------------------------------------------------------------------
    def servo_port(self, ch: int) -> SignalPort:
        """Signal port of channel ``ch``'s pulse widths (value in ns, at each falling edge)."""
        return self.board.bus.port(f"servo{self._check_ch(ch)}.pulse_ns")

    def servo_pin(self, ch: int) -> SignalPort:
        """Signal port of channel ``ch``'s pin edges (value 1 rising, 0 falling)."""
        return self.board.bus.port(f"servo{self._check_ch(ch)}.pin")

    def servo_pulse_ns(self, ch: int) -> int:
        """Latest complete pulse width on channel ``ch`` in ns (0 before the first one)."""
        timer, idx = self.board.servo_timer(self._check_ch(ch))
        return timer.last_width_ns[idx]

    def servo_pulse_us(self, ch: int) -> float:
        """Latest complete pulse width on channel ``ch`` in µs (a multiple of 0.5)."""
        # read 12 times per coupling step (rig, safety monitor): no helper calls
        if not 0 <= ch < 6:
            raise ValueError(f"servo channel must be 0..5, got {ch}")
        b = self.board
        return (b.timer1.last_width_ns[ch] if ch < 3 else b.timer3.last_width_ns[ch - 3]) / 1000.0

    def servo_pulses_us(self) -> tuple[float, ...]:
        """:meth:`servo_pulse_us` of channels 0..5 in one call (the rig reads all six per
        coupling step)."""
        t1, t3 = self.board.timer1, self.board.timer3
        serials = self._width_serials
        # the widths change a few times per second: the tuple is rebuilt only when a timer
        # says its widths may differ (the same tuple also makes the readers' != checks cheap)
        if t1.width_serial != serials[0] or t3.width_serial != serials[1]:
            self._width_serials = (t1.width_serial, t3.width_serial)
            w1, w3 = t1.last_width_ns, t3.last_width_ns
            self._pulses_us = (w1[0] / 1000.0, w1[1] / 1000.0, w1[2] / 1000.0,
                               w3[0] / 1000.0, w3[1] / 1000.0, w3[2] / 1000.0)
        return self._pulses_us

    def subscribe_servo(self, ch: int, callback: Callable[[int, int], None]) -> Callable[[], None]:
        """Call ``callback(t_us, width_ns)`` at every falling edge of channel ``ch``."""
        return self.servo_port(ch).subscribe(callback)

    def wheel_duty(self) -> tuple[int, int]:
        """Signed duties (left, right), -255..255, as the motor drivers see them now."""
        # WheelPwm.signed_duty of both, which each keeps in duty_now: read at every coupling step
        b = self.board
        return b.wheel_left.duty_now, b.wheel_right.duty_now

    @staticmethod
    def _check_ch(ch: int) -> int:
        if not 0 <= ch < 6:
            raise ValueError(f"servo channel must be 0..5, got {ch}")
        return ch

    # -- inputs --------------------------------------------------------------------------------
    def set_encoder_ticks(self, left: int, right: int, t_us: int | None = None) -> None:
        """The wheels' cumulative quadrature counts are (left, right) at ``t_us`` (default now);
        a future time spreads the edges from now until then."""
        now = self._cycle
        t = now if t_us is None else int(t_us) * CYCLES_PER_US
        b = self.board
        b.enc_left.set_ticks(left, t, now)
        b.enc_right.set_ticks(right, t, now)

    def set_sonar_provider(self, provider: Callable[[int], float | None] | None) -> None:
        """Set ``provider(index) -> metres | None`` consulted when a sonar is triggered."""
        if provider is not None and not callable(provider):
            raise TypeError(f"sonar provider must be callable or None, got {provider!r}")
        self.board.sonars.provider = provider

    # -- diagnostics ---------------------------------------------------------------------------
    def safety_flags(self) -> tuple[bool, bool]:
        """(watchdog stop active, host handshake done), for the safety monitor."""
        fw = self.firmware
        return fw.watchdog_tripped, fw.handshake

    def limit_hits(self) -> int:
        """Commands the firmware clamped to the joint limits so far."""
        return int(self.firmware.limit_hits)

    def stats(self) -> dict[str, int]:
        """Counters of the firmware and the USART (what a debugger would read from SRAM)."""
        fw = self.firmware
        usart = self.board.usart0
        out = {
            "rx_bytes": usart.rx_bytes,
            "tx_bytes": usart.tx_bytes,
            "rx_ring_overruns": fw.rx.overruns,
            "rx_line_dropped": usart.rx_line_dropped,
            "overruns": fw.overruns(),
            "corrupt_frames": fw.corrupt_frames(),
            "bad_frames": fw.bad_frames,
            "not_ready": fw.not_ready,
            "unexpected": fw.unexpected,
            "tx_dropped": fw.tx_dropped,
            "limit_hits": fw.limit_hits,
            "watchdog_trips": fw.watchdog_trips,
            "telemetry_sent": fw.telemetry_sent,
            "duplicates": fw.dup.duplicates,
            "events": self.events,
        }
        for key, value in fw.parser.stats.as_dict().items():
            out[f"parser_{key}"] = value
        out.update(fw.load_stats(self._cycle))
        return out
