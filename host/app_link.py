"""The host program's side of the serial protocol: handshake, heartbeat, reliable commands.

No I/O and no clock: bytes come in with their arrival time (:meth:`HostLink.receive`) and outgoing
wire bytes are queued with the simulated time the host finished producing them
(:meth:`HostLink.take_output`). The driver (lockstep client or a real-board loop) moves bytes
between this object and the serial port. Reliable commands (docs/protocol.md) go through
:class:`mobigrasp.protocol.reliable.RetransmitQueue`: resent with the same seq until ACKed/NACKed.

Every outgoing command is validated before it is encoded: a NaN, an infinity, a non-integer or a
value outside the protocol's range is refused and counted (``rejected_outputs``), never sent and
never a crash of the loop; servo targets are clamped to the joint table of docs/conventions.md.
One policy, in host/outgoing_guard.py: coerce (:func:`coerce_int`), clamp, check.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, replace

from mobigrasp.host import arm_calib
from mobigrasp.host.mcu_watch import McuWatch
from mobigrasp.host.outgoing_guard import check_gripper, check_servo_mrad, check_wheels, coerce_int
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import PROTOCOL_VERSION, FrameParser
from mobigrasp.protocol.reliable import RetransmitQueue, SequenceCounter

HOST_ID = "mobigrasp-2440"  # at most 16 ASCII chars (protocol)


_SEND_TIME = operator.itemgetter(0)  # of an outbox chunk (at_us, wire)
_COERCE_LIM = 1 << 62  # the range coerce_int accepts (host.outgoing_guard)
_SUPERSEDING = (m.SetServos, m.Gripper)  # a newer one cancels the unanswered older one
_JOINT_LO = tuple(lo for lo, _ in arm_calib.JOINT_LIMITS_MRAD[1:])  # channels 1..5
_JOINT_HI = tuple(hi for _, hi in arm_calib.JOINT_LIMITS_MRAD[1:])
# The MCU's power-on pose (docs/firmware.md "Reset"): what a channel is taken to be at until a
# readable pulse has been seen on it.
_POWER_ON_PULSES_US = (1000, 1500, 1500, 1500, 1500, 1500)


@dataclass
class LinkCounters:
    """Protocol figures the run summary reports (``protocol {...}``, docs/cosim.md)."""

    tx_frames: int = 0
    tx_bytes: int = 0
    rx_frames: int = 0
    rx_bytes: int = 0
    decode_errors: int = 0
    retransmits: int = 0
    reliable_failed: int = 0
    nacks: int = 0
    rejected_outputs: int = 0
    clamped_outputs: int = 0
    telemetry: int = 0
    odd_telemetry: int = 0  # in-spec telemetry with a servo pulse the joint table cannot read


class HostLink:
    """Protocol state of the host: what it knows of the MCU, and the queue of bytes to send."""

    def __init__(self, retransmit_timeout_us: int = 40_000, max_retries: int = 10) -> None:
        self.parser = FrameParser()
        self.seq = SequenceCounter()
        self.reliable = RetransmitQueue(timeout_us=retransmit_timeout_us, max_retries=max_retries)
        self.counters = LinkCounters()
        self.telemetry: m.Telemetry | None = None
        self.telemetry_us = -1
        self.handshake_ok = False
        self._hello_seq: int | None = None
        self._outbox: list[tuple[int, bytes]] = []
        self.events: list[dict] = []
        self.rx_bytes_since_take = 0
        self.gripper_permille = 0
        self.watch = McuWatch()
        self.mcu_resets = 0
        self._latest_seq: dict[type, int] = {}  # newest reliable seq per superseding type
        self._last_servos: m.SetServos | None = None  # newest SetServos (mrad), for send_gripper
        self._readable_pulses_us = _POWER_ON_PULSES_US  # newest readable pulse per channel

    # ---- receiving -------------------------------------------------------------------------
    def receive(self, data: bytes, arrival_us: int) -> None:
        """Bytes read from the serial port that arrived at ``arrival_us``."""
        self.counters.rx_bytes += len(data)
        self.rx_bytes_since_take += len(data)
        for frame in self.parser.feed(data):
            try:
                msg = m.decode_frame(frame)
            except ValueError:
                self.counters.decode_errors += 1
                continue
            self.counters.rx_frames += 1
            self._dispatch(msg, arrival_us)

    def _dispatch(self, msg: m.Message, t_us: int) -> None:
        if isinstance(msg, m.Telemetry):
            self.telemetry = self._readable(msg)
            self.telemetry_us = t_us
            self.counters.telemetry += 1
            why = self.watch.feed(msg.time_us, msg.flags)
            if why is not None:  # the MCU reset and forgot the session: HELLO again
                self.mcu_resets += 1
                self.handshake_ok = False
                self.reliable.clear()
                self._latest_seq.clear()
                self.events.append({"ev": "mcu_reset_seen", "t_us": t_us, "why": why})
        elif isinstance(msg, m.Ack):
            # The ACK of a HELLO is not the end of it: only HELLO_ACK opens the session, so a
            # lost HELLO_ACK must leave the HELLO in the retransmit queue (the MCU answers a
            # repeated HELLO with ACK and HELLO_ACK again).
            if msg.acked_seq != self._hello_seq or self.handshake_ok:
                self.reliable.ack(msg.acked_seq)
        elif isinstance(msg, m.Nack):
            if self.reliable.ack(msg.acked_seq):
                self.counters.nacks += 1
                self.events.append({"ev": "nack", "t_us": t_us, "seq": msg.acked_seq,
                                    "reason": msg.reason})
        elif isinstance(msg, m.HelloAck):
            if self._hello_seq is not None:
                self.reliable.ack(self._hello_seq)
            self.handshake_ok = msg.proto_version == PROTOCOL_VERSION
            if self.handshake_ok:
                self.watch.handshake_done()
            self.events.append({"ev": "hello_ack", "t_us": t_us,
                                "firmware_id": msg.firmware_id, "ok": self.handshake_ok})
        elif isinstance(msg, m.Log):
            self.events.append({"ev": "mcu_log", "t_us": t_us, "code": msg.code,
                                "text": msg.text})

    def _readable(self, tel: m.Telemetry) -> m.Telemetry:
        """``tel`` with every servo pulse the joint table can read (500..2500 us). The spec
        allows any u16 (0 = "off"): such a channel keeps its newest readable pulse, and the
        frame is counted in ``odd_telemetry``; the other fields are taken as they came."""
        pulses = tel.servo_us
        lo, hi = arm_calib.PULSE_MIN_US, arm_calib.PULSE_MAX_US
        if lo <= min(pulses) and max(pulses) <= hi:  # every frame of a working MCU
            self._readable_pulses_us = pulses
            return tel
        self.counters.odd_telemetry += 1
        kept = tuple(p if lo <= p <= hi else old
                     for p, old in zip(pulses, self._readable_pulses_us, strict=True))
        self._readable_pulses_us = kept
        return replace(tel, servo_us=kept)

    # ---- sending ---------------------------------------------------------------------------
    def send(self, msg: m.Message, at_us: int) -> int:
        """Queue ``msg`` to leave at ``at_us``; reliable ones are tracked for retransmission."""
        seq = self.seq.next()
        while msg.RELIABLE and seq in self.reliable:
            seq = self.seq.next()  # never reuse a seq still waiting for its answer
        wire = m.encode_message(msg, seq)
        if msg.RELIABLE:
            # A newer SetServos/Gripper supersedes an unanswered older one: never let a late
            # retransmission of the old command execute after the new one (protocol.reliable).
            if isinstance(msg, _SUPERSEDING):
                old = self._latest_seq.get(type(msg))
                if old is not None:
                    self.reliable.cancel(old)
                self._latest_seq[type(msg)] = seq
            self.reliable.track(seq, wire, at_us)
        self._queue(wire, at_us)
        return seq

    def _queue(self, wire: bytes, at_us: int) -> None:
        self.counters.tx_frames += 1
        self.counters.tx_bytes += len(wire)
        self._outbox.append((at_us, wire))

    @property
    def needs_hello(self) -> bool:
        """True when no session is open and no HELLO is waiting for its answer."""
        return not self.handshake_ok and (self._hello_seq is None
                                          or self._hello_seq not in self.reliable)

    def hello(self, at_us: int) -> None:
        """Open the session (HELLO, reliable; the MCU answers ACK then HELLO_ACK)."""
        self._hello_seq = self.send(m.Hello(proto_version=PROTOCOL_VERSION, host_id=HOST_ID,
                                            capabilities=0), at_us)

    def service(self, now_us: int) -> None:
        """Resend reliable frames whose answer is overdue; report those that gave up."""
        for wire in self.reliable.due(now_us):
            self.counters.retransmits += 1
            self._queue(wire, now_us)
        for seq in self.reliable.failed():
            self.counters.reliable_failed += 1
            self.events.append({"ev": "reliable_failed", "t_us": now_us, "seq": seq})

    def take_output(self, before_us: int) -> list[tuple[int, bytes]]:
        """Wire chunks whose send time is before ``before_us``, in time order (removed)."""
        box = self._outbox
        if not box:
            return []
        box.sort(key=_SEND_TIME)
        # sorted by time: the chunks due are a prefix
        i = 0
        while i < len(box) and box[i][0] < before_us:
            i += 1
        out = box[:i]
        self._outbox = box[i:]
        return out

    def next_send_us(self) -> int | None:
        """Send time of the earliest chunk still queued (None when the outbox is empty)."""
        if not self._outbox:
            return None
        return min(t for t, _ in self._outbox)

    # ---- validated commands ----------------------------------------------------------------
    def send_servos_mrad(self, joints_mrad, at_us: int, slew_mrad_s: int = 0) -> bool:
        """SetServos in mrad for channels 1..5, clamped to the joint limits; channel 0 (the
        gripper, per mille in this mode) repeats the last gripper command so it is not
        disturbed. False if refused."""
        try:
            if len(joints_mrad) != 6:
                raise ValueError(f"servo targets must have 6 values, got {len(joints_mrad)}")
            # plain ints in range pass coerce_int unchanged: skip the calls for them
            if (set(map(type, joints_mrad)) == {int} and min(joints_mrad) >= -_COERCE_LIM
                    and max(joints_mrad) <= _COERCE_LIM):
                raw = list(joints_mrad)
            else:
                raw = [coerce_int(f"servo_mrad[{ch}]", v) for ch, v in enumerate(joints_mrad)]
            # arm_calib.clamp_mrad of channels 1..5, in C: raw holds plain ints here
            targets = [self.gripper_permille,
                       *map(min, map(max, raw[1:], _JOINT_LO), _JOINT_HI)]
            if targets[1:] != raw[1:]:
                self.counters.clamped_outputs += 1
            msg = m.SetServos(mode=m.SERVO_MODE_MRAD, targets=check_servo_mrad(targets),
                              slew=slew_mrad_s)
        except ValueError as exc:
            return self._reject("SetServos", exc, at_us)
        self._last_servos = msg
        self.send(msg, at_us)
        return True

    def send_wheels(self, left_mmps, right_mmps, at_us: int) -> bool:
        """SetWheels (not reliable: repeated every control step), clamped to ±1000 mm/s."""
        try:
            left = coerce_int("wheels.left_mmps", left_mmps)
            right = coerce_int("wheels.right_mmps", right_mmps)
            lim = m.WHEEL_SPEED_LIMIT_MMPS
            cl, cr = max(-lim, min(lim, left)), max(-lim, min(lim, right))
            if (cl, cr) != (left, right):
                self.counters.clamped_outputs += 1
            cl, cr = check_wheels(cl, cr)
            msg = m.SetWheels(left_mmps=cl, right_mmps=cr)
        except ValueError as exc:
            return self._reject("SetWheels", exc, at_us)
        self.send(msg, at_us)
        return True

    def send_gripper(self, close_permille, at_us: int) -> bool:
        """Gripper (reliable), 0 = open .. 1000 = closed, clamped."""
        try:
            value = check_gripper(max(0, min(1000, coerce_int("gripper_permille",
                                                               close_permille))))
            msg = m.Gripper(close_permille=value)
        except ValueError as exc:
            return self._reject("Gripper", exc, at_us)
        self.gripper_permille = value
        self.send(msg, at_us)
        # An unanswered SetServos carries the old gripper value on channel 0: a late
        # retransmission of it would open the gripper again after this command (seen under bit
        # error rate 1e-3: "gripper closed but no object held"). Send it again with the new
        # value; as the newer SetServos it cancels the old one (send()).
        last, old = self._last_servos, self._latest_seq.get(m.SetServos)
        if last is not None and old is not None and old in self.reliable \
                and last.targets[0] != value:
            self._last_servos = replace(last, targets=(value, *last.targets[1:]))
            self.send(self._last_servos, at_us)
        return True

    def send_heartbeat(self, at_us: int) -> None:
        """Heartbeat carrying the host's time (keeps the MCU watchdog fed when idle)."""
        self.send(m.Heartbeat(time_us=at_us & 0xFFFFFFFF), at_us)

    def send_stop(self, at_us: int) -> None:
        """Stop (reliable): wheels stopped, arm held."""
        self.send(m.Stop(), at_us)

    def _reject(self, what: str, exc: Exception, at_us: int) -> bool:
        self.counters.rejected_outputs += 1
        self.events.append({"ev": "output_rejected", "t_us": at_us, "msg": what,
                            "why": str(exc)[:200]})
        return False

    def stats(self) -> dict:
        """Counters for the summary, including the parser's rejections."""
        out = dict(vars(self.counters))
        out["retransmits"] = self.counters.retransmits
        parser_stats = self.parser.stats
        out["crc_errors"] = getattr(parser_stats, "crc_errors", 0)
        out["parser"] = parser_stats.as_dict() if hasattr(parser_stats, "as_dict") else {}
        return out
