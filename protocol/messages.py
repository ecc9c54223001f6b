"""The messages of the serial protocol: one frozen dataclass per message type.

Each class knows its ``MSG_TYPE``, whether it is ``RELIABLE`` (answered by ACK/NACK and
retransmitted until then), how to ``encode()`` its payload and ``decode()`` one. Values are checked
on construction, so a message that exists is always encodable; out-of-range values raise
:class:`FieldRangeError` (a ``ValueError``) naming the field and its range. All integers are
little-endian in integer units (µs, mrad, mm, mm/s, ticks, per mille). The byte layout of every
message is in docs/protocol.md; the ``_SPEC`` tuples below are that table in code, in wire order.
"""

from __future__ import annotations

import numbers
import struct
from dataclasses import dataclass
from typing import ClassVar, NamedTuple

from mobigrasp.protocol.frame import MAX_PAYLOAD, PROTOCOL_VERSION, Frame, encode_frame, encode_raw
from mobigrasp.protocol.frozen import built

# NACK reason codes (Nack.reason).
NACK_OUT_OF_RANGE = 1
NACK_UNKNOWN_TYPE = 2
NACK_BAD_LENGTH = 3
NACK_NOT_READY = 4
NACK_BAD_PARAM = 5
NACK_BAD_VERSION = 6
NACK_SEQ_REUSED = 7  # a reliable seq reused with other content inside the duplicate window

SERVO_MODE_PULSE_US = 0
SERVO_MODE_MRAD = 1
SERVO_COUNT = 6
SERVO_PULSE_MIN_US = 500
SERVO_PULSE_MAX_US = 2500
SERVO_MRAD_LIMIT = 3142  # ±π rad in mrad
SONAR_COUNT = 5
SONAR_NO_ECHO = 0xFFFF  # nothing within range, or that sonar is not fitted
WHEEL_SPEED_LIMIT_MMPS = 1000
GRIPPER_CLOSED_PERMILLE = 1000
ID_MAX_CHARS = 16
LOG_MAX_CHARS = 48

# Telemetry.flags bits.
FLAG_WATCHDOG = 1 << 0  # watchdog stop active (no valid frame from the host for watchdog_ms)
FLAG_LIMIT = 1 << 1  # a servo/wheel limit clamped a command since the previous telemetry
FLAG_HANDSHAKE = 1 << 2  # HELLO accepted: the MCU executes commands
FLAG_STOPPED = 1 << 3  # STOP received; cleared by the next motion command
FLAG_RESET = 1 << 4  # first telemetry after an MCU reset
FLAG_GRIPPER_CLOSED = 1 << 5  # gripper commanded closed (close_permille >= 500)


class MessageError(ValueError):
    """A payload or value the protocol does not allow; ``nack_reason`` is the NACK code to send."""

    nack_reason = NACK_OUT_OF_RANGE


class FieldRangeError(MessageError):
    """A field value outside its documented range (or of the wrong kind: bool, float, NaN...)."""

    nack_reason = NACK_OUT_OF_RANGE


class PayloadLengthError(MessageError):
    """A payload whose length does not match its message type."""

    nack_reason = NACK_BAD_LENGTH


class UnknownTypeError(MessageError):
    """A frame whose message type this protocol version does not define."""

    nack_reason = NACK_UNKNOWN_TYPE


_INT_ONLY = {int}  # the set of element types of a tuple of plain ints (bool is not int)


class _F(NamedTuple):
    """One wire field: struct code, inclusive range, element count (>1: a tuple)."""

    name: str
    code: str
    lo: int = 0
    hi: int = 0
    count: int = 1


_CODE_RANGE = {
    "B": (0, 0xFF), "H": (0, 0xFFFF), "h": (-0x8000, 0x7FFF),
    "I": (0, 0xFFFFFFFF), "i": (-0x80000000, 0x7FFFFFFF),
}


def _f(name: str, code: str, lo: int | None = None, hi: int | None = None, count: int = 1) -> _F:
    c_lo, c_hi = _CODE_RANGE[code]
    return _F(name, code, c_lo if lo is None else lo, c_hi if hi is None else hi, count)


