"""Noticing an MCU reset from the host's side: the session must be opened again.

An ATmega128 that resets (brown-out, watchdog, a flashing tool) forgets the handshake: it refuses
every command (NACK_NOT_READY, SetWheels ignored) until the host says HELLO again. The host learns
of it from the telemetry: the first frame after the reset carries ``FLAG_RESET``, its
``time_us`` starts again near 0 (it went backwards), and ``FLAG_HANDSHAKE`` is clear. Any one of
these, once the session was up, means: clear the retransmit queue, send HELLO, and resume (or fail
the task cleanly) when HELLO_ACK arrives.

``time_us`` is a u32 of µs since the MCU's reset and wraps every 71.6 minutes: a step back by more
than half the range is a wrap, not a reset.
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.protocol.messages import FLAG_HANDSHAKE, FLAG_RESET

_U32 = 1 << 32


@dataclass
class McuWatch:
    """Feed every telemetry; :meth:`feed` returns the reason when the MCU has reset."""

    resets: int = 0
    last_time_us: int | None = None
    session_up: bool = False  # the host had a handshake that the MCU still confirmed

    def handshake_done(self) -> None:
        """HELLO_ACK arrived: from now on a missing handshake flag means a reset."""
        self.session_up = True

    def feed(self, time_us: int, flags: int) -> str | None:
        """One telemetry's ``time_us`` and ``flags``: None, or why the MCU must have reset."""
        reason = None
        last = self.last_time_us
        if last is not None and time_us < last and last - time_us < _U32 // 2:
            reason = "time_went_back"
        if self.session_up and flags & FLAG_RESET:
            reason = "flag_reset"
        elif self.session_up and not flags & FLAG_HANDSHAKE and reason is None:
            reason = "handshake_lost"
        self.last_time_us = time_us
        if reason is not None:
            self.resets += 1
            self.session_up = False  # until the new HELLO_ACK
        return reason
