"""The lockstep channel between the rig (time authority) and the host: message codec, stdlib only.

Spec: docs/cosim.md. The rig grants the host a quantum of simulated time; the host processes up to
``until_us`` (never beyond) and answers DONE. UART bytes do NOT travel here: they cross the real
pty (or the in-process pair); the lockstep messages only say how many bytes each side will find and
at which simulated time each chunk arrived or was sent, so the receiver reads exactly that many.
Camera frames do travel here (pixels are too big for a 115200 baud line and are a different wire
on the board: the camera bus into the S3C2440's CAMIF).

Wire format of every message (little-endian)::

    magic  4s  b"MGLS"
    kind   u8  1 HELLO, 2 GRANT, 3 DONE, 4 END, 5 BYE; 6 GRANT and 7 DONE in compact form
    meta   u32 length of the JSON metadata that follows (UTF-8, sorted keys)
    blob   u32 length of the binary blob after the metadata (frame pixels, concatenated)

Most quanta's GRANT (no frames) and DONE (no events, no load window finished) go in a compact
binary form instead of JSON (kinds 6 and 7, see :func:`encode`): the same message once decoded,
at a fraction of the cost on both sides, every 5 ms quantum.

A GRANT's frames list ``offset``/``nbytes`` into the blob, or ``shared`` (where a frame ring holds
the pixels: cosim/frame_ring.py; ``encode(frame_sink=...)``, ``decode_body(frame_source=...)``).
JSON keeps the channel debuggable and lets host events (task transitions, detections) ride in
DONE; all of it is simulated-time data.
"""

from __future__ import annotations

import json
import operator
import os
import select
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from mobigrasp.protocol.frozen import built

MAGIC = b"MGLS"
LOCKSTEP_VERSION = 2  # 2: the compact GRANT and DONE kinds
HEADER = struct.Struct("<4sBII")
MAX_META_BYTES = 16 << 20  # a DONE with many events stays far below this; a bigger one is a bug
MAX_BLOB_BYTES = 64 << 20  # ~280 frames of 320x240x3

KIND_HELLO = 1
KIND_GRANT = 2
KIND_DONE = 3
KIND_END = 4
KIND_BYE = 5
KIND_GRANT_COMPACT = 6
KIND_DONE_COMPACT = 7
_KINDS = (KIND_HELLO, KIND_GRANT, KIND_DONE, KIND_END, KIND_BYE, KIND_GRANT_COMPACT,
          KIND_DONE_COMPACT)

# Compact GRANT (no frames): start_us, until_us, number of UART chunks; then per chunk
# (arrival_us, nbytes).
_GRANT_HEAD = struct.Struct("<qqI")
# Compact DONE (no events, no load window finished, the load's six usual keys): until_us,
# quiet_until, window_us, finished, camera, length of the state's UTF-8 name, number of write
# chunks; then the state's name, then per chunk (send_us, nbytes).
_DONE_HEAD = struct.Struct("<qqqBBBI")
_CHUNK = struct.Struct("<qI")
# the message header followed by the fixed part of a compact GRANT or DONE, packed at once
_GRANT_FIRST = struct.Struct(HEADER.format + _GRANT_HEAD.format[1:])
_DONE_FIRST = struct.Struct(HEADER.format + _DONE_HEAD.format[1:])
_NBYTES = operator.itemgetter(1)  # of a chunk (time_us, nbytes)
_DONE_LOAD_KEYS = frozenset(("window_us", "windows", "state", "finished", "camera",
                             "quiet_until"))


class LockstepError(ValueError):
    """A lockstep message that cannot be decoded (bad magic, kind, lengths or fields)."""


class LockstepClosed(ConnectionError):
    """The other side of the lockstep channel went away mid-message or between messages."""


@dataclass(frozen=True)
class FrameBlob:
    """One camera frame as it crosses the channel: simulated times and raw pixels (row-major)."""

    seq: int
    capture_us: int
    arrival_us: int
    width: int
    height: int
    channels: int
    pixels: bytes

    def __post_init__(self) -> None:
        expected = self.width * self.height * self.channels
        if len(self.pixels) != expected:
            raise LockstepError(f"frame {self.seq}: {len(self.pixels)} pixel bytes, "
                                f"expected {self.width}x{self.height}x{self.channels}={expected}")
        if self.arrival_us < self.capture_us:
            raise LockstepError(f"frame {self.seq}: arrival_us {self.arrival_us} before "
                                f"capture_us {self.capture_us}")


