"""The rig: the time authority that couples the emulated MCU, the plant and the host in lockstep.

Spec: docs/cosim.md. Simulated time advances in quanta of ``quantum_us``. For quantum [T, T+Q):

1. :meth:`Rig.grant` writes the bytes the MCU sent in the previous quantum to the serial port (the
   pty master, or the in-process pair) and returns a GRANT listing them with their arrival times
   (the time their stop bit left the MCU) and the camera frames captured, each with its capture
   time; the host may run up to T+Q and no further.
2. The host answers DONE with the chunks it wrote and their send times. :meth:`Rig.complete`
   reads exactly that many bytes from the port, puts each chunk on the simulated line at its send
   time (serialised at the host's baud rate, so a command is not seen by the MCU before its last
   byte arrived), then advances MCU and plant together to T+Q in ``couple_us`` steps, capturing
   frames at the camera rate.

The host thus sees MCU output with at most one quantum of extra latency (it polls its UART once
per quantum), and the MCU sees host output at exactly the modelled line times. Nothing here reads
the wall clock: pacing to real time is a policy of the caller (tools/commands/run.py).

With ``host_lag_quanta`` = 1 (the default of ``mobigrasp run``) the grant for [T+Q, T+2Q) is
issued when the rig is at T, with what the MCU and camera produced before T: the host's UART and
CAMIF hand data over one quantum later (5-10 ms instead of 0-5 ms), and in exchange the host serves
the next quantum while the rig simulates this one, so the two processes overlap instead of taking
turns. The MCU still sees every host byte at its modelled line time.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from mobigrasp.cosim.lockstep import Done, FrameBlob, Grant
from mobigrasp.cosim.plant import Plant
from mobigrasp.mcu_sim.avr import pinmap
from mobigrasp.mcu_sim.backend import McuBackend

HOST_BAUD = 115_200
BITS_PER_BYTE = 10  # 8N1: start + 8 data + stop


def byte_time_us(n_bytes: int, baud: int = HOST_BAUD) -> int:
    """Integer µs for the last stop bit of ``n_bytes`` sent back to back at ``baud`` 8N1."""
    return -(-n_bytes * BITS_PER_BYTE * 1_000_000 // baud)


class PortLike(Protocol):
    """The rig's end of the serial line (link.base.Transport)."""

    def write(self, data: bytes) -> None: ...
    def read(self) -> bytes: ...
    def wait_readable(self, timeout_s: float) -> bool: ...


