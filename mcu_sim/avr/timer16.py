"""16-bit Timer/Counter 1 and 3 of the ATmega128 in fast PWM mode 14 (TOP = ICRn).

Register-level model of what the servo firmware uses (datasheet, 16-bit Timer/Counter, "Fast PWM
Mode"): TCCRnA holds COMnA/B/C (bits 7:2, 0b10 = non-inverting) and WGMn1:0, TCCRnB holds WGMn3:2
(bits 4:3) and the clock select CSn2:0. In mode 14 the counter runs 0..ICRn, the non-inverting
outputs go high at BOTTOM and low at the compare match TCNTn == OCRnx, so a pulse lasts
``OCRnx + 1`` timer ticks; ICRn = 39999 with prescaler 8 at 16 MHz gives a 20 ms period of 0.5 µs
ticks. OCRnx is double-buffered: a value written during a period is latched at the next BOTTOM
(the "servo timing" pitfall of docs/firmware.md), which is why ``write_ocr`` only fills the buffer.

The model is event-driven: it computes the edges of each period arithmetically (one rising edge per
channel at BOTTOM, one falling edge at BOTTOM + (OCR+1) ticks) instead of stepping ticks. Time is
in 16 MHz CPU cycles. The overflow interrupt (TOVn, set at TOP) is reported at the following BOTTOM,
one tick later, after the buffered OCR values have been latched: an OCR write from that ISR takes
effect one period later, as on the part. ICRn writes are taken at the next BOTTOM too (the firmware
writes ICRn only before starting the clock).
"""

from __future__ import annotations

from mobigrasp.mcu_sim.avr.signals import SignalBus

PRESCALERS = {0: 0, 1: 1, 2: 8, 3: 64, 4: 256, 5: 1024}  # CSn2:0 -> divider (0 = stopped)
WGM_FAST_PWM_ICR = 14
COM_NON_INVERTING = 0b10
NS_PER_CYCLE_NUM = 1000  # ns = cycles * 1000 / 16 (16 MHz)