@dataclass(frozen=True)
class Hello:
    """Host → rig, once after connecting: versions, so a mismatch fails loudly."""

    version: int = LOCKSTEP_VERSION
    host_id: str = "host"


@dataclass(frozen=True)
class Grant:
    """Rig → host: run up to ``until_us``; UART chunks (arrival_us, nbytes) are on the pty."""

    start_us: int
    until_us: int
    uart: tuple[tuple[int, int], ...] = ()
    frames: tuple[FrameBlob, ...] = ()

    @property
    def uart_bytes(self) -> int:
        """Total UART bytes the host must read from its port for this grant."""
        return sum(map(_NBYTES, self.uart))


@dataclass(frozen=True)
class Done:
    """Host → rig: reached ``until_us``; wrote these chunks (send_us, nbytes) to the port."""

    until_us: int
    writes: tuple[tuple[int, int], ...] = ()
    events: tuple[dict, ...] = ()
    load: dict = field(default_factory=dict)

    @property
    def write_bytes(self) -> int:
        """Total UART bytes the rig must read from the pty master for this quantum."""
        return sum(map(_NBYTES, self.writes))

    def writes_nothing(self) -> bool:
        """Whether the host certainly writes nothing in this quantum (a DONE still to be read
        answers from the host's promise: mobigrasp.cosim.handshake.PendingDone)."""
        return not self.writes


@dataclass(frozen=True)
class End:
    """Rig → host: the run is over (``reason``); the host answers BYE with its final stats."""

    at_us: int
    reason: str


@dataclass(frozen=True)
class Bye:
    """Host → rig: last message; ``stats`` are the host's counters (protocol, budget)."""

    stats: dict = field(default_factory=dict)


Message = Hello | Grant | Done | End | Bye


# One encoder and decoder for every message (json.dumps/loads with options build new ones per
# call); a message is encoded and decoded every 5 ms quantum on each side of the channel.
_ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"), allow_nan=False)
_DECODER = json.JSONDecoder()


def _int(meta: dict, key: str, lo: int = 0, hi: int = (1 << 63) - 1) -> int:
    value = meta.get(key)
    # type() is int: a bool is not a count of microseconds
    if type(value) is not int or not lo <= value <= hi:
        raise LockstepError(f"field {key!r} must be an integer in [{lo}, {hi}], got {value!r}")
    return value


def _chunks(meta: dict, key: str) -> tuple[tuple[int, int], ...]:
    raw = meta.get(key, [])
    if not isinstance(raw, list):
        raise LockstepError(f"field {key!r} must be a list of [time_us, nbytes]")
    out = []
    last = -1
    for item in raw:
        if type(item) is not list or len(item) != 2:
            raise LockstepError(f"field {key!r}: bad chunk {item!r}, expected [time_us, nbytes]")
        t, n = item
        if type(t) is not int or type(n) is not int or t < 0 or n < 0:
            raise LockstepError(f"field {key!r}: bad chunk {item!r}, expected [time_us, nbytes]")
        if t < last:
            raise LockstepError(f"field {key!r}: chunk times go backwards at {item!r}")
        last = t
        out.append((t, n))
    return tuple(out)


