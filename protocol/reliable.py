"""Acknowledgement state machines: sequence numbers, retransmission, duplicate suppression.

Pure logic with time passed in as integer microseconds, so the lockstep rig controls time and the
same code runs on the host (Python today, C on the S3C2440 tomorrow). Rules (docs/protocol.md):
every RELIABLE message is answered by ACK or NACK carrying its seq; the sender resends the same
wire bytes (same seq) every ``timeout_us`` until answered, at most ``max_retries`` times, then
reports the seq as failed. The receiver executes a reliable seq once and ACKs every copy.
Senders keep one reliable command outstanding (or cancel superseded ones): a retransmission is
the only way the serial line can reorder commands.
"""

from __future__ import annotations

from dataclasses import dataclass


class SequenceCounter:
    """Frame sequence numbers 0..255; ``next()`` returns the current one and advances, wrapping."""

    def __init__(self, start: int = 0) -> None:
        if isinstance(start, bool) or not isinstance(start, int) or not 0 <= start <= 255:
            raise ValueError(f"SequenceCounter start must be an int in [0, 255], got {start!r}")
        self._next = start

    def next(self) -> int:
        """The next sequence number (wraps from 255 to 0)."""
        seq = self._next
        self._next = (seq + 1) & 0xFF
        return seq

    def peek(self) -> int:
        """The number ``next()`` will return, without consuming it."""
        return self._next


@dataclass
class _Pending:
    wire: bytes
    deadline_us: int
    retries: int


class RetransmitQueue:
    """Reliable frames waiting for their ACK/NACK, keyed by seq, in the order they were tracked."""

    def __init__(self, timeout_us: int = 20_000, max_retries: int = 10) -> None:
        if isinstance(timeout_us, bool) or not isinstance(timeout_us, int) or timeout_us <= 0:
            raise ValueError(f"timeout_us must be a positive int, got {timeout_us!r}")
        if isinstance(max_retries, bool) or not isinstance(max_retries, int) or max_retries < 0:
            raise ValueError(f"max_retries must be an int >= 0, got {max_retries!r}")
        self.timeout_us = timeout_us
        self.max_retries = max_retries
        self.retransmits = 0
        self.acked = 0
        self._pending: dict[int, _Pending] = {}
        self._failed: list[int] = []

    def __len__(self) -> int:
        return len(self._pending)

    def __contains__(self, seq: object) -> bool:
        """Whether ``seq`` is still waiting for its answer (``in_flight()`` without the list)."""
        return seq in self._pending

    def in_flight(self) -> list[int]:
        """Sequence numbers still waiting for an answer, oldest first."""
        return list(self._pending)

    def track(self, seq: int, wire_bytes: bytes, now_us: int) -> None:
        """Start waiting for the answer to ``seq`` whose frame ``wire_bytes`` was sent at now_us.

        ValueError if ``seq`` is already in flight: 256 seqs cover more than max_retries x
        timeout of traffic, so a reuse means the sender's bookkeeping is wrong."""
        if isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq <= 255:
            raise ValueError(f"seq must be an int in [0, 255], got {seq!r}")
        if seq in self._pending:
            raise ValueError(f"seq {seq} is already waiting for its ACK")
        self._pending[seq] = _Pending(bytes(wire_bytes), int(now_us) + self.timeout_us, 0)

    def ack(self, seq: int) -> bool:
        """An ACK or NACK for ``seq`` arrived; True if it was in flight (False: late or stray)."""
        if self._pending.pop(seq, None) is None:
            return False
        self.acked += 1
        return True

    def cancel(self, seq: int) -> bool:
        """Stop retransmitting ``seq`` (superseded by a newer command); True if it was waiting.

        Needed when several reliable commands are outstanding: a retransmitted older command
        would otherwise be executed after a newer one (the serial line itself never reorders).
        """
        return self._pending.pop(seq, None) is not None

    def due(self, now_us: int) -> list[bytes]:
        """Frames to resend now; seqs that used up their retries move to ``failed()``."""
        out: list[bytes] = []
        for seq in list(self._pending):
            p = self._pending[seq]
            if now_us < p.deadline_us:
                continue
            if p.retries >= self.max_retries:
                del self._pending[seq]
                self._failed.append(seq)
                continue
            p.retries += 1
            p.deadline_us = now_us + self.timeout_us
            self.retransmits += 1
            out.append(p.wire)
        return out

    def next_deadline_us(self) -> int | None:
        """Earliest time at which ``due()`` will have something to do (None if nothing waits)."""
        return min((p.deadline_us for p in self._pending.values()), default=None)

    def failed(self) -> list[int]:
        """Seqs given up since the last call (each reported once)."""
        out, self._failed = self._failed, []
        return out

    def clear(self) -> None:
        """Drop everything in flight (e.g. after a new handshake)."""
        self._pending.clear()
        self._failed.clear()


