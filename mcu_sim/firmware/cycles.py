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

# cycles per event; handlers are per call, the rest per main-loop work item
CYCLES = {
    "startup": 35_000,  # reset to the first pass: C runtime, fw_setup (about 2.2 ms)
    "isr_usart0_rx": 145,  # per received byte
    "isr_usart0_udre": 69,  # per sent byte
    "isr_timer1_ovf": 107,  # per 20 ms servo period
    "timer0_tick": 100,  # TIMER0_OVF (41) and the wait's countdown back to sleep, per 1.024 ms
    "isr_encoder": 156,  # INT0..3, per encoder edge
    "isr_echo": 241,  # INT6, per echo edge
    "loop_pass": 457,  # one main-loop pass and the wake into it, whatever it does
    "rx_byte_decode": 200,  # per byte drained into the frame parser (COBS, CRC-16)
    "frame_dispatch": 786,  # per whole frame handed to the dispatch
    "tx_byte_encode": 130,  # per byte of an answer frame (ACK, NACK, replies)
    "telemetry": 7_184,  # one telemetry frame packed and encoded (its bytes' UDRE apart)
    "wheel_pi": 1_314,  # both wheels' PI at 100 Hz, with the pass of its own it wakes on the AVR
    "sonar_slot": 370,  # one sonar slot: close the last, trigger the next
}


class CycleMeter:
    """Counts of the charged events and the busy cycles they add up to."""

    def __init__(self) -> None:
        self.counts = dict.fromkeys(CYCLES, 0)

    def charge(self, item: str, n: int = 1) -> None:
        """``n`` more events of ``item`` (a key of :data:`CYCLES`)."""
        self.counts[item] += n

    def busy_cycles(self, elapsed_cycles: int) -> int:
        """Cycles not asleep over ``elapsed_cycles`` since power-on (Timer0's ticks by time)."""
        counts = self.counts
        busy = sum(CYCLES[k] * n for k, n in counts.items())
        return busy + elapsed_cycles // CYCLES_PER_TIMER0_TICK * CYCLES["timer0_tick"]

    def load_permille(self, elapsed_cycles: int) -> int:
        """Busy share of ``elapsed_cycles`` in ‰ (at most 1000)."""
        if elapsed_cycles <= 0:
            return 0
        asleep = max(0, elapsed_cycles - self.busy_cycles(elapsed_cycles))
        return 1000 - asleep * 1000 // elapsed_cycles  # rounded as simavr's profile rounds
