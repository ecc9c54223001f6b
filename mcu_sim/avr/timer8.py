"""8-bit Timer/Counter 0 and 2 in fast PWM mode plus a direction pin: the two wheel motor drivers.

Each wheel has an H-bridge driven by one PWM output (OC0 for the left wheel, OC2 for the right) and
one GPIO direction pin, as on the usual L298-style board. Fast PWM mode 3 (TOP = 0xFF) with
prescaler 64 at 16 MHz gives a 976.6 Hz PWM of 16 384 cycles (1024 µs) per period. OCRn is
double-buffered: a written duty becomes effective at the end of the current period; the direction
pin is a plain port bit and changes at once. ``signed_duty`` is what the motor sees: -255..255,
negative when the direction pin is set (reverse).

Event-driven: only a pending OCR latch is an event; nothing is stepped per tick.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.avr.signals import SignalBus

TOP = 0xFF
COM_NON_INVERTING = 0b10


class WheelPwm:
    """One 8-bit fast-PWM channel and its direction pin, observable as a signed duty port."""

    def __init__(self, name: str, bus: SignalBus, prescale: int = 64,
                 cycles_per_us: int = 16) -> None:
        if prescale <= 0:
            raise ValueError(f"{name}: prescale must be > 0, got {prescale}")
        self.name = name
        self.prescale = prescale
        self.cycles_per_us = cycles_per_us
        self._port = bus.port(f"{name}.duty")
        self.reset()

    def reset(self) -> None:
        """After MCU reset: clock stopped, output low, direction forward."""
        self.running = False
        self._start = 0
        self.ocr_active = 0
        self._pending: tuple[int, int] | None = None  # (effective cycle, value)
        self.reverse = False
        self.enabled = False
        self._emitted = 0
        # signed_duty, kept by every write of enabled / reverse / ocr_active: the MCU reads
        # both wheels' duties at every coupling step
        self.duty_now = 0

    @property
    def period_cycles(self) -> int:
        """One PWM period in CPU cycles: 256 x prescaler."""
        return (TOP + 1) * self.prescale

    def start(self, cycle: int) -> None:
        """Start the counter (TCCRn clock select written) with the output connected."""
        if not self.running:
            self.running = True
            self._start = cycle
        self.enabled = True
        self.duty_now = self.signed_duty

    def _next_bottom_after(self, cycle: int) -> int:
        period = self.period_cycles
        k = (cycle - self._start) // period + 1
        return self._start + k * period

    def write_ocr(self, value: int, cycle: int) -> None:
        """Write OCRn: takes effect at the next BOTTOM (immediately while the clock is stopped)."""
        value &= 0xFF
        if not self.running:
            self.ocr_active = value
            self.duty_now = self.signed_duty
            self._pending = None
            return
        self._pending = (self._next_bottom_after(cycle), value)

    def write_direction(self, reverse: bool, cycle: int) -> None:
        """Set the direction port bit (immediate)."""
        self.reverse = bool(reverse)
        self.duty_now = self.signed_duty
        self.publish(cycle)

    def next_event(self) -> int | None:
        """Cycle of the pending OCR latch, if any."""
        return self._pending[0] if self._pending else None

    def advance_to(self, cycle: int) -> None:
        """Latch a pending OCR once its BOTTOM has passed."""
        if self._pending is not None and self._pending[0] <= cycle:
            effective, value = self._pending
            self._pending = None
            self.ocr_active = value
            self.duty_now = self.signed_duty
            self.publish(effective)

    @property
    def signed_duty(self) -> int:
        """Duty the motor sees now: -255..255 (OCR value, sign from the direction pin)."""
        if not self.enabled:
            return 0
        return -self.ocr_active if self.reverse else self.ocr_active

    def publish(self, cycle: int) -> None:
        duty = self.signed_duty
        if duty != self._emitted:
            self._emitted = duty
            self._port.emit(cycle, duty, self.cycles_per_us)