def encode(msg: Message, frame_sink: Callable[[bytes], dict | None] | None = None) -> bytes:
    """Wire bytes of one lockstep message. ``frame_sink(pixels)`` may take a GRANT's frame
    pixels out of band (cosim/frame_ring.py) and return where they are, or None to send them in
    the blob."""
    compact = _encode_compact(msg)
    if compact is not None:
        return compact
    blob = b""
    if isinstance(msg, Hello):
        kind, meta = KIND_HELLO, {"version": msg.version, "host_id": msg.host_id}
    elif isinstance(msg, Grant):
        if msg.until_us < msg.start_us:
            raise LockstepError(f"grant until_us {msg.until_us} < start_us {msg.start_us}")
        frames, parts, offset = [], [], 0
        for fr in msg.frames:
            entry = {"seq": fr.seq, "capture_us": fr.capture_us, "arrival_us": fr.arrival_us,
                     "width": fr.width, "height": fr.height, "channels": fr.channels,
                     "offset": offset, "nbytes": len(fr.pixels)}
            where = frame_sink(fr.pixels) if frame_sink is not None and fr.pixels else None
            if where is not None:
                entry["shared"] = where
            else:
                parts.append(fr.pixels)
                offset += len(fr.pixels)
            frames.append(entry)
        blob = b"".join(parts)
        kind, meta = KIND_GRANT, {"start_us": msg.start_us, "until_us": msg.until_us,
                                  "uart": [list(c) for c in msg.uart], "frames": frames}
    elif isinstance(msg, Done):
        kind, meta = KIND_DONE, {"until_us": msg.until_us,
                                 "writes": [list(c) for c in msg.writes],
                                 "events": list(msg.events), "load": msg.load}
    elif isinstance(msg, End):
        kind, meta = KIND_END, {"at_us": msg.at_us, "reason": msg.reason}
    elif isinstance(msg, Bye):
        kind, meta = KIND_BYE, {"stats": msg.stats}
    else:
        raise LockstepError(f"not a lockstep message: {type(msg).__name__}")
    try:
        meta_bytes = _ENCODER.encode(meta).encode()
    except (TypeError, ValueError) as exc:
        raise LockstepError(f"{type(msg).__name__} metadata is not plain JSON: {exc}") from exc
    return HEADER.pack(MAGIC, kind, len(meta_bytes), len(blob)) + meta_bytes + blob


def _encode_compact(msg: Message) -> bytes | None:
    """The compact form of a GRANT without frames or of a DONE without events whose load is
    the usual six keys with no window finished; None for any other message (JSON then)."""
    # the header and the fixed part go in one pack, the chunks after it (one or two, if any):
    # this runs for most quanta on both sides of the channel
    try:
        if type(msg) is Grant:
            chunks = msg.uart
            if msg.frames or msg.until_us < msg.start_us:
                return None
            out = _GRANT_FIRST.pack(MAGIC, KIND_GRANT_COMPACT,
                                    _GRANT_HEAD.size + len(chunks) * _CHUNK.size, 0,
                                    msg.start_us, msg.until_us, len(chunks))
        elif type(msg) is Done:
            load = msg.load
            if msg.events or load.keys() != _DONE_LOAD_KEYS or load["windows"]:
                return None
            quiet, window, state = load["quiet_until"], load["window_us"], load["state"]
            finished, camera = load["finished"], load["camera"]
            if (type(quiet) is not int or type(window) is not int or type(state) is not str
                    or type(finished) is not bool or type(camera) is not bool):
                return None
            name = state.encode()
            if len(name) > 255:
                return None
            chunks = msg.writes
            out = _DONE_FIRST.pack(MAGIC, KIND_DONE_COMPACT,
                                   _DONE_HEAD.size + len(name) + len(chunks) * _CHUNK.size, 0,
                                   msg.until_us, quiet, window, finished, camera, len(name),
                                   len(chunks)) + name
        else:
            return None
        for t, n in chunks:
            out += _CHUNK.pack(t, n)
    except struct.error:  # a time or size out of the fields' range: JSON's checks say so
        return None
    return out


def _compact_chunks(body: bytes, offset: int, n: int, what: str) -> tuple[tuple[int, int], ...]:
    if len(body) != offset + n * _CHUNK.size:
        raise LockstepError(f"compact {what}: {len(body)} bytes, expected "
                            f"{offset + n * _CHUNK.size} for {n} chunks")
    if not n:
        return ()
    out = tuple(_CHUNK.iter_unpack(body[offset:]))
    last = -1
    for t, _ in out:
        if t < last or t < 0:
            raise LockstepError(f"compact {what}: chunk time {t} negative or going backwards")
        last = t
    return out


