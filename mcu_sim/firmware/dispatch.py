"""Frame dispatch of the firmware: what each command does (the ``switch (msg_type)`` of the C port).

``handle_frame`` is called by the main loop for every frame the parser accepted. Rules
(docs/firmware.md): nothing actuates before HELLO (NACK_NOT_READY); a frame whose payload does not
decode is NACKed with the protocol's reason and never actuates; reliable commands are ACKed, a
retransmitted copy (same seq and CRC) is answered again but not executed twice, and another
command reusing a recent seq is NACKed SEQ_REUSED (docs/protocol.md §5.2); STOP holds the arm and
stops the wheels. ``fw`` is the :class:`mcu_sim.firmware.program.Firmware` (the C globals).
"""

from __future__ import annotations

import struct

from mobigrasp.mcu_sim.firmware.servo_table import (
    GRIPPER_OPEN_US,
    SERVO_COUNT,
    mrad_slew_to_us,
    mrad_to_us,
)
from mobigrasp.protocol.frame import PROTOCOL_VERSION, frame_crc
from mobigrasp.protocol.messages import (
    NACK_BAD_PARAM,
    NACK_BAD_VERSION,
    NACK_NOT_READY,
    NACK_SEQ_REUSED,
    SERVO_MODE_MRAD,
    Ack,
    Gripper,
    Heartbeat,
    Hello,
    HelloAck,
    MessageError,
    Nack,
    ParamGet,
    ParamSet,
    ParamValue,
    SetServos,
    SetWheels,
    Stop,
    decode_frame,
)
from mobigrasp.protocol.reliable import DUP_COPY, DUP_NEW

FIRMWARE_ID = "mobigrasp-avr"
CAP_SERVOS, CAP_WHEELS, CAP_SONARS, CAP_PARAMS = 1, 2, 4, 8
CAPABILITIES = CAP_SERVOS | CAP_WHEELS | CAP_SONARS | CAP_PARAMS
SET_WHEELS_STRUCT = struct.Struct("<hh")
SET_WHEELS_TYPE = SetWheels.MSG_TYPE
WHEEL_MMPS_MAX = 1000  # protocol range of SetWheels fields


def handle_frame(fw, frame, now: int) -> None:
    """Dispatch one checked frame received at ``now`` (µs since reset)."""
    if frame.msg_type == SET_WHEELS_TYPE and len(frame.payload) == SET_WHEELS_STRUCT.size:
        # Hot path (50 Hz stream): unpack the two int16 like the C switch does; anything odd
        # falls through to the general decoder, which NACKs it with the protocol's reason.
        left, right = SET_WHEELS_STRUCT.unpack(frame.payload)
        lim = WHEEL_MMPS_MAX
        if -lim <= left <= lim and -lim <= right <= lim:
            fw.last_valid_us = now
            fw.watchdog_tripped = False
            fw.dup.observe(frame.seq)
            if not fw.handshake:
                fw.not_ready += 1
                return
            fw.set_wheels(left, right)
            return
    try:
        msg = decode_frame(frame)
    except MessageError as exc:
        fw.bad_frames += 1
        fw.send(Nack(frame.seq, exc.nack_reason))
        return
    fw.last_valid_us = now
    fw.watchdog_tripped = False
    seq = frame.seq
    if isinstance(msg, Hello):
        if msg.proto_version != PROTOCOL_VERSION:
            fw.send(Nack(seq, NACK_BAD_VERSION))
            return
        fw.dup.reset()  # a (re)started host counts from 0 again
        fw.dup.observe(seq)
        fw.dup.remember(seq, frame_crc(frame), 0)
        # a new session starts from the power-on safety PARAMs: no earlier session's
        # watchdog or limits carry over
        if fw.params.restore_safety():
            fw.apply_servo_limits()
        fw.handshake = True
        fw.send(Ack(seq))
        fw.send(HelloAck(PROTOCOL_VERSION, FIRMWARE_ID, CAPABILITIES))
        return
    fw.dup.observe(seq)
    if isinstance(msg, SetWheels):
        if not fw.handshake:
            fw.not_ready += 1
            return
        fw.set_wheels(msg.left_mmps, msg.right_mmps)
        return
    if not msg.RELIABLE:
        if not isinstance(msg, Heartbeat):  # replies and logs are not for the MCU
            fw.unexpected += 1
        return
    if not fw.handshake:
        fw.not_ready += 1
        fw.send(Nack(seq, NACK_NOT_READY))
        return
    crc = frame_crc(frame)
    kind = fw.dup.classify(seq, crc)
    if kind == DUP_NEW:
        reason = execute(fw, msg)
        fw.dup.remember(seq, crc, reason)
    elif kind == DUP_COPY:  # a retransmission: the same answer again, not executed again
        reason = fw.dup.result(seq)
    else:  # another command with a recent seq: refused, and the slot keeps the first one
        reason = NACK_SEQ_REUSED
    if reason:
        fw.send(Nack(seq, reason))
    else:
        fw.send_ack(seq)
    if not reason and isinstance(msg, ParamGet | ParamSet):
        value = fw.params.get(msg.param_id)
        if value is not None:
            fw.send(ParamValue(msg.param_id, value))

def execute(fw, msg) -> int:
    """Carry out a new reliable command; 0 or a NACK reason."""
    if isinstance(msg, SetServos):
        mrad = msg.mode == SERVO_MODE_MRAD
        slew_us = mrad_slew_to_us(msg.slew) if mrad else msg.slew
        servos = fw.servos
        targets = msg.targets
        for ch in range(SERVO_COUNT):
            pulse = mrad_to_us(ch, targets[ch]) if mrad else targets[ch]
            if servos.set_target_us(ch, pulse, slew_us):
                fw.count_limit()
        # then the six OCRs: a channel's OCR depends on that channel's state alone, so this is
        # what writing each right after its target gives
        fw.write_all_ocrs()
        fw.stopped = False
        return 0
    if isinstance(msg, Gripper):
        if fw.servos.set_target_us(0, GRIPPER_OPEN_US + msg.close_permille, 0):
            fw.count_limit()
        fw.write_ocr(0)
        return 0
    if isinstance(msg, Stop):
        fw.stop_wheels()
        fw.hold_arm()
        fw.stopped = True
        return 0
    if isinstance(msg, ParamGet):
        return 0 if fw.params.get(msg.param_id) is not None else NACK_BAD_PARAM
    if isinstance(msg, ParamSet):
        reason = fw.params.check(msg.param_id, msg.value)
        if reason == 0:
            fw.params.set(msg.param_id, msg.value)
            fw.apply_servo_limits()
        return reason
    return NACK_BAD_PARAM  # a reliable type this firmware does not execute
