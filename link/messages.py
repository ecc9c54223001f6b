"""The message layer over a Transport: send protocol messages, poll the ones received.

``Link`` frames and parses; it does no retransmission (the host and the firmware own their
``protocol.reliable`` state machines, so the lockstep rig controls all time). Frames that pass
the CRC but whose payload does not decode are counted in ``decode_errors``, never raised; an
optional ``on_bad_frame(frame, error)`` callback lets a receiver NACK them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from mobigrasp.link.base import LinkClosed, Transport
from mobigrasp.protocol.frame import Frame, FrameParser, encode_frame
from mobigrasp.protocol.messages import (
    MESSAGE_TYPES,
    Message,
    MessageError,
    decode_frame,
    message_frame,
)
from mobigrasp.protocol.reliable import SequenceCounter

_MAX_READS_PER_POLL = 64  # bounds one poll() even if the peer never stops sending


@dataclass(frozen=True)
class Received:
    """One decoded message with the frame (sequence number, version, raw payload) it came in."""

    seq: int
    msg: Message
    frame: Frame


class Link:
    """Messages over a byte transport. ``known_types=None`` passes unknown types to the decoder
    (and so to ``on_bad_frame``) instead of dropping them in the parser."""

    def __init__(
        self,
        transport: Transport,
        known_types=tuple(MESSAGE_TYPES),
        on_bad_frame: Callable[[Frame, MessageError], None] | None = None,
    ) -> None:
        self.transport = transport
        self.parser = FrameParser(known_types=known_types)
        self.seq = SequenceCounter()
        self.on_bad_frame = on_bad_frame
        self.tx_frames = 0
        self.tx_bytes = 0
        self.rx_frames = 0
        self.rx_bytes = 0
        self.decode_errors = 0
        self.last_wire = b""
        self._pending_close: LinkClosed | None = None

    def send(self, msg: Message) -> int:
        """Send ``msg`` with the next sequence number; returns that number."""
        seq = self.seq.next()
        self.send_with_seq(msg, seq)
        return seq

    def send_with_seq(self, msg: Message, seq: int) -> bytes:
        """Send ``msg`` with a given ``seq``; returns the wire bytes (for a RetransmitQueue)."""
        wire = encode_frame(message_frame(msg, seq))
        self.send_wire(wire)
        return wire

    def send_wire(self, wire: bytes) -> None:
        """Send already-encoded frame bytes (a retransmission)."""
        self.transport.write(wire)
        self.last_wire = wire
        self.tx_frames += 1
        self.tx_bytes += len(wire)

    def poll(self) -> list[Received]:
        """Read what the transport has now (never blocks) and return the decoded messages.

        LinkClosed propagates, but only after the messages that arrived before the peer
        vanished have been returned (by this call; the next call raises)."""
        if self._pending_close is not None:
            exc, self._pending_close = self._pending_close, None
            raise exc
        out: list[Received] = []
        for _ in range(_MAX_READS_PER_POLL):
            try:
                chunk = self.transport.read()
            except LinkClosed as exc:
                if not out:
                    raise
                self._pending_close = exc
                break
            if not chunk:
                break
            self.rx_bytes += len(chunk)
            for frame in self.parser.feed(chunk):
                try:
                    msg = decode_frame(frame)
                except MessageError as exc:
                    self.decode_errors += 1
                    if self.on_bad_frame is not None:
                        self.on_bad_frame(frame, exc)
                    continue
                self.rx_frames += 1
                out.append(Received(frame.seq, msg, frame))
        return out

    def wait(self, timeout_s: float) -> bool:
        """Wait up to ``timeout_s`` for incoming bytes (see Transport.wait_readable)."""
        return self.transport.wait_readable(timeout_s)

    @property
    def stats(self) -> dict[str, int]:
        """tx/rx frame and byte counts, decode errors and every parser counter (``rx_*``)."""
        out = {
            "tx_frames": self.tx_frames,
            "tx_bytes": self.tx_bytes,
            "rx_frames": self.rx_frames,
            "rx_bytes": self.rx_bytes,
            "decode_errors": self.decode_errors,
        }
        out.update({f"parser_{k}": v for k, v in self.parser.stats.as_dict().items()})
        return out

    def close(self) -> None:
        """Close the transport."""
        self.transport.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
