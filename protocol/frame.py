"""Frames of the serial protocol and the stream parser that finds them in any byte chunking.

Wire format (see docs/protocol.md)::

    COBS( version u8 | seq u8 | msg_type u8 | payload (0..64 bytes) | crc16 u16 LE ) | 0x00

The CRC is CRC-16/CCITT-FALSE over version..payload. COBS guarantees that 0x00 appears only as the
delimiter, so after any corruption the parser resumes at the very next 0x00 and never skips a good
frame (the MAVLink resync pitfalls of docs/protocol.md §2.1 cannot happen: there is no length field
to trust and no start byte that can occur inside a payload).
"""

from __future__ import annotations

import binascii
from dataclasses import dataclass, fields

from mobigrasp.protocol.cobs import cobs_encode
from mobigrasp.protocol.frozen import built

PROTOCOL_VERSION = 1
MAX_PAYLOAD = 64
HEADER_LEN = 3  # version, seq, msg_type
CRC_LEN = 2
MIN_RAW = HEADER_LEN + CRC_LEN
MAX_RAW = HEADER_LEN + MAX_PAYLOAD + CRC_LEN  # 69
MAX_ENCODED = MAX_RAW + 1  # COBS adds one code byte per started 254 bytes: 70, delimiter excluded
MAX_WIRE = MAX_ENCODED + 1  # with the 0x00 delimiter: 71 bytes
DELIMITER = b"\x00"
# HELLO keeps its frame layout in every protocol version, so a peer of another version is still
# parsed and can be answered with NACK_BAD_VERSION instead of silence.
VERSION_FREE_TYPES = frozenset({0x01})


def _check_u8(name: str, value: object) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 0xFF:
        raise ValueError(f"Frame.{name} must be an int in [0, 255], got {value!r}")


@dataclass(frozen=True)
class Frame:
    """One checked frame: header fields and the raw message payload (at most MAX_PAYLOAD bytes)."""

    version: int
    seq: int
    msg_type: int
    payload: bytes

    def __post_init__(self) -> None:
        _check_u8("version", self.version)
        _check_u8("seq", self.seq)
        _check_u8("msg_type", self.msg_type)
        if not isinstance(self.payload, bytes | bytearray | memoryview):
            raise ValueError(f"Frame.payload must be bytes, got {type(self.payload).__name__}")
        if len(self.payload) > MAX_PAYLOAD:
            raise ValueError(
                f"Frame.payload is {len(self.payload)} bytes, at most {MAX_PAYLOAD} allowed"
            )
        object.__setattr__(self, "payload", bytes(self.payload))


def encode_frame(frame: Frame) -> bytes:
    """Wire bytes of ``frame``: COBS-encoded header+payload+CRC followed by the 0x00 delimiter."""
    return encode_raw(frame.version, frame.seq, frame.msg_type, frame.payload)


def encode_raw(version: int, seq: int, msg_type: int, payload: bytes) -> bytes:
    """Wire bytes of a frame from fields the caller has checked (as a :class:`Frame` does)."""
    raw = bytes((version, seq, msg_type)) + payload
    crc = binascii.crc_hqx(raw, 0xFFFF)
    return cobs_encode(raw + bytes((crc & 0xFF, crc >> 8))) + DELIMITER


def frame_crc(frame: Frame) -> int:
    """The CRC-16 field of ``frame`` on the wire (over version, seq, msg_type and payload): what
    the duplicate filter compares to tell a copy from another command with the same seq."""
    return binascii.crc_hqx(bytes((frame.version, frame.seq, frame.msg_type)) + frame.payload,
                            0xFFFF)


