"""Acknowledgement state machines: sequence numbers, retransmission, duplicate suppression.

Pure logic with time passed in as integer microseconds, so the lockstep rig controls time and the
same code runs on the host (Python today, C on the S3C2440 tomorrow). Rules (docs/protocol.md):
every RELIABLE message is answered by ACK or NACK carrying its seq; the sender resends the same
wire bytes (same seq) every ``timeout_us`` until answered, at most ``max_retries`` times, then
reports the seq as failed. The receiver executes a reliable command once and answers every copy
the same way; a different command reusing a recent seq is NACKed, never silently dropped.
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


DUP_NEW = 0  # DuplicateFilter.classify: execute it, then remember()
DUP_COPY = 1  # the same command again: answer with result(), do not execute
DUP_REUSED = 2  # the seq of a recent command with other content: NACK_SEQ_REUSED, not executed
_EMPTY = 0xFF  # a slot's result byte when it holds no command


class DuplicateFilter:
    """Receiver side: which reliable frames are copies of a command already executed.

    Two frames are **the same command** when they have the same seq AND the same CRC-16 (the CRC
    covers version, seq, msg_type and payload: the whole content). The filter remembers the
    commands of the last ``window`` sequence numbers of the sender, counted in seqs, not in time
    or in reliable commands (docs/protocol.md §5.2):

    - ``observe(seq)`` for every valid frame from the peer, reliable or not, keeps ``newest``:
      a seq 1 .. 256 - window ahead of it is a newer frame and becomes ``newest`` (the slots of
      the seqs it passes are cleared: their old entries are a lap of the 8-bit counter old); a
      seq 0 .. window - 1 behind it is a recent one.
    - ``classify(seq, crc)`` of a reliable frame, after ``observe``: DUP_COPY if the slot of a
      recent seq holds that seq with that CRC, DUP_REUSED if it holds that seq with another CRC,
      else DUP_NEW.

    Storage as in C: ``window`` slots indexed by ``seq % window``, each a seq tag (u8), a CRC
    (u16) and the answer given (u8; 0 = ACK, else the NACK reason, 0xFF = empty). ``window`` is a
    power of two in 2..128; it must exceed the number of frames the sender can send during one
    command's retransmission span (docs/protocol.md §5.2). Call ``reset()`` on HELLO.
    """

    def __init__(self, window: int = 64) -> None:
        if isinstance(window, bool) or not isinstance(window, int) or window not in (
                2, 4, 8, 16, 32, 64, 128):
            raise ValueError(f"window must be a power of two in [2, 128], got {window!r}")
        self.window = window
        self._mask = window - 1
        self._ahead_max = 256 - window
        self.duplicates = 0
        self.reused = 0
        self.newest = -1  # -1: nothing observed since reset
        self._tag = [0] * window
        self._crc = [0] * window
        self._result = [_EMPTY] * window

    def observe(self, seq: int) -> None:
        """A valid frame with ``seq`` arrived from the peer: advance ``newest`` if it is newer."""
        newest = self.newest
        if newest < 0:
            self.newest = seq
            return
        ahead = (seq - newest) & 0xFF
        if 1 <= ahead <= self._ahead_max:
            mask = self._mask
            result = self._result
            for k in range(1, min(ahead, self.window) + 1):
                result[(newest + k) & mask] = _EMPTY
            self.newest = seq

    def classify(self, seq: int, crc: int) -> int:
        """DUP_NEW, DUP_COPY or DUP_REUSED for a reliable frame (``observe`` it first)."""
        i = seq & self._mask
        if self._result[i] == _EMPTY or self._tag[i] != seq:
            return DUP_NEW
        if self._crc[i] == crc:
            self.duplicates += 1
            return DUP_COPY
        self.reused += 1
        return DUP_REUSED

    def remember(self, seq: int, crc: int, nack_reason: int) -> None:
        """Store the command ``seq``/``crc`` and its answer (0 = ACK, else the NACK reason,
        which is below 0xFF)."""
        i = seq & self._mask
        self._tag[i] = seq
        self._crc[i] = crc
        self._result[i] = nack_reason

    def result(self, seq: int) -> int:
        """The answer stored for ``seq`` (0 = ACK when nothing is stored)."""
        i = seq & self._mask
        r = self._result[i]
        return 0 if r == _EMPTY or self._tag[i] != seq else r

    def reset(self) -> None:
        """Forget every command and the newest seq (new session)."""
        self.newest = -1
        self._result[:] = [_EMPTY] * self.window
