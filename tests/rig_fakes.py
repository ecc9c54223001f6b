"""Small stand-ins for the MCU, the plant and the task, to test the lockstep frame on its own.

FakeMcu models the line like the USART should: a byte is seen by the firmware only once its stop
bit arrived (start + (i+1)·10 bits at 115200 baud), and it answers HELLO / reliable commands and
sends telemetry at 50 Hz, so the host's handshake and ACK paths run.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import FrameParser


def byte_done_us(start_us: int, i: int) -> int:
    return start_us + -(-(i + 1) * 10 * 1_000_000 // 115_200)


class FakeMcu:
    def __init__(self, telemetry_period_us: int = 20_000) -> None:
        self.now_us = 0
        self._line: list[tuple[int, int]] = []  # (time the byte is complete, byte)
        self._parser = FrameParser()
        self.seen: list[tuple[int, m.Message]] = []  # (time seen by firmware, message)
        self.rx_chunks: list[tuple[int, bytes]] = []
        self._tx: list[tuple[int, bytes]] = []
        self._seq = 0
        self._next_tel = telemetry_period_us
        self._tel_period = telemetry_period_us
        self.wheels = (0, 0)
        self.enc = (0, 0)
        self.flags = 0

    def uart_rx(self, data: bytes, start_us: int | None = None) -> int:
        start_us = self.now_us if start_us is None else start_us
        assert start_us >= self.now_us, "bytes put on the line in the MCU's past"
        self.rx_chunks.append((start_us, bytes(data)))
        self._line += [(byte_done_us(start_us, i), b) for i, b in enumerate(data)]
        return len(data)

    def _send(self, msg: m.Message, t_us: int) -> None:
        self._tx.append((t_us, m.encode_message(msg, self._seq)))
        self._seq = (self._seq + 1) & 0xFF

    def advance_to(self, t_us: int) -> None:
        # telemetry due before t_us first: the chunks taken are in time order
        while self._next_tel <= t_us:
            self._send(m.Telemetry(time_us=self._next_tel, enc_left=self.enc[0],
                                   enc_right=self.enc[1], servo_us=(1500,) * 6,
                                   sonar_mm=(m.SONAR_NO_ECHO,) * 5, flags=self.flags,
                                   crc_errors=0,
                                   overruns=0, limit_hits=0, watchdog_trips=0), self._next_tel)
            self._next_tel += self._tel_period
        ready = [b for when, b in self._line if when <= t_us]
        self._line = [(w, b) for w, b in self._line if w > t_us]
        for frame in self._parser.feed(bytes(ready)):
            msg = m.decode_frame(frame)
            self.seen.append((t_us, msg))
            if msg.RELIABLE:
                self._send(m.Ack(acked_seq=frame.seq), t_us)
            if isinstance(msg, m.Hello):
                self.flags = m.FLAG_HANDSHAKE
                self._send(m.HelloAck(proto_version=1, firmware_id="fake", capabilities=0), t_us)
            if isinstance(msg, m.SetWheels):
                self.wheels = (msg.left_mmps, msg.right_mmps)
        self.now_us = t_us

    def advance_outputs(self, t_us: int):
        self.advance_to(t_us)
        return self.servo_pulses_us(), self.wheel_duty()

    def reset(self) -> None:
        self._line, self._tx, self.flags, self.wheels = [], [], 0, (0, 0)
        self._parser = FrameParser()

    def uart_tx_take(self):
        out, self._tx = self._tx, []
        return out

    def tx_idle_through_us(self):
        return None  # cannot tell: the rig issues no grant early

    baud = 115_200.0
    baud_error_pct = 0.0

    def servo_pulse_us(self, ch):
        return 1500

    def servo_pulses_us(self):
        return (1500,) * 6

    def wheel_duty(self):
        return (self.wheels[0] // 4, self.wheels[1] // 4)

    def set_encoder_ticks(self, left, right, t_us=None):
        self.enc = (left, right)

    def set_sonar_provider(self, fn):
        self.sonar = fn

    def safety_flags(self):
        return False, bool(self.flags & m.FLAG_HANDSHAKE)

    def limit_hits(self):
        return 0

    def stats(self):
        return {"frames_seen": len(self.seen)}


class FakePlant:
    def __init__(self) -> None:
        self.t_us = 0
        self.duty = (0, 0)
        self.ticks = [0, 0]

    def step_to(self, t_us):
        dt = t_us - self.t_us
        self.ticks[0] += self.duty[0] * dt // 10_000
        self.ticks[1] += self.duty[1] * dt // 10_000
        self.t_us = t_us

    def set_servo_pulse_us(self, ch, pulse_us):
        pass

    def set_wheel_duty(self, left, right):
        self.duty = (left, right)

    def encoder_ticks(self):
        return tuple(self.ticks)

    def sonar_range_m(self, index):
        return None

    def capture(self, t_us):
        img = np.zeros((24, 32, 3), np.uint8)
        img[:, :, 0] = (t_us // 1000) & 0xFF
        return img

    def truth(self, t_us):
        return {"ticks": list(self.ticks)}


@dataclass
class FakeOutputs:
    servo_mrad: tuple | None = None
    wheels_mmps: tuple | None = None
    gripper_permille: int | None = None
    events: list = field(default_factory=list)
    state: str = "SEARCH"
    detail: dict = field(default_factory=dict)
    ops: OpCounts | None = None


class FakeTask:
    """Drives forward after 3 detections of the fake detector, DONE at 300 ms."""

    def __init__(self, plan_cycles: int = 0) -> None:
        self.state = "SEARCH"
        self.seen = 0
        self.plan_cycles = plan_cycles
        self.steps: list[int] = []

    def detectors_needed(self):
        return ["blob"] if self.state == "SEARCH" else []

    def detector_fallbacks(self):
        return {}

    def step(self, now_us, inputs):
        self.steps.append(now_us)
        events = []
        ops = None
        if inputs.get("blob") is not None:
            self.seen += 1
        if self.state == "SEARCH" and self.seen >= 3:
            events.append({"t_us": now_us, "from": "SEARCH", "to": "APPROACH", "why": "seen"})
            self.state = "APPROACH"
            ops = OpCounts(alu=self.plan_cycles)
        elif self.state == "APPROACH" and now_us >= 300_000:
            events.append({"t_us": now_us, "from": "APPROACH", "to": "DONE", "why": "time"})
            self.state = "DONE"
        wheels = (200, 200) if self.state == "APPROACH" else (0, 0)
        return FakeOutputs(servo_mrad=(0, 0, -1571, -1571, 1571, 0), wheels_mmps=wheels,
                           events=events, state=self.state, ops=ops)


def blob_detector(cost_alu: int = 4_000_000):
    """A detector costing ``cost_alu`` cycles (10 ms at 400 MHz by default)."""
    def detect(rgb):
        return {"u_q4": 16 * 10, "v_q4": 16 * 12, "mean": int(rgb[..., 0].mean())}, \
            OpCounts(alu=cost_alu)
    return detect


def build_inputs(app, now_us, detections):
    return detections


class BufferPort:
    """A serial port of the lockstep client over two buffers: ``rx`` holds what the test put
    there for the host to read, ``tx`` collects what the host wrote."""

    def __init__(self) -> None:
        self.rx, self.tx = bytearray(), bytearray()

    def read(self) -> bytes:
        out, self.rx = bytes(self.rx), bytearray()
        return out

    def write(self, data: bytes) -> None:
        self.tx += data

    def wait_readable(self, timeout_s: float) -> bool:
        return bool(self.rx)


def scripted_grants(width: int = 32, height: int = 24, frame=None):
    """(grant, its UART bytes) of 0.8 s for a host program's tests: 5 ms quanta (one of 23 ms),
    the MCU's bytes of :func:`mcu_script`, a camera frame of ``width`` x ``height`` every 66 ms
    in the GRANT's blob (or ``frame(at_us)``'s: width, height, RGB bytes)."""
    from mobigrasp.cosim import lockstep as ls

    def plain(at: int) -> tuple[int, int, bytes]:
        return width, height, bytes([at % 251]) * (width * height * 3)

    t = 0
    for k in range(160):
        until = t + (23_000 if k == 50 else 5_000)
        chunks = mcu_script(t, until)
        frames = tuple(ls.FrameBlob(at // 66_000, at - 3000, at, *(frame or plain)(at)[:2], 3,
                                    (frame or plain)(at)[2])
                       for at in range(t - t % 66_000 + 66_000, until, 66_000))
        yield (ls.Grant(t, until, tuple((a, len(b)) for a, b in chunks), frames),
               b"".join(b for _, b in chunks))
        t = until


def mcu_script(t_us: int, until_us: int) -> list[tuple[int, bytes]]:
    """An MCU's bytes in [t, until) for a host program's tests: HELLO_ACK at 4 ms, telemetry
    every 10 ms (the reset flag at 405 ms), an ACK every 70 ms."""
    out = []
    for at in range(t_us - t_us % 1000, until_us, 1000):
        if not t_us <= at < until_us:
            continue
        if at == 4000:
            out.append((at, m.encode_message(m.HelloAck(1, "atmega128-fw"), 0)))
        if at % 10_000 == 5000:
            flags = m.FLAG_RESET if at == 405_000 else m.FLAG_HANDSHAKE
            out.append((at, m.encode_message(m.Telemetry(at, 0, 0, (1500,) * 6, (2500,) * 5,
                                                         flags, 0, 0, 0, 0), 1)))
        if at % 70_000 == 33_000:
            out.append((at, m.encode_message(m.Ack(at // 70_000), 2)))
    return out