def check_int(where: str, value: object, lo: int, hi: int) -> int:
    """``value`` as a Python int if it is an integer in [lo, hi], else FieldRangeError."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise FieldRangeError(f"{where} must be an integer in [{lo}, {hi}], got {value!r}")
    v = int(value)
    if not lo <= v <= hi:
        raise FieldRangeError(f"{where}={v} is out of range [{lo}, {hi}]")
    return v


def check_ascii(where: str, value: object, max_chars: int) -> str:
    """``value`` if it is a str of printable ASCII (0x20..0x7E) of at most ``max_chars``."""
    if not isinstance(value, str):
        raise FieldRangeError(f"{where} must be a str of printable ASCII, got {value!r}")
    if len(value) > max_chars:
        raise FieldRangeError(f"{where} has {len(value)} chars, at most {max_chars} allowed")
    for ch in value:
        if not " " <= ch <= "~":
            raise FieldRangeError(f"{where} must be printable ASCII (0x20..0x7E), got {ch!r}")
    return value


class Message:
    """Base of all messages: generic validation and (de)serialisation driven by ``_SPEC``.

    ``_SPEC`` lists the fixed-size fields in wire order; ``_TEXT`` names an optional trailing
    ASCII field of at most ``_TEXT_MAX`` bytes whose length is the rest of the payload.
    """

    MSG_TYPE: ClassVar[int]
    RELIABLE: ClassVar[bool] = False
    _SPEC: ClassVar[tuple[_F, ...]] = ()
    _TEXT: ClassVar[str | None] = None
    _TEXT_MAX: ClassVar[int] = 0
    _STRUCT: ClassVar[struct.Struct]
    _CHECKS: ClassVar[tuple[tuple[str, int, int, int], ...]]
    _NAMES: ClassVar[tuple[str, ...]]
    _INDEX: ClassVar[tuple[int | slice, ...]]
    _DYNAMIC_RANGE: ClassVar[bool]
    _TRUSTED_DECODE: ClassVar[bool]

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        fmt = "<" + "".join(f.code * f.count for f in cls._SPEC)
        cls._STRUCT = struct.Struct(fmt)
        # Every message fits a frame (so encode_message need not check the payload length).
        if cls._STRUCT.size + (cls._TEXT_MAX if cls._TEXT is not None else 0) > MAX_PAYLOAD:
            raise TypeError(f"{cls.__name__} payloads can exceed {MAX_PAYLOAD} bytes")
        # each field's index into the unpacked tuple: an int, or a slice for a counted field
        # (raw[index] is then the value decode() sets: the whole split runs in C)
        index, i = [], 0
        for f in cls._SPEC:
            index.append(i if f.count == 1 else slice(i, i + f.count))
            i += f.count
        cls._NAMES = tuple(f.name for f in cls._SPEC)
        cls._INDEX = tuple(index)
        cls._CHECKS = tuple((f.name, f.lo, f.hi, f.count) for f in cls._SPEC)
        cls._DYNAMIC_RANGE = cls._range is not Message._range
        # A payload of a type whose every field may take any value of its struct code (and
        # that has no text) decodes to a valid message by construction: decode() then skips
        # the field checks (telemetry, the bulk of what the host parses, is such a type).
        cls._TRUSTED_DECODE = (cls._TEXT is None and not cls._DYNAMIC_RANGE
                               and all((f.lo, f.hi) == _CODE_RANGE[f.code] for f in cls._SPEC))

    def _range(self, f: _F) -> tuple[int, int]:
        return f.lo, f.hi

    def _checks(self) -> tuple[tuple[str, int, int, int], ...]:
        """(name, lo, hi, count) of each field in wire order, with this message's ranges."""
        if not self._DYNAMIC_RANGE:
            return self._CHECKS
        return tuple((f.name, *self._range(f), f.count) for f in self._SPEC)

    def _plain_values(self) -> list[int] | None:
        """The wire values in order if every field already is a plain int (a tuple of plain
        ints for the counted ones) within its range, else None (then the full check decides).
        The cheap check of the hot paths (host commands built every control tick); it accepts
        exactly the values the full check below passes unchanged."""
        values: list[int] = []
        d = self.__dict__
        for name, lo, hi, count in self._checks():
            value = d.get(name)
            if count == 1:
                if type(value) is not int or not lo <= value <= hi:
                    return None
                values.append(value)
            else:
                # element checks in C (map, min, max): six servo targets every control tick
                if (type(value) is not tuple or len(value) != count
                        or set(map(type, value)) != _INT_ONLY
                        or min(value) < lo or max(value) > hi):
                    return None
                values += value
        return values

    def __post_init__(self) -> None:
        if self._TEXT is None and self._plain_values() is not None:
            return  # all plain ints in range: nothing to check further or convert
        name = type(self).__name__
        for f in self._SPEC:
            value = getattr(self, f.name)
            lo, hi = self._range(f)
            if f.count == 1:
                # fast path for the common case (a plain int in range); the where-string of
                # the error is only built when a value needs the full check
                if type(value) is int and lo <= value <= hi:
                    continue
                v = check_int(f"{name}.{f.name}", value, lo, hi)
            else:
                if isinstance(value, str | bytes) or not hasattr(value, "__len__"):
                    raise FieldRangeError(
                        f"{name}.{f.name} must be a sequence of {f.count} integers, got {value!r}"
                    )
                if len(value) != f.count:
                    raise FieldRangeError(
                        f"{name}.{f.name} must have exactly {f.count} values, got {len(value)}"
                    )
                if type(value) is tuple and all(type(x) is int and lo <= x <= hi
                                                 for x in value):
                    continue
                v = tuple(
                    check_int(f"{name}.{f.name}[{i}]", x, lo, hi) for i, x in enumerate(value)
                )
            object.__setattr__(self, f.name, v)
        if self._TEXT is not None:
            check_ascii(f"{name}.{self._TEXT}", getattr(self, self._TEXT), self._TEXT_MAX)

    def encode(self) -> bytes:
        """The payload bytes of this message (without frame header and CRC)."""
        # Re-checked because a frozen dataclass can still be mutated with object.__setattr__.
        values = self._plain_values() if self._TEXT is None else None
        if values is None:
            values = []
            for f in self._SPEC:
                value = getattr(self, f.name)
                if f.count == 1:
                    values.append(value)
                else:
                    values.extend(value)
            self.__post_init__()
        out = self._STRUCT.pack(*values)
        if self._TEXT is not None:
            out += getattr(self, self._TEXT).encode("ascii")
        return out

    @classmethod
    def decode(cls, payload: bytes):
        """Parse a payload; PayloadLengthError / FieldRangeError (ValueErrors) if it is bad."""
        payload = bytes(payload)
        size = cls._STRUCT.size
        n = len(payload)
        max_n = size + (cls._TEXT_MAX if cls._TEXT is not None else 0)
        if not size <= n <= max_n:
            want = f"{size}" if max_n == size else f"{size}..{max_n}"
            raise PayloadLengthError(f"{cls.__name__} payload must be {want} bytes, got {n}")
        raw = cls._STRUCT.unpack_from(payload)
        if cls._TRUSTED_DECODE:  # every unpacked value is valid: set the fields directly
            return built(cls, zip(cls._NAMES, map(raw.__getitem__, cls._INDEX), strict=True))
        kwargs: dict[str, object] = {}
        i = 0
        for f in cls._SPEC:
            if f.count == 1:
                kwargs[f.name] = raw[i]
            else:
                kwargs[f.name] = tuple(raw[i:i + f.count])
            i += f.count
        if cls._TEXT is not None:
            text = payload[size:]
            if any(not 0x20 <= b <= 0x7E for b in text):
                raise FieldRangeError(
                    f"{cls.__name__}.{cls._TEXT} must be printable ASCII, got {text!r}"
                )
            kwargs[cls._TEXT] = text.decode("ascii")
        return cls(**kwargs)


