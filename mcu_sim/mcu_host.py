"""A minimal in-process host end for :class:`mcu_sim.mcu.Mcu`, for tests and the MCU benchmark.

It puts encoded messages on the MCU's RX line at the current simulated time (the USART model
serialises them at the line rate) and decodes everything the MCU sends back, stamped with the
simulated time its last bit left. No pty, no wall clock: a whole exchange is deterministic.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.backend import McuBackend
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.protocol.messages import MessageError, Telemetry, decode_frame, encode_message
from mobigrasp.protocol.reliable import SequenceCounter


class InProcessHost:
    """Talks to one Mcu directly; ``received`` is the list of ``(t_us, message)`` from the MCU."""

    def __init__(self, mcu: McuBackend, decode: bool = True) -> None:
        self.mcu = mcu
        self.decode = decode  # False: only count frames (benchmarks measure the MCU, not us)
        self.frames = 0
        self.seq = SequenceCounter()
        self.parser = FrameParser()
        self.received: list[tuple[int, object]] = []
        self.decode_errors = 0
        self.tx_bytes = 0

    def send(self, msg, seq: int | None = None) -> int:
        """Encode ``msg`` (next seq unless given) onto the RX line now; returns the seq."""
        if seq is None:
            seq = self.seq.next()
        self.send_raw(encode_message(msg, seq))
        return seq

    def send_raw(self, data: bytes) -> int:
        """Raw bytes onto the RX line now; returns how many the line accepted."""
        self.tx_bytes += len(data)
        return self.mcu.uart_rx(bytes(data), self.mcu.now_us)

    def collect(self) -> None:
        """Decode what the MCU has sent so far."""
        for t_us, data in self.mcu.uart_tx_take():
            for frame in self.parser.feed(data):
                self.frames += 1
                if not self.decode:
                    continue
                try:
                    self.received.append((t_us, decode_frame(frame)))
                except MessageError:
                    self.decode_errors += 1

    def run_us(self, delta_us: int) -> None:
        """Advance the MCU by ``delta_us`` and collect its output."""
        self.mcu.advance_to(self.mcu.now_us + int(delta_us))
        self.collect()

    def run_ms(self, delta_ms: int) -> None:
        """Advance the MCU by ``delta_ms`` and collect its output."""
        self.run_us(int(delta_ms) * 1000)

    def messages(self, cls=None) -> list:
        """Messages received (of class ``cls`` if given), oldest first."""
        return [m for _, m in self.received if cls is None or isinstance(m, cls)]

    def telemetry(self) -> list[Telemetry]:
        """Telemetry received, oldest first."""
        return self.messages(Telemetry)

    def clear(self) -> None:
        """Forget what was received."""
        self.received.clear()