@dataclass(frozen=True)
class RigConfig:
    """Timing of the co-simulation. All integer microseconds of simulated time."""

    quantum_us: int = 5_000
    couple_us: int = 1_000  # MCU <-> plant exchange period (the 1 kHz physics step)
    camera_fps: int = 15
    host_baud: int = HOST_BAUD
    # grants issued this many quanta ahead of the rig (0: strict alternation; 1: overlap, with the
    # host's input one quantum later; see the module docstring)
    host_lag_quanta: int = 0
    read_timeout_s: float = 60.0  # safety limit only: a healthy peer answers at once

    def __post_init__(self) -> None:
        for name in ("quantum_us", "couple_us", "camera_fps", "host_baud"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value <= 0:
                raise ValueError(f"RigConfig.{name} must be a positive integer, got {value!r}")
        lag = self.host_lag_quanta
        if not isinstance(lag, int) or isinstance(lag, bool) or not 0 <= lag <= 4:
            raise ValueError(f"RigConfig.host_lag_quanta must be an integer in [0, 4], got {lag!r}")
        if self.quantum_us % self.couple_us:
            raise ValueError(f"RigConfig.quantum_us ({self.quantum_us}) must be a multiple of "
                             f"couple_us ({self.couple_us})")

    def capture_time_us(self, k: int) -> int:
        """Capture time of frame ``k`` (k·10⁶/fps, rounded down: no drift over a long run)."""
        return k * 1_000_000 // self.camera_fps


def _pixels(rgb: Any) -> Any:
    """A frame's pixels for its FrameBlob: a flat read-only view of the array when it is
    contiguous (the array is not written after its capture: the plant's frames are new arrays
    or read-only, cosim/rig_plant.py), else a copy. The view compares, encodes and
    np.frombuffer-s like the bytes it saves copying (the frame ring copies it once anyway); it
    cannot be hashed (nothing hashes a grant)."""
    if rgb.flags.c_contiguous:
        return memoryview(rgb).cast("B").toreadonly()
    return rgb.tobytes()


class RigPortError(RuntimeError):
    """The host announced bytes that never arrived on the serial port (within the safety limit)."""


class Rig:
    """Couples an MCU, a plant and a serial port end; grants the host time quantum by quantum."""

    def __init__(self, mcu: McuBackend, plant: Plant, port: PortLike,
                 config: RigConfig | None = None,
                 on_frame: Callable[[int, int, Any], None] | None = None) -> None:
        self.mcu = mcu
        self.plant = plant
        self.port = port
        self.config = config or RigConfig()
        self.now_us = 0
        self.granted_until_us = 0  # end of the last grant issued
        self._on_frame = on_frame
        self._tx_pending: list[tuple[int, bytes]] = []
        self._tx_written = 0  # how many of _tx_pending are on the port already
        self._rx_ahead = bytearray()  # host bytes read for a DONE not completed yet
        self._frames_pending: list[tuple[int, int, Any]] = []
        self._next_frame = 0
        self._line_free_us = 0  # host -> MCU line busy until (serialises the host's chunks)
        self._pulses: list = [None] * 6
        self.stats = {"quanta": 0, "uart_to_host_bytes": 0, "uart_to_mcu_bytes": 0,
                      "frames_captured": 0, "frames_skipped": 0,
                      "grants_early": 0}
        self.camera_on = True
        # _couple runs twice per quantum: its calls are bound once here (through a delegating
        # wrapper every attribute lookup is a __getattr__ call)
        self._couple_calls = (mcu.advance_outputs, mcu.uart_tx_take, plant.set_servo_pulse_us,
                              plant.set_wheel_duty, plant.step_to)
        # the sensors, wired as the board table declares them (mcu_sim/avr/pinmap.py SENSORS):
        # a coupled one is read at every coupling step, a polled one when the firmware asks
        self._coupled_sensors = tuple(
            (getattr(plant, s.plant_reading), getattr(mcu, s.mcu_input))
            for s in pinmap.SENSORS if s.feed == pinmap.COUPLED)
        for s in pinmap.SENSORS:
            if s.feed == pinmap.POLLED:
                getattr(mcu, s.mcu_input)(self._polled(getattr(plant, s.plant_reading)))
        # what the plant was last given: a servo pulse or duty that did not change is not sent
        # again (the plant keeps its inputs; they change a few times per second)
        self._pulses_seen: tuple | None = None
        self._duty_sent: tuple[int, int] | None = None
        self._tx_idle = mcu.tx_idle_through_us

    def _polled(self, read: Callable[[int], Any]) -> Callable[[int], Any]:
        """The provider a polled sensor's MCU input is given: ``read(index)`` of the plant as
        it is at the last coupling step, read once per index and coupling step (the MCU polls
        one sonar at a time)."""
        cache: dict[int, Any] = {}
        cached_at = -1

        def provide(index: int) -> Any:
            nonlocal cached_at
            if cached_at != self.now_us:
                cache.clear()
                cached_at = self.now_us
            if index not in cache:
                cache[index] = read(index)
            return cache[index]

        return provide

    # how many quanta before its usual time (with a lag) a grant may go when it would be the same:
    # the host then has that much more of the rig's time to answer it (a control tick's grant: the
    # quantum before a tick usually holds the MCU's telemetry, two before it the last tick's
    # command, so two is what paper000-exp1 can use)
    max_early_quanta = 2

    def grants_due(self, done: Done | None = None,
                   early_wanted: Callable[[int], bool] | None = None,
                   issued: Sequence[Done] = ()) -> int:
        """How many grants to issue before completing the quantum at now: the grant of
        [now, now+Q) itself and ``host_lag_quanta`` beyond it, less those already issued.

        Given ``done``, the DONE this quantum completes with, and with a lag, up to
        ``max_early_quanta`` more while each would be the same grant issued later
        (:meth:`quiet_through` the time it would be issued at; ``issued``: the DONEs of the
        grants issued beyond now, in order) and ``early_wanted(its start_us)`` (default: yes)
        says it helps: the host gets it earlier by the rig's time, with exactly the same
        content."""
        q = self.config.quantum_us
        lag = self.config.host_lag_quanta
        due = max(0, (self.now_us + (lag + 1) * q - self.granted_until_us) // q)
        if not lag or done is None:
            return due
        early = 0
        while True:
            start = self.granted_until_us + (due + early) * q
            upto = start - lag * q  # when the rig would issue it
            if (upto > self.now_us + self.max_early_quanta * q
                    or (early_wanted is not None and not early_wanted(start))
                    or not self.quiet_through(done, upto, issued)):
                break
            early += 1
        self.stats["grants_early"] += early
        return due + early

    def quiet_through(self, done: Done, upto_us: int, issued: Sequence[Done] = ()) -> bool:
        """Whether completing the quanta from now to ``upto_us`` cannot give the host anything:
        no camera frame slot falls in (now, upto_us], the host writes nothing in them (``done``
        for [now, now+Q), then ``issued`` in order: DONEs without writes; one still to be read
        says so by its ``writes_nothing()``), and the MCU can finish sending
        no byte by ``upto_us`` (``tx_idle_through_us``: its TX line idle, nothing received
        left to answer, the next telemetry not before it; None: it cannot tell). A grant issued at
        ``upto_us`` would
        then hold what one issued now holds."""
        if done.writes:
            return False
        q = self.config.quantum_us
        between = (upto_us - self.now_us) // q - 1  # quanta after now's, before upto_us
        if between > len(issued):
            return False
        for i in range(between):
            d = issued[i]
            if d.writes or not d.writes_nothing():
                return False
        if self.config.capture_time_us(self._next_frame) <= upto_us:
            return False
        idle = self._tx_idle()
        return idle is not None and idle >= upto_us

    def grant(self) -> Grant:
        """The next quantum's grant (the one after the last issued, [now, now+Q) with no lag):
        hand over the MCU bytes (on the port) and the frames captured so far."""
        start = self.granted_until_us
        if start < self.now_us:
            raise ValueError(f"grant for {start} us issued after the rig passed it "
                             f"({self.now_us} us)")
        chunks = []
        if self._tx_pending:
            self._write_tx()
            chunks = [(t, len(d)) for t, d in self._tx_pending if d]
            self._tx_pending.clear()
            self._tx_written = 0
        frames = []
        for seq, capture_us, rgb in self._frames_pending:
            if rgb is None:  # the host had its camera off: the frame slot passes, no pixels
                frames.append(FrameBlob(seq=seq, capture_us=capture_us, arrival_us=start,
                                        width=0, height=0, channels=0, pixels=b""))
                continue
            h, w, c = rgb.shape
            frames.append(FrameBlob(seq=seq, capture_us=capture_us, arrival_us=start,
                                    width=w, height=h, channels=c, pixels=_pixels(rgb)))
        self._frames_pending.clear()
        self.granted_until_us = start + self.config.quantum_us
        return Grant(start_us=start, until_us=self.granted_until_us,
                     uart=tuple(chunks), frames=tuple(frames))

    def complete(self, done: Done) -> None:
        """Finish the quantum: deliver the host's bytes at their times, advance everything."""
        until = self.now_us + self.config.quantum_us
        if done.until_us != until:
            raise ValueError(f"DONE for until_us={done.until_us}, expected {until}")
        # The host says whether it will look at frames (its task needs a detector): rendering
        # is skipped while it does not, as a CAMIF switched off would deliver nothing.
        self.camera_on = bool(done.load.get("camera", True))
        if done.writes:  # most quanta the host writes nothing: nothing to read or deliver
            self._deliver_host_bytes(done, until)
        self._advance_to(until)
        self.stats["quanta"] += 1
        self._write_tx()

    def _deliver_host_bytes(self, done: Done, until: int) -> None:
        # (reading none would be a no-op: in strict alternation nothing is ever left ahead)
        data = self._read_exact(done.write_bytes)
        self.stats["uart_to_mcu_bytes"] += len(data)
        offset = 0
        for send_us, n in done.writes:
            if not self.now_us <= send_us < until:
                raise ValueError(f"host chunk sent at {send_us} us outside its quantum "
                                 f"[{self.now_us}, {until})")
            start = max(send_us, self._line_free_us)
            self.mcu.uart_rx(data[offset:offset + n], start)
            self._line_free_us = start + byte_time_us(n, self.config.host_baud)
            offset += n

    def _write_tx(self) -> None:
        # The MCU's bytes go on the port as soon as the quantum that produced them is done, not
        # when the grant that announces them is issued (later, after the next DONE was waited
        # for): the pty's line discipline has passed them on by the time the host reads them.
        # The host reads only what a grant announces and keeps the rest for the next grants.
        pending = self._tx_pending
        if self._tx_written < len(pending):
            data = b"".join(d for _, d in pending[self._tx_written:])
            self._tx_written = len(pending)
            if data:
                self.port.write(data)
                self.stats["uart_to_host_bytes"] += len(data)

    def _read_exact(self, n: int) -> bytes:
        # With grants ahead (host_lag_quanta >= 1) the host may already have written the bytes of
        # the next quantum: they wait in _rx_ahead for its DONE.
        buf = self._rx_ahead
        while len(buf) < n:
            chunk = self.port.read()
            if chunk:
                buf += chunk
                continue
            if not self.port.wait_readable(self.config.read_timeout_s):
                raise RigPortError(f"host announced {n} bytes, only {len(buf)} arrived within "
                                   f"{self.config.read_timeout_s} s")
        if len(buf) > n and self.config.host_lag_quanta == 0:
            # In strict alternation the host never writes ahead of its DONE; more bytes mean the
            # accounting broke.
            raise RigPortError(f"host announced {n} bytes but {len(buf)} were on the port")
        data = bytes(buf[:n])
        del buf[:n]
        return data

    def _advance_to(self, until: int) -> None:
        step = self.config.couple_us
        capture_time_us = self.config.capture_time_us
        couple = self._couple
        t = self.now_us
        cap = capture_time_us(self._next_frame)  # changes only when a frame is captured
        if cap <= t:  # frame 0 at t = 0
            self._capture(t)
            cap = capture_time_us(self._next_frame)
        while t < until:
            nxt = t - t % step + step
            if nxt > until:
                nxt = until
            if t < cap <= nxt:
                nxt = cap
            couple(nxt)
            t = nxt
            if t == cap:
                self._capture(t)
                cap = capture_time_us(self._next_frame)

    def _couple(self, t_us: int) -> None:
        advance_outputs, tx_take, set_servo, set_wheels, step_to = self._couple_calls
        now, duty = advance_outputs(t_us)
        if now != self._pulses_seen:  # the same six values: every one was sent already
            self._pulses_seen = now
            pulses = self._pulses
            for ch in range(6):
                pulse = now[ch]
                if pulse and pulse != pulses[ch]:  # 0/None before the first complete pulse
                    set_servo(ch, pulse)
                    pulses[ch] = pulse
        if duty != self._duty_sent:
            self._duty_sent = duty
            set_wheels(duty[0], duty[1])
        step_to(t_us)
        self.now_us = t_us
        for read, give in self._coupled_sensors:
            give(*read(), t_us)
        tx = tx_take()
        if tx:
            self._tx_pending.extend(tx)

    def _capture(self, t_us: int) -> None:
        seq = self._next_frame
        self._next_frame += 1
        if not self.camera_on:
            self.stats["frames_skipped"] += 1
            self._frames_pending.append((seq, t_us, None))
            return
        rgb = self.plant.capture(t_us)
        if rgb is None:
            return
        self.stats["frames_captured"] += 1
        self._frames_pending.append((seq, t_us, rgb))
        if self._on_frame is not None:
            self._on_frame(seq, t_us, rgb)