@dataclass(frozen=True)
class Hello(Message):
    """HELLO (host → MCU): opens the session; answered by ACK then HELLO_ACK, or
    NACK_BAD_VERSION when ``proto_version`` differs from the MCU's."""

    MSG_TYPE: ClassVar[int] = 0x01
    RELIABLE: ClassVar[bool] = True
    _SPEC: ClassVar = (_f("proto_version", "B"), _f("capabilities", "H"))
    _TEXT: ClassVar = "host_id"
    _TEXT_MAX: ClassVar = ID_MAX_CHARS
    proto_version: int
    host_id: str
    capabilities: int = 0


@dataclass(frozen=True)
class HelloAck(Message):
    """HELLO_ACK (MCU → host): the MCU's protocol version, firmware id and capability bits."""

    MSG_TYPE: ClassVar[int] = 0x02
    _SPEC: ClassVar = (_f("proto_version", "B"), _f("capabilities", "H"))
    _TEXT: ClassVar = "firmware_id"
    _TEXT_MAX: ClassVar = ID_MAX_CHARS
    proto_version: int
    firmware_id: str
    capabilities: int = 0


@dataclass(frozen=True)
class Heartbeat(Message):
    """HEARTBEAT (either way): sender's time in µs (wraps at 2^32); keeps the watchdog fed."""

    MSG_TYPE: ClassVar[int] = 0x03
    _SPEC: ClassVar = (_f("time_us", "I"),)
    time_us: int


