"""An emulated MCU on a real pseudo-terminal: the pump between a pty master and ``Mcu``.

Bytes the host writes to the slave (``port``) are read from the master and put on the simulated
RX line at the current simulated time; bytes the firmware sent are written to the master once
simulated time has passed their last bit. Simulated time moves only when the owner calls
``advance_us`` / ``advance_to`` (tests, the pytest plugin, ``mobigrasp mcu``, which paces it to
the wall clock: pacing is a policy of the tool, never of the firmware). Writing never blocks: if
the host does not read and the pty buffer fills, the bytes are dropped and counted in
``host_tx_dropped``. Every frame the MCU sends is also decoded into ``sent`` for inspection.

With no world attached the encoders follow a wheel plant chosen by name (``WHEELS``):
``bench`` (the default) is mcu_sim/bench_plant.py's two unloaded motors, so a SetWheels turns
the encoders with the motor's lag; ``still`` leaves every count at 0 (the wheels held).
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable

from mobigrasp.link.base import LinkClosed
from mobigrasp.link.registry import open_transport
from mobigrasp.mcu_sim.backend import open_mcu
from mobigrasp.mcu_sim.bench_plant import WheelsInTheAir
from mobigrasp.mcu_sim.mcu import McuConfig
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.protocol.messages import MessageError, Telemetry, decode_frame

WHEELS = ("bench", "still")  # wheel plants by name; the first is the default
PLANT_STEP_US = 10_000  # the bench plant's step: encoder counts change at most this often


class PtyMcu:
    """``Mcu`` + the master end of a new pty; ``port`` is the slave path a host opens."""

    def __init__(self, config: McuConfig | None = None, record: bool = True,
                 wheels: str = WHEELS[0],
                 on_sent: Callable[[int, object], None] | None = None,
                 mcu: str = "python") -> None:
        """``record``: keep every decoded message the MCU sent in ``sent``; ``on_sent(t_us,
        message)`` is called for each of them either way (``mobigrasp mcu --log``); ``mcu``:
        the backend (mcu_sim/backend.py, ``python`` or ``native``)."""
        if wheels not in WHEELS:
            raise ValueError(f"wheels must be one of {', '.join(WHEELS)}, got {wheels!r}")
        self.wheels = wheels
        self._plant = WheelsInTheAir() if wheels == "bench" else None
        self._next_plant_us = 0
        self.mcu = open_mcu(mcu, config)
        self.transport = open_transport("pty://")
        self.port: str = self.transport.slave_path
        self.record = record
        self._on_sent = on_sent
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

    def wait_from_host(self, n_bytes: int | None = None, timeout_s: float = 10.0) -> bool:
        """Put everything the host has written so far on the RX line; simulated time does not
        move. A read of the master that finds nothing has waited for the kernel to hand over
        what a finished write() on the slave put in the pty (n_tty_read flushes the pty's
        buffer work first), so with no ``n_bytes`` one pass is enough and no one counts bytes.
        With ``n_bytes``: block until ``bytes_from_host`` reaches it; False on timeout."""
        if n_bytes is None:
            self.pump_from_host()
            return not self.host_closed
        while self.bytes_from_host < n_bytes and not self.host_closed:
            if not self.pump_from_host(timeout_s):
                return False
        return self.bytes_from_host >= n_bytes

    def forward_tx(self) -> None:
        """Write what the MCU has sent by now to the pty (never blocks; drops are counted)."""
        fd = self.transport.fileno()
        for t_us, data in self.mcu.uart_tx_take():
            if self.record or self._on_sent is not None:
                for frame in self._parser.feed(data):
                    try:
                        msg = decode_frame(frame)
                    except MessageError:
                        continue
                    if self.record:
                        self.sent.append((t_us, msg))
                    if self._on_sent is not None:
                        self._on_sent(t_us, msg)
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
        self.advance_to(self.mcu.now_us + int(delta_us), step_us)

    def advance_to(self, target_us: int, step_us: int = 1000) -> None:
        """Run simulated time to ``target_us``: every ``step_us`` the pty's bytes go onto the RX
        line and the MCU's onto the pty; every PLANT_STEP_US the wheel plant turns the
        encoders by the duties the MCU drives."""
        mcu = self.mcu
        while True:
            if self._plant is not None and mcu.now_us >= self._next_plant_us:
                left, right = self._plant.step(mcu.wheel_duty(), PLANT_STEP_US)
                self._next_plant_us = mcu.now_us + PLANT_STEP_US
                mcu.set_encoder_ticks(left, right, self._next_plant_us)
            self.pump_from_host()
            t = min(target_us, mcu.now_us + step_us)
            if self._plant is not None:
                t = min(t, self._next_plant_us)
            mcu.advance_to(t)
            self.forward_tx()
            if t >= target_us:
                break

    def nacks(self) -> list[tuple[int, str]]:
        """``(acked_seq, reason name)`` of every NACK the MCU sent, oldest first."""
        from mobigrasp.mcu_sim.wire_names import nacks_sent

        return nacks_sent(self.sent)

    def telemetry(self) -> list[Telemetry]:
        """Telemetry messages sent so far, oldest first."""
        return [m for _, m in self.sent if isinstance(m, Telemetry)]

    def close(self) -> None:
        """Close the pty master (the host then sees EOF/EIO)."""
        self.transport.close()
