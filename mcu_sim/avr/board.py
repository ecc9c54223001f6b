"""The ATmega128 board: the peripheral models the firmware touches, on one CPU-cycle clock.

``Board.cycle`` is the current time in 16 MHz cycles, set by :class:`mcu_sim.mcu.Mcu` before it runs
an interrupt handler or the main loop; register writes made by the firmware take effect at that
cycle. Pin map: ``mcu_sim/avr/pinmap.py`` (``Board.pins``), from which the C port's
``firmware/board.h`` is generated.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.avr import pinmap
from mobigrasp.mcu_sim.avr.encoder import QuadratureEncoder
from mobigrasp.mcu_sim.avr.signals import SignalBus
from mobigrasp.mcu_sim.avr.sonar import SonarArray
from mobigrasp.mcu_sim.avr.timer8 import WheelPwm
from mobigrasp.mcu_sim.avr.timer16 import Timer16
from mobigrasp.mcu_sim.avr.usart import Usart

CYCLES_PER_US = 16
SERVO_PORTS = tuple(f"servo{ch}" for ch in range(6))


class Board:
    """All peripherals of one MCU plus the cycle counter they share."""

    pins = pinmap.by_signal()  # signal -> (pin, function): the wiring the models stand for

    def __init__(self, ubrr: int = 16, u2x: int = 1, tx_capacity: int = 128,
                 line_capacity: int = 4096, sonar_count: int = 5) -> None:
        self.bus = SignalBus()
        self.cycle = 0
        self.reset_cycle = 0
        self.timer1 = Timer16("Timer1", self.bus, SERVO_PORTS[0:3], CYCLES_PER_US)
        self.timer3 = Timer16("Timer3", self.bus, SERVO_PORTS[3:6], CYCLES_PER_US)
        self.wheel_left = WheelPwm("wheel_left", self.bus, 64, CYCLES_PER_US)
        self.wheel_right = WheelPwm("wheel_right", self.bus, 64, CYCLES_PER_US)
        self.usart0 = Usart(ubrr, u2x, tx_capacity, line_capacity)
        self.enc_left = QuadratureEncoder("enc_left")
        self.enc_right = QuadratureEncoder("enc_right")
        self.sonars = SonarArray(sonar_count, CYCLES_PER_US)

    def reset(self, cycle: int) -> None:
        """MCU reset at ``cycle``: registers cleared, buffers emptied; the shafts keep turning."""
        self.reset_cycle = cycle
        self.cycle = cycle
        for part in (self.timer1, self.timer3, self.wheel_left, self.wheel_right, self.usart0,
                     self.sonars):
            part.reset()
        for enc in (self.enc_left, self.enc_right):
            enc.take_edges(cycle)  # edges before the reset are not counted by the new firmware
        for port in SERVO_PORTS:
            self.bus.port(f"{port}.pin").value = 0
        for wheel in (self.wheel_left, self.wheel_right):
            wheel.publish(cycle)

    def micros(self) -> int:
        """Microseconds since reset, as the C port derives them from Timer1 (overflows x 20 ms +
        TCNT1 / 2)."""
        return (self.cycle - self.reset_cycle) // CYCLES_PER_US

    def servo_timer(self, ch: int) -> tuple[Timer16, int]:
        """(timer, compare channel index) driving servo channel ``ch``."""
        return (self.timer1, ch) if ch < 3 else (self.timer3, ch - 3)