class DuplicateFilter:
    """Receiver side: remembers recently executed reliable seqs and the answer given to each.

    ``is_new(seq, now_us)`` is True the first time a seq is seen (execute it, then ACK) and False
    for a retransmitted copy (ACK again, or repeat the stored NACK, but do not execute). An entry
    lives until ``expiry_us`` has passed (default 250 ms, longer than the sender's whole
    retransmission span of 10 x 20 ms) or until ``window`` newer seqs pushed it out.

    Pass ``now_us``: seq numbers wrap every 256 frames of the sender, and without the time a new
    command that happens to reuse the seq of a recent one (sparse reliable commands between
    many unreliable frames) would be taken for a copy and not executed. Without ``now_us`` entries
    only leave by the window. ``live_evictions`` counts entries pushed out before their expiry:
    a copy of those would be executed twice, so it should stay 0 (send fewer reliable commands
    at once, or raise ``window``). Call ``reset()`` on HELLO: a restarted host counts from 0.
    """

    def __init__(self, window: int = 16, expiry_us: int = 250_000) -> None:
        if isinstance(window, bool) or not isinstance(window, int) or not 1 <= window <= 256:
            raise ValueError(f"window must be an int in [1, 256], got {window!r}")
        if isinstance(expiry_us, bool) or not isinstance(expiry_us, int) or expiry_us <= 0:
            raise ValueError(f"expiry_us must be a positive int, got {expiry_us!r}")
        self.window = window
        self.expiry_us = expiry_us
        self.duplicates = 0
        self.live_evictions = 0
        # seq -> [time seen (or None), answer: 0 = ACK, else NACK reason]; insertion = age order
        self._seen: dict[int, list] = {}

    def _expire(self, now_us: int) -> None:
        for seq in list(self._seen):
            t = self._seen[seq][0]
            if t is None or now_us - t < self.expiry_us:
                break  # entries are in arrival order: the rest are younger
            del self._seen[seq]

    def is_new(self, seq: int, now_us: int | None = None) -> bool:
        """True (and remember seq) unless seq was executed recently; False for a copy."""
        if now_us is not None:
            self._expire(now_us)
        if seq in self._seen:
            self.duplicates += 1
            return False
        if len(self._seen) >= self.window:
            oldest = next(iter(self._seen))
            t = self._seen.pop(oldest)[0]
            if now_us is None or t is None or now_us - t < self.expiry_us:
                self.live_evictions += 1
        self._seen[seq] = [now_us, 0]
        return True

    def set_result(self, seq: int, nack_reason: int) -> None:
        """Store the answer given to ``seq`` (0 = ACK, else the NACK reason) for its copies."""
        entry = self._seen.get(seq)
        if entry is not None:
            entry[1] = nack_reason

    def result(self, seq: int) -> int:
        """The stored answer for ``seq`` (0 = ACK when nothing was stored)."""
        entry = self._seen.get(seq)
        return 0 if entry is None else entry[1]

    def reset(self) -> None:
        """Forget every seq (new session)."""
        self._seen.clear()