class Timer16:
    """One 16-bit timer with output compare channels A, B, C driving named signal ports."""

    def __init__(self, name: str, bus: SignalBus, channel_ports: tuple[str, str, str],
                 cycles_per_us: int = 16) -> None:
        self.name = name
        self.cycles_per_us = cycles_per_us
        self._pins = [bus.port(f"{p}.pin") for p in channel_ports]
        self._pulses = [bus.port(f"{p}.pulse_ns") for p in channel_ports]
        # bumped whenever last_width_ns may hold other values: a reader that cached something
        # derived from the widths (Mcu.servo_pulses_us) rebuilds it only then
        self.width_serial = 0
        self.reset()

    def reset(self) -> None:
        """Register state after an MCU reset: everything zero, clock stopped, pins low."""
        self.tccra = 0
        self.tccrb = 0
        self.icr = 0
        self._icr_active = 0
        self.ocr_buffer = [0, 0, 0]
        self.ocr_active = [0, 0, 0]
        self.overflows = 0
        self._prescale = 0
        self._period_start: int | None = None
        self.next_bottom: int | None = None
        self._falls: list[tuple[int, int, int]] = []  # (cycle, channel, pulse width in ns)
        self.next_edge: int | None = None  # always next_event(): read once per coupling step
        self.last_width_ns = [0, 0, 0]
        self.width_serial += 1  # a new list of widths

    # -- register writes (firmware side) --------------------------------------------------------
    @property
    def wgm(self) -> int:
        """Waveform generation mode WGMn3:0 assembled from TCCRnA and TCCRnB."""
        return ((self.tccrb >> 3) & 0b11) << 2 | (self.tccra & 0b11)

    def write_tccra(self, value: int) -> None:
        """Write TCCRnA (COM bits, WGMn1:0)."""
        self.tccra = value & 0xFF

    def write_icr(self, value: int) -> None:
        """Write ICRn (TOP in mode 14); latched at the next BOTTOM, immediately if stopped."""
        self.icr = value & 0xFFFF
        if self._period_start is None:
            self._icr_active = self.icr

    def write_ocr(self, channel: int, value: int) -> None:
        """Write OCRnA/B/C (channel 0/1/2) into its buffer; latched at the next BOTTOM."""
        self.ocr_buffer[channel] = value & 0xFFFF
        if self._period_start is None:
            self.ocr_active[channel] = self.ocr_buffer[channel]

    def write_tccrb(self, value: int, cycle: int) -> None:
        """Write TCCRnB; a non-zero clock select starts the counter at ``cycle`` (TCNT = 0)."""
        self.tccrb = value & 0xFF
        prescale = PRESCALERS.get(self.tccrb & 0b111)
        if prescale is None:
            raise ValueError(f"{self.name}: external clock sources (CS={self.tccrb & 7}) "
                             "are not modelled")
        if prescale and self.wgm != WGM_FAST_PWM_ICR:
            raise ValueError(f"{self.name}: only WGM mode 14 (fast PWM, TOP=ICRn) is modelled, "
                             f"got mode {self.wgm}")
        if prescale == 0:
            self._prescale = 0
            self._period_start = None
            self.next_bottom = None
            self._falls = []
            self.next_edge = None
            return
        if self._period_start is None:
            self._prescale = prescale
            self._start_period(cycle)

    # -- derived values ------------------------------------------------------------------------
    @property
    def period_cycles(self) -> int:
        """Length of one PWM period in CPU cycles ((TOP + 1) x prescaler)."""
        return (self._icr_active + 1) * self._prescale

    def tcnt(self, cycle: int) -> int:
        """TCNTn as the firmware would read it at ``cycle``."""
        if self._period_start is None:
            return 0
        return (cycle - self._period_start) // self._prescale

    def _channel_enabled(self, channel: int) -> bool:
        return (self.tccra >> (6 - 2 * channel)) & 0b11 == COM_NON_INVERTING

    # -- event engine --------------------------------------------------------------------------
    def _start_period(self, cycle: int) -> None:
        # runs twice per 20 ms period (Timer1 and Timer3): attributes read once into locals,
        # _channel_enabled and period_cycles written out
        icr = self._icr_active = self.icr
        ocr = self.ocr_active = list(self.ocr_buffer)
        prescale = self._prescale
        cpu = self.cycles_per_us
        self._period_start = cycle
        bottom = self.next_bottom = cycle + (icr + 1) * prescale
        falls = []
        tccra = self.tccra
        for ch in range(3):
            if (tccra >> (6 - 2 * ch)) & 0b11 != COM_NON_INVERTING:  # not _channel_enabled(ch)
                continue
            pin = self._pins[ch]
            if pin.subscribers:
                pin.emit(cycle, 1, cpu)
            else:  # what emit() does with no one to call (a run subscribes to no servo port)
                pin.value, pin.last_cycle, pin.t_us = 1, cycle, cycle // cpu
            if ocr[ch] < icr:  # OCR >= TOP: output stays high
                ticks = (ocr[ch] + 1) * prescale  # the pulse: from this BOTTOM to the fall
                falls.append((cycle + ticks, ch, ticks * NS_PER_CYCLE_NUM // cpu))
        falls.sort()  # by cycle, then channel (one fall per channel: widths never compared)
        self._falls = falls
        self.next_edge = falls[0][0] if falls else bottom

    def next_event(self) -> int | None:
        """Cycle of the next edge or BOTTOM, or None when the clock is stopped."""
        if self._falls:
            return self._falls[0][0]
        return self.next_bottom

    def advance_to(self, cycle: int) -> int:
        """Produce every edge up to and including ``cycle``; returns the BOTTOMs crossed."""
        bottoms = 0
        cpu = self.cycles_per_us
        while True:
            bottom = self.next_bottom
            if bottom is None:
                break
            falls = self._falls  # a new list after every BOTTOM; every fall is before it
            while falls and falls[0][0] <= cycle:
                fall, ch, width_ns = falls.pop(0)
                widths = self.last_width_ns
                if widths[ch] != width_ns:
                    widths[ch] = width_ns
                    self.width_serial += 1
                pin, pulse = self._pins[ch], self._pulses[ch]
                if pin.subscribers or pulse.subscribers:
                    pin.emit(fall, 0, cpu)
                    pulse.emit(fall, width_ns, cpu)
                else:  # emit() of both with no one to call: the samples alone
                    t_us = fall // cpu
                    pin.value, pin.last_cycle, pin.t_us = 0, fall, t_us
                    pulse.value, pulse.last_cycle, pulse.t_us = width_ns, fall, t_us
            self.next_edge = falls[0][0] if falls else bottom
            if bottom > cycle:
                break
            self.overflows += 1
            bottoms += 1
            self._start_period(bottom)
        return bottoms
