"""An emulated MCU on a real pseudo-terminal: the pump between a pty master and ``Mcu``.

Bytes the host writes to the slave (``port``) are read from the master and put on the simulated
RX line at the current simulated time; bytes the firmware sent are written to the master once
simulated time has passed their last bit. Simulated time moves only when the owner calls
``advance_us`` (tests, the pytest plugin) or ``run_paced`` (``mobigrasp mcu``, which paces it to
the wall clock: pacing is a policy of the tool, never of the firmware). Writing never blocks: if
the host does not read and the pty buffer fills, the bytes are dropped and counted in
``host_tx_dropped``. Every frame the MCU sends is also decoded into ``sent`` for inspection.
"""

from __future__ import annotations

import errno
import os

from mobigrasp.link.base import LinkClosed
from mobigrasp.link.registry import open_transport
from mobigrasp.mcu_sim.backend import McuBackend, open_mcu
from mobigrasp.mcu_sim.mcu import McuConfig
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.protocol.messages import MessageError, Telemetry, decode_frame


class PtyMcu:
    """An MCU (backend ``backend``, mobigrasp.mcu_sim.backend) + the master end of a new pty;
    ``port`` is the slave path a host opens."""

    def __init__(self, config: McuConfig | None = None, record: bool = True,
                 backend: str = "python") -> None:
        self.mcu: McuBackend = open_mcu(backend, config)
        self.transport = open_transport("pty://")
        self.port: str = self.transport.slave_path
        self.record = record
        self.sent: list[tuple[int, object]] = []  # (t_us, decoded message) the MCU sent
        self.bytes_from_host = 0
        self.host_tx_dropped = 0
        self.host_closed = False
        self._parser = FrameParser()

    @property
    def now_us(self) -> int:
        """Simulated time in µs."""
        return self.mcu.now_us

    def pump_from_host(self, timeout_s: float = 0.0) -> int:
        """Move bytes waiting on the pty onto the RX line now; returns how many were read.
        ``timeout_s`` > 0 waits that long for the first byte (wall clock: a tool policy)."""
        if self.host_closed:
            return 0
        total = 0
        try:
            if timeout_s > 0 and not self.transport.wait_readable(timeout_s):
                return 0
            while True:
                data = self.transport.read()
                if not data:
                    break
                total += len(data)
                self.mcu.uart_rx(data, self.mcu.now_us)
        except LinkClosed:
            self.host_closed = True
        self.bytes_from_host += total
        return total

    def wait_from_host(self, n_bytes: int, timeout_s: float = 10.0) -> bool:
        """Block until ``bytes_from_host`` reaches ``n_bytes`` (a pty hands bytes over
        asynchronously); False on timeout. Simulated time does not move."""
        while self.bytes_from_host < n_bytes and not self.host_closed:
            if not self.pump_from_host(timeout_s):
                return False
        return self.bytes_from_host >= n_bytes

    def forward_tx(self) -> None:
        """Write what the MCU has sent by now to the pty (never blocks; drops are counted)."""
        fd = self.transport.fileno()
        for t_us, data in self.mcu.uart_tx_take():
            if self.record:
                for frame in self._parser.feed(data):
                    try:
                        self.sent.append((t_us, decode_frame(frame)))
                    except MessageError:
                        pass
            if self.host_closed or fd is None:
                continue
            view = memoryview(data)
            while view:
                try:
                    n = os.write(fd, view)
                except BlockingIOError:
                    self.host_tx_dropped += len(view)
                    break
                except OSError as exc:
                    if exc.errno == errno.EIO:
                        self.host_closed = True
                        break
                    raise
                view = view[n:]

    def advance_us(self, delta_us: int, step_us: int = 1000) -> None:
        """Run simulated time forward by ``delta_us``, pumping the pty every ``step_us``."""
        if delta_us < 0:
            raise ValueError(f"delta_us must be >= 0, got {delta_us}")
        target = self.mcu.now_us + int(delta_us)
        while True:
            self.pump_from_host()
            t = min(target, self.mcu.now_us + step_us)
            self.mcu.advance_to(t)
            self.forward_tx()
            if t >= target:
                break

    def telemetry(self) -> list[Telemetry]:
        """Telemetry messages sent so far, oldest first."""
        return [m for _, m in self.sent if isinstance(m, Telemetry)]

    def close(self) -> None:
        """Close the pty master (the host then sees EOF/EIO)."""
        self.transport.close()
