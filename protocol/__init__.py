"""Framed binary serial protocol between the S3C2440 host and the ATmega128 (stdlib only, no I/O).

Typical use::

    from mobigrasp.protocol import encode_message, FrameParser, decode_frame, SetServos
    wire = encode_message(SetServos(mode=0, targets=(1500,) * 6, slew=0), seq=7)
    for frame in FrameParser().feed(wire):
        msg = decode_frame(frame)

The byte-level specification with golden vectors is docs/protocol.md.
"""

from mobigrasp.protocol.cobs import cobs_decode, cobs_encode
from mobigrasp.protocol.crc import crc16_ccitt_false, crc16_ccitt_false_table
from mobigrasp.protocol.frame import (
    MAX_ENCODED,
    MAX_PAYLOAD,
    MAX_WIRE,
    PROTOCOL_VERSION,
    Frame,
    FrameParser,
    ParserStats,
    encode_frame,
)
from mobigrasp.protocol.messages import (
    ALL_MESSAGES,
    FLAG_GRIPPER_CLOSED,
    FLAG_HANDSHAKE,
    FLAG_LIMIT,
    FLAG_RESET,
    FLAG_STOPPED,
    FLAG_WATCHDOG,
    MESSAGE_TYPES,
    NACK_BAD_LENGTH,
    NACK_BAD_PARAM,
    NACK_BAD_VERSION,
    NACK_NOT_READY,
    NACK_OUT_OF_RANGE,
    NACK_SEQ_REUSED,
    NACK_UNKNOWN_TYPE,
    RELIABLE_TYPES,
    SERVO_COUNT,
    SERVO_MODE_MRAD,
    SERVO_MODE_PULSE_US,
    SONAR_COUNT,
    SONAR_NO_ECHO,
    Ack,
    FieldRangeError,
    Gripper,
    Heartbeat,
    Hello,
    HelloAck,
    Log,
    Message,
    MessageError,
    Nack,
    ParamGet,
    ParamSet,
    ParamValue,
    PayloadLengthError,
    SetServos,
    SetWheels,
    Stop,
    Telemetry,
    UnknownTypeError,
    decode_frame,
    encode_message,
    message_frame,
)
from mobigrasp.protocol.reliable import DuplicateFilter, RetransmitQueue, SequenceCounter

__all__ = [
    "ALL_MESSAGES", "FLAG_GRIPPER_CLOSED", "FLAG_HANDSHAKE", "FLAG_LIMIT", "FLAG_RESET",
    "FLAG_STOPPED", "FLAG_WATCHDOG", "MAX_ENCODED", "MAX_PAYLOAD", "MAX_WIRE", "MESSAGE_TYPES",
    "NACK_BAD_LENGTH", "NACK_BAD_PARAM", "NACK_BAD_VERSION", "NACK_NOT_READY",
    "NACK_OUT_OF_RANGE", "NACK_SEQ_REUSED", "NACK_UNKNOWN_TYPE", "PROTOCOL_VERSION",
    "RELIABLE_TYPES",
    "SERVO_COUNT", "SERVO_MODE_MRAD", "SERVO_MODE_PULSE_US", "SONAR_COUNT", "SONAR_NO_ECHO",
    "Ack", "DuplicateFilter", "FieldRangeError", "Frame", "FrameParser", "Gripper", "Heartbeat",
    "Hello", "HelloAck", "Log", "Message", "MessageError", "Nack", "ParamGet", "ParamSet",
    "ParamValue", "ParserStats", "PayloadLengthError", "RetransmitQueue", "SequenceCounter",
    "SetServos", "SetWheels", "Stop", "Telemetry", "UnknownTypeError", "cobs_decode",
    "cobs_encode", "crc16_ccitt_false", "crc16_ccitt_false_table", "decode_frame",
    "encode_frame", "encode_message", "message_frame",
]