def _decode_compact(kind: int, body: bytes) -> Message:
    if kind == KIND_GRANT_COMPACT:
        if len(body) < _GRANT_HEAD.size:
            raise LockstepError(f"compact GRANT of {len(body)} bytes")
        start, until, n = _GRANT_HEAD.unpack_from(body)
        if start < 0 or until < start:
            raise LockstepError(f"compact GRANT: bad quantum [{start}, {until})")
        return built(Grant, start_us=start, until_us=until,
                      uart=_compact_chunks(body, _GRANT_HEAD.size, n, "GRANT"), frames=())
    if len(body) < _DONE_HEAD.size:
        raise LockstepError(f"compact DONE of {len(body)} bytes")
    until, quiet, window, finished, camera, name_len, n = _DONE_HEAD.unpack_from(body)
    if until < 0 or finished > 1 or camera > 1:
        raise LockstepError(f"compact DONE: bad until_us {until} or flags {finished}, {camera}")
    end = _DONE_HEAD.size + name_len
    try:
        state = body[_DONE_HEAD.size:end].decode()
    except UnicodeDecodeError as exc:
        raise LockstepError(f"compact DONE: state is not UTF-8: {exc}") from exc
    writes = _compact_chunks(body, end, n, "DONE")
    return built(Done, until_us=until, writes=writes, events=(),
                  load={"window_us": window, "windows": {}, "state": state,
                        "finished": bool(finished), "camera": bool(camera),
                        "quiet_until": quiet})


def decode_header(header: bytes) -> tuple[int, int, int]:
    """(kind, meta_len, blob_len) of a 13-byte header; LockstepError when it is not one."""
    if len(header) != HEADER.size:
        raise LockstepError(f"header must be {HEADER.size} bytes, got {len(header)}")
    magic, kind, meta_len, blob_len = HEADER.unpack(header)
    if magic != MAGIC:
        raise LockstepError(f"bad magic {magic!r}, expected {MAGIC!r}")
    if kind not in _KINDS:
        raise LockstepError(f"unknown message kind {kind}")
    if meta_len > MAX_META_BYTES or blob_len > MAX_BLOB_BYTES:
        raise LockstepError(f"message too large: meta {meta_len} B, blob {blob_len} B")
    return kind, meta_len, blob_len


def decode_body(kind: int, meta_bytes: bytes, blob: bytes,
                frame_source: Callable[[Any, int], bytes] | None = None) -> Message:
    """The message of a decoded header's kind from its metadata and blob; ``frame_source(where,
    nbytes)`` fetches the pixels of a frame sent out of band ("shared")."""
    if kind >= KIND_GRANT_COMPACT:
        if blob:
            raise LockstepError(f"a compact message has no blob, got {len(blob)} bytes")
        return _decode_compact(kind, meta_bytes)
    try:
        meta: Any = _DECODER.decode(meta_bytes.decode())
    except (UnicodeDecodeError, ValueError) as exc:
        raise LockstepError(f"metadata is not JSON: {exc}") from exc
    if not isinstance(meta, dict):
        raise LockstepError("metadata must be a JSON object")
    if kind == KIND_HELLO:
        return Hello(version=_int(meta, "version", 0, 255), host_id=str(meta.get("host_id", "")))
    if kind == KIND_GRANT:
        start, until = _int(meta, "start_us"), _int(meta, "until_us")
        if until < start:
            raise LockstepError(f"grant until_us {until} < start_us {start}")
        frames = []
        for fm in meta.get("frames", []):
            if not isinstance(fm, dict):
                raise LockstepError("each frame must be a JSON object")
            off, n = _int(fm, "offset"), _int(fm, "nbytes")
            if "shared" in fm:
                if frame_source is None:
                    raise LockstepError(f"frame {fm.get('seq')} is in shared memory, and this "
                                        f"end has no reader for it")
                pixels = frame_source(fm["shared"], n)
            elif off + n > len(blob):
                raise LockstepError(f"frame {fm.get('seq')} runs past the blob ({off}+{n} > "
                                    f"{len(blob)})")
            else:
                pixels = bytes(blob[off:off + n])
            frames.append(FrameBlob(seq=_int(fm, "seq"), capture_us=_int(fm, "capture_us"),
                                    arrival_us=_int(fm, "arrival_us"), width=_int(fm, "width"),
                                    height=_int(fm, "height"), channels=_int(fm, "channels"),
                                    pixels=pixels))
        return Grant(start_us=start, until_us=until, uart=_chunks(meta, "uart"),
                     frames=tuple(frames))
    if kind == KIND_DONE:
        events = meta.get("events", [])
        load = meta.get("load", {})
        if not isinstance(events, list) or not isinstance(load, dict):
            raise LockstepError("DONE events must be a list and load an object")
        return Done(until_us=_int(meta, "until_us"), writes=_chunks(meta, "writes"),
                    events=tuple(events), load=load)
    if kind == KIND_END:
        return End(at_us=_int(meta, "at_us"), reason=str(meta.get("reason", "")))
    stats = meta.get("stats", {})
    if not isinstance(stats, dict):
        raise LockstepError("BYE stats must be an object")
    return Bye(stats=stats)


