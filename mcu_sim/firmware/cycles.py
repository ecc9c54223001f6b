"""The AVR cycles the Python model's work would take, charged by the events the C program runs on.

The model runs no instructions, so each handler call and each main-loop work item is charged a
fixed cycle count taken from the avr-gcc ELF under simavr (docs/firmware.md, "AVR load of the
Python model"): handler worst cases from simavr's profile, main-loop items fitted to simavr's busy
cycles over runs that differ in one kind of work only. ``load_permille`` is the share of cycles
not asleep, the figure simavr reports as ``avr_load_permille``: a report, never an input to the
model's behaviour.
"""

from __future__ import annotations

CYCLES_PER_TIMER0_TICK = 16_384  # Timer0 overflows every 1.024 ms at 16 MHz
CYCLES_PER_TIMER2_PERIOD = 16_384  # Timer2's 8-bit fast PWM at clk/64: 256 x 64 cycles

# cycles per event; handlers are per call, the rest per main-loop work item
CYCLES = {
    "startup": 35_000,  # reset to the first pass: C runtime, fw_setup (about 2.2 ms)
    "isr_usart0_rx": 145,  # per received byte
    "isr_usart0_udre": 69,  # per sent byte
    "isr_timer1_ovf": 107,  # per 20 ms servo period
    "timer0_tick": 100,  # TIMER0_OVF (41) and the wait's countdown back to sleep, per 1.024 ms
    "timer2_period": 81,  # TIMER2_OVF (46) + TIMER2_COMP (35): the right wheel's soft PWM
    "isr_encoder": 156,  # INT0..3, per encoder edge
    "isr_echo": 241,  # INT6, per echo edge
    "loop_pass": 457,  # one main-loop pass and the wake into it, whatever it does
    "rx_byte_decode": 200,  # per byte drained into the frame parser (COBS, CRC-16)
    "frame_dispatch": 786,  # per whole frame handed to the dispatch
    "tx_byte_encode": 130,  # per byte of an answer frame (ACK, NACK, replies)
    "telemetry": 7_184,  # one telemetry frame packed and encoded (its bytes' UDRE apart)
    "wheel_pi": 1_314,  # both wheels' 100 Hz step with the drive off, and the pass it wakes
    "wheel_pi_drive": 4_464,  # the same with the drive on: both PIs' 32-bit products
    "sonar_slot": 370,  # one sonar slot: close the last, trigger the next
}


class CycleMeter:
    """Counts of the charged events and the busy cycles they add up to (cycles count from
    power-on, as simavr's do)."""

    def __init__(self) -> None:
        self.counts = dict.fromkeys(CYCLES, 0)
        self.pwm_on_cycles = 0  # time the soft PWM ran, up to pwm_on_since
        self.pwm_on_since: int | None = None  # cycle it last started, None while off

    def soft_pwm(self, on: bool, cycle: int) -> None:
        """The right wheel's duty was written at ``cycle``: Timer2's two interrupts run while it
        is strictly between 0 and 255 (firmware/hal_avr.c, hal_wheel_ocr)."""
        if on and self.pwm_on_since is None:
            self.pwm_on_since = cycle
        elif not on and self.pwm_on_since is not None:
            self.pwm_on_cycles += cycle - self.pwm_on_since
            self.pwm_on_since = None

    def charge(self, item: str, n: int = 1) -> None:
        """``n`` more events of ``item`` (a key of :data:`CYCLES`)."""
        self.counts[item] += n

    def busy_cycles(self, elapsed_cycles: int) -> int:
        """Cycles not asleep over ``elapsed_cycles`` since power-on (Timer0's ticks by time)."""
        busy = sum(CYCLES[k] * n for k, n in self.counts.items())
        busy += elapsed_cycles // CYCLES_PER_TIMER0_TICK * CYCLES["timer0_tick"]
        pwm = self.pwm_on_cycles
        if self.pwm_on_since is not None:
            pwm += max(0, elapsed_cycles - self.pwm_on_since)
        return busy + pwm // CYCLES_PER_TIMER2_PERIOD * CYCLES["timer2_period"]

    def load_permille(self, elapsed_cycles: int) -> int:
        """Busy share of ``elapsed_cycles`` in ‰ (at most 1000)."""
        if elapsed_cycles <= 0:
            return 0
        asleep = max(0, elapsed_cycles - self.busy_cycles(elapsed_cycles))
        return 1000 - asleep * 1000 // elapsed_cycles  # rounded as simavr's profile rounds