@dataclass(frozen=True)
class SetServos(Message):
    """SET_SERVOS (host → MCU): six targets, channel = joint index of docs/conventions.md.

    mode 0 (PULSE_US): pulse widths 500..2500 µs; mode 1 (MRAD): joint angles -3142..3142 mrad.
    ``slew``: µs/s (mode 0) or mrad/s (mode 1) per channel, 0 = no limit.
    """

    MSG_TYPE: ClassVar[int] = 0x10
    RELIABLE: ClassVar[bool] = True
    _SPEC: ClassVar = (
        _f("mode", "B", 0, 1),
        _f("targets", "h", count=SERVO_COUNT),
        _f("slew", "H"),
    )
    mode: int
    targets: tuple[int, ...]
    slew: int = 0

    def _range(self, f: _F) -> tuple[int, int]:
        if f.name != "targets":
            return f.lo, f.hi
        if self.mode == SERVO_MODE_PULSE_US:
            return SERVO_PULSE_MIN_US, SERVO_PULSE_MAX_US
        return -SERVO_MRAD_LIMIT, SERVO_MRAD_LIMIT

    def _checks(self) -> tuple[tuple[str, int, int, int], ...]:
        # the table of each valid mode is built once (a host command every control tick)
        mode = self.mode
        if type(mode) is int and mode in (SERVO_MODE_PULSE_US, SERVO_MODE_MRAD):
            checks = _SERVO_CHECKS.get(mode)
            if checks is None:
                checks = _SERVO_CHECKS[mode] = super()._checks()
            return checks
        return super()._checks()


_SERVO_CHECKS: dict[int, tuple] = {}  # SetServos mode -> _checks() of that mode


@dataclass(frozen=True)
class Gripper(Message):
    """GRIPPER (host → MCU): 0 = fully open, 1000 = fully closed (per mille)."""

    MSG_TYPE: ClassVar[int] = 0x11
    RELIABLE: ClassVar[bool] = True
    _SPEC: ClassVar = (_f("close_permille", "H", 0, GRIPPER_CLOSED_PERMILLE),)
    close_permille: int


@dataclass(frozen=True)
class SetWheels(Message):
    """SET_WHEELS (host → MCU): wheel speed targets in mm/s, streamed (not acknowledged)."""

    MSG_TYPE: ClassVar[int] = 0x12
    _SPEC: ClassVar = (
        _f("left_mmps", "h", -WHEEL_SPEED_LIMIT_MMPS, WHEEL_SPEED_LIMIT_MMPS),
        _f("right_mmps", "h", -WHEEL_SPEED_LIMIT_MMPS, WHEEL_SPEED_LIMIT_MMPS),
    )
    left_mmps: int
    right_mmps: int


@dataclass(frozen=True)
class Stop(Message):
    """STOP (host → MCU): wheels to zero at once, arm holds its current pulses."""

    MSG_TYPE: ClassVar[int] = 0x13
    RELIABLE: ClassVar[bool] = True


@dataclass(frozen=True)
class Telemetry(Message):
    """TELEMETRY (MCU → host): state at MCU time ``time_us``; counters wrap modulo 2^16."""

    MSG_TYPE: ClassVar[int] = 0x20
    _SPEC: ClassVar = (
        _f("time_us", "I"),
        _f("enc_left", "i"),
        _f("enc_right", "i"),
        _f("servo_us", "H", count=SERVO_COUNT),
        _f("sonar_mm", "H", count=SONAR_COUNT),
        _f("flags", "H"),
        _f("crc_errors", "H"),
        _f("overruns", "H"),
        _f("limit_hits", "H"),
        _f("watchdog_trips", "H"),
    )
    time_us: int
    enc_left: int
    enc_right: int
    servo_us: tuple[int, ...]
    sonar_mm: tuple[int, ...]
    flags: int
    crc_errors: int
    overruns: int
    limit_hits: int
    watchdog_trips: int