def decode(data: bytes) -> Message:
    """Decode one complete message (header + metadata + blob, nothing more)."""
    kind, meta_len, blob_len = decode_header(bytes(data[:HEADER.size]))
    if len(data) != HEADER.size + meta_len + blob_len:
        raise LockstepError(f"message length {len(data)} does not match its header "
                            f"({HEADER.size}+{meta_len}+{blob_len})")
    body = memoryview(data)[HEADER.size:]
    return decode_body(kind, bytes(body[:meta_len]), bytes(body[meta_len:]))


class _Readable(Protocol):
    def read(self, n: int) -> bytes: ...


def read_message(stream: _Readable,
                 frame_source: Callable[[Any, int], bytes] | None = None) -> Message:
    """Read exactly one message from a blocking stream (e.g. ``socket.makefile('rb')``).

    Raises LockstepClosed when the stream ends, even in the middle of a message.
    """
    header = _read_exact(stream, HEADER.size)
    kind, meta_len, blob_len = decode_header(header)
    meta = _read_exact(stream, meta_len)
    blob = _read_exact(stream, blob_len) if blob_len else b""  # (a compact message has none)
    return decode_body(kind, meta, blob, frame_source)


class SocketReader:
    """A blocking reader of a socket that tells how many bytes it holds already read
    (``buffered``): the host answers a batch of GRANTs that arrived together with one write of
    their DONEs (drivers/lockstep.serve_stream). A BufferedReader cannot say so without
    blocking when it is empty.

    With ``poll_s`` > 0 it polls the socket for up to that long (yielding the CPU between
    polls) before it blocks: the host process of a run at full speed waits for the rig's next
    grant this way, so it is already running when the grant arrives (docs/cosim.md, "Busy
    polling")."""

    def __init__(self, sock: Any, chunk: int = 1 << 16, poll_s: float = 0.0) -> None:
        if not poll_s >= 0.0:
            raise ValueError(f"poll_s must be >= 0, got {poll_s!r}")
        self._sock = sock
        self._buf = bytearray()
        self._chunk = chunk
        self._poll_s = poll_s
        self._poller: Any = None

    def _poll(self) -> None:
        # Why: a process that sleeps in recv is woken when the bytes arrive, ~0.1-0.2 ms later
        # on a virtual machine, and that latency sits between every grant and its DONE
        if self._poller is None:
            self._poller = select.poll()
            self._poller.register(self._sock, select.POLLIN)
        poll, end = self._poller.poll, time.perf_counter() + self._poll_s
        while not poll(0) and time.perf_counter() < end:
            os.sched_yield()  # a process that needs this core gets it

    def close(self) -> None:
        """Drop what was read and not consumed (the socket is its owner's to close)."""
        self._buf.clear()

    @property
    def buffered(self) -> int:
        """Bytes received and not read yet."""
        return len(self._buf)

    def read(self, n: int) -> bytes:
        """``n`` bytes, fewer only when the peer closed (like a file's read)."""
        buf = self._buf
        while len(buf) < n:
            if self._poll_s and not buf:
                self._poll()
            data = self._sock.recv(max(self._chunk, n - len(buf)))
            if not data:
                break
            buf += data
        out = bytes(buf[:n])
        del buf[:n]
        return out


def _read_exact(stream: _Readable, n: int) -> bytes:
    if n == 0:
        return b""
    data = stream.read(n)
    if data is None or len(data) != n:
        got = 0 if data is None else len(data)
        raise LockstepClosed(f"lockstep channel closed after {got} of {n} bytes")
    return data