@dataclass
class ParserStats:
    """What the parser accepted and rejected. Every rejected run of bytes increments exactly one
    reason counter; ``garbage_bytes`` counts the bytes that were not delivered in a frame."""

    frames_ok: int = 0
    crc_errors: int = 0
    oversize: int = 0  # more than MAX_ENCODED bytes before a delimiter
    unknown_type: int = 0
    bad_version: int = 0
    truncated: int = 0  # runt: fewer than 5 bytes after COBS decoding, or cut at end of stream
    cobs_errors: int = 0  # a COBS code byte pointing past the delimiter (bytes lost in transit)
    garbage_bytes: int = 0
    bytes_in: int = 0
    recovered: int = 0  # frames found at the end of a rejected run (its delimiter was lost)

    def as_dict(self) -> dict[str, int]:
        """The counters as a plain dict (for JSON and for Link.stats)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def chain_starts(run: bytes) -> list[int]:
    """Offsets ``j`` of a zero-free ``run`` whose COBS code chain ends exactly at its end: where
    a frame that ends at the run's delimiter may start. One pass from the end (C: a bitmap of
    MAX_ENCODED bits): ``j`` qualifies iff ``j + run[j]`` is the end or itself qualifies."""
    n = len(run)
    ok = bytearray(n + 1)
    ok[n] = 1
    for i in range(n - 1, -1, -1):
        nxt = i + run[i]
        if nxt <= n and ok[nxt]:
            ok[i] = 1
    return [j for j in range(n) if ok[j]]


class FrameParser:
    """Turns a byte stream, in any chunking, into checked frames; counts what it rejects.

    ``known_types``: the message types this end understands (None = accept every type and let
    the message layer decide, which the firmware needs in order to answer NACK_UNKNOWN_TYPE).
    The pending buffer never exceeds MAX_ENCODED bytes: a longer run without a delimiter is
    counted once as ``oversize``, and only its last MAX_ENCODED bytes are kept until the next
    0x00. A run that fails as one frame (oversize, COBS or CRC error) is searched for a valid
    frame that ends at its 0x00 (docs/protocol.md §2.1): when a delimiter is lost, the frame
    after it is still delivered and only the frame before it is lost.
    """

    def __init__(self, known_types=None, version: int = PROTOCOL_VERSION) -> None:
        self.known_types = None if known_types is None else frozenset(known_types)
        self.version = version
        self.stats = ParserStats()
        self._buf = b""
        self._skipping = False  # inside an oversize run: _buf holds its last MAX_ENCODED bytes

    @property
    def pending(self) -> int:
        """Bytes held while waiting for a delimiter (0..MAX_ENCODED)."""
        return len(self._buf)

    def reset(self) -> None:
        """Forget any partial frame (counters are kept)."""
        self._buf = b""
        self._skipping = False

    def flush(self) -> None:
        """End of stream: a partial frame still pending is counted as truncated and dropped."""
        if self._buf:
            if not self._skipping:  # an oversize run was counted when it overflowed
                self.stats.truncated += 1
            self.stats.garbage_bytes += len(self._buf)
        self.reset()

    def _checked(self, enc: bytes) -> Frame | None:
        """The frame whose COBS bytes are ``enc`` if it passes every check, else None (not
        counted: used on the tail of a run already counted as rejected)."""
        n = len(enc)
        if n < MIN_RAW + 1 or n > MAX_ENCODED:
            return None
        buf = bytearray(enc)
        i = 0
        while i < n:
            code = buf[i]
            buf[i] = 0
            i += code
        if i != n or binascii.crc_hqx(buf[1:-2], 0xFFFF) != buf[-2] | (buf[-1] << 8):
            return None
        msg_type = buf[3]
        if buf[1] != self.version and msg_type not in VERSION_FREE_TYPES:
            return None
        if self.known_types is not None and msg_type not in self.known_types:
            return None
        return Frame(buf[1], buf[2], msg_type, bytes(buf[4:-2]))

    def _recover(self, run: bytes, first: int, frames: list[Frame]) -> None:
        """``run`` (zero-free, ending at a 0x00) was rejected: deliver the longest suffix from
        offset ``first`` on that is a valid frame, if any; the rest is garbage."""
        n = len(run)
        for j in chain_starts(run):
            if j < first or n - j < MIN_RAW + 1:
                continue
            if n - j > MAX_ENCODED:
                continue
            frame = self._checked(run[j:])
            if frame is not None:
                frames.append(frame)
                self.stats.recovered += 1
                self.stats.garbage_bytes += j
                return
        self.stats.garbage_bytes += n

    def feed(self, chunk: bytes) -> list[Frame]:
        """Consume ``chunk`` and return the complete valid frames it finished, in order."""
        if not chunk:
            return []
        stats = self.stats
        stats.bytes_in += len(chunk)
        if b"\x00" not in chunk and not self._skipping \
                and len(self._buf) + len(chunk) <= MAX_ENCODED:
            # the front part of a frame (the UART delivers frames in pieces): only buffered,
            # exactly as the general path below would do with it
            self._buf += bytes(chunk)
            return []
        data = self._buf + bytes(chunk) if self._buf else bytes(chunk)
        pieces = data.split(b"\x00")
        tail = pieces.pop()
        frames: list[Frame] = []
        if self._skipping:
            if not pieces:  # still inside an oversize run: keep its last MAX_ENCODED bytes
                drop = len(tail) - MAX_ENCODED
                if drop > 0:
                    stats.garbage_bytes += drop
                    tail = tail[drop:]
                self._buf = tail
                return frames
            # the oversize run (counted when it overflowed) ends here: a frame may end with it
            run = pieces[0]
            if len(run) > MAX_ENCODED:
                stats.garbage_bytes += len(run) - MAX_ENCODED
                run = run[-MAX_ENCODED:]
            pieces[0] = b""
            self._skipping = False
            self._recover(run, 0, frames)
        known = self.known_types
        version = self.version
        crc_hqx = binascii.crc_hqx
        append = frames.append
        for piece in pieces:
            n = len(piece)
            if n == 0:
                continue  # idle delimiter: senders may emit extra 0x00 to force a resync
            if n > MAX_ENCODED:
                stats.oversize += 1
                stats.garbage_bytes += n - MAX_ENCODED
                self._recover(piece[-MAX_ENCODED:], 0, frames)
                continue
            # COBS decoding in place: every code byte after the first becomes the zero it
            # stands for (a valid frame is < 254 bytes, so there are no 0xFF "no zero" codes).
            # ``buf`` keeps the first code byte at index 0; raw frame bytes start at index 1.
            if piece[0] == n:
                buf = piece
            else:
                buf = bytearray(piece)
                i = 0
                while i < n:
                    code = buf[i]
                    buf[i] = 0
                    i += code
                if i != n:
                    stats.cobs_errors += 1
                    self._recover(piece, 1, frames)
                    continue
            if n < MIN_RAW + 1:
                stats.truncated += 1
                stats.garbage_bytes += n
                continue
            if crc_hqx(buf[1:-2], 0xFFFF) != buf[-2] | (buf[-1] << 8):
                stats.crc_errors += 1
                self._recover(piece, 1, frames)
                continue
            msg_type = buf[3]
            if buf[1] != version and msg_type not in VERSION_FREE_TYPES:
                stats.bad_version += 1
                stats.garbage_bytes += n
                continue
            if known is not None and msg_type not in known:
                stats.unknown_type += 1
                stats.garbage_bytes += n
                continue
            # checked above: the fields are what __post_init__ would accept
            append(built(Frame, version=buf[1], seq=buf[2], msg_type=msg_type,
                         payload=bytes(buf[4:-2])))
        stats.frames_ok += len(frames)
        if len(tail) > MAX_ENCODED:
            stats.oversize += 1
            stats.garbage_bytes += len(tail) - MAX_ENCODED
            tail = tail[-MAX_ENCODED:]
            self._skipping = True
        self._buf = tail
        return frames