@dataclass(frozen=True)
class ParamGet(Message):
    """PARAM_GET (host → MCU): answered by ACK then PARAM_VALUE (or NACK_BAD_PARAM)."""

    MSG_TYPE: ClassVar[int] = 0x30
    RELIABLE: ClassVar[bool] = True
    _SPEC: ClassVar = (_f("param_id", "H"),)
    param_id: int


@dataclass(frozen=True)
class ParamSet(Message):
    """PARAM_SET (host → MCU): answered by ACK then PARAM_VALUE with the value now in force."""

    MSG_TYPE: ClassVar[int] = 0x31
    RELIABLE: ClassVar[bool] = True
    _SPEC: ClassVar = (_f("param_id", "H"), _f("value", "i"))
    param_id: int
    value: int


@dataclass(frozen=True)
class ParamValue(Message):
    """PARAM_VALUE (MCU → host): a parameter's current value."""

    MSG_TYPE: ClassVar[int] = 0x32
    _SPEC: ClassVar = (_f("param_id", "H"), _f("value", "i"))
    param_id: int
    value: int


@dataclass(frozen=True)
class Ack(Message):
    """ACK: the reliable frame with sequence number ``acked_seq`` was received and executed."""

    MSG_TYPE: ClassVar[int] = 0x40
    _SPEC: ClassVar = (_f("acked_seq", "B"),)
    acked_seq: int


@dataclass(frozen=True)
class Nack(Message):
    """NACK: the reliable frame ``acked_seq`` was received but refused for ``reason`` (NACK_*).

    Any u8 reason decodes, so a newer peer's codes still end the retransmission."""

    MSG_TYPE: ClassVar[int] = 0x41
    _SPEC: ClassVar = (_f("acked_seq", "B"), _f("reason", "B"))
    acked_seq: int
    reason: int


@dataclass(frozen=True)
class Log(Message):
    """LOG (either way): a numeric code and a short printable-ASCII text."""

    MSG_TYPE: ClassVar[int] = 0x50
    _SPEC: ClassVar = (_f("code", "H"),)
    _TEXT: ClassVar = "text"
    _TEXT_MAX: ClassVar = LOG_MAX_CHARS
    code: int
    text: str = ""


ALL_MESSAGES: tuple[type[Message], ...] = (
    Hello, HelloAck, Heartbeat, SetServos, Gripper, SetWheels, Stop, Telemetry,
    ParamGet, ParamSet, ParamValue, Ack, Nack, Log,
)
MESSAGE_TYPES: dict[int, type[Message]] = {cls.MSG_TYPE: cls for cls in ALL_MESSAGES}
RELIABLE_TYPES: frozenset[int] = frozenset(c.MSG_TYPE for c in ALL_MESSAGES if c.RELIABLE)


def message_frame(msg: Message, seq: int) -> Frame:
    """The Frame carrying ``msg`` with sequence number ``seq`` (0..255)."""
    if not isinstance(msg, Message):
        raise TypeError(f"not a protocol message: {msg!r}")
    return Frame(PROTOCOL_VERSION, seq, msg.MSG_TYPE, msg.encode())


def encode_message(msg: Message, seq: int) -> bytes:
    """Wire bytes (COBS frame + 0x00 delimiter) of ``msg`` with sequence number ``seq``."""
    if type(seq) is int and 0 <= seq <= 0xFF and isinstance(msg, Message):
        # the checks of Frame hold by construction here (version and type are constants, every
        # payload fits: Message.__init_subclass__), so no Frame object is built
        return encode_raw(PROTOCOL_VERSION, seq, msg.MSG_TYPE, msg.encode())
    return encode_frame(message_frame(msg, seq))  # raises the error of the bad argument


def decode_frame(frame: Frame) -> Message:
    """The message a checked frame carries; UnknownTypeError / PayloadLengthError /
    FieldRangeError (all MessageError, a ValueError with ``nack_reason``) if it cannot."""
    cls = MESSAGE_TYPES.get(frame.msg_type)
    if cls is None:
        raise UnknownTypeError(f"unknown message type 0x{frame.msg_type:02X}")
    return cls.decode(frame.payload)
