"""Host side of the lockstep channel: a Clock and a Camera fed by GRANTs, and the serve loop.

docs/cosim.md. For each GRANT the client reads exactly the announced number of UART bytes from the
serial port (blocking, with a generous safety timeout and no sleeps), hands each chunk to the host
program with its modelled arrival time, queues the granted frames on the :class:`LockstepCamera`,
runs the host program up to ``until_us`` and never beyond, writes what it sent to the port and
answers DONE with the chunks' send times and the trace events of the quantum.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.frame_ring import FrameRingReader
from mobigrasp.host.app import HostApp, jsonable
from mobigrasp.host.hal import Camera, CameraFrame, Clock


class LockstepClock(Clock):
    """The host's time: the start of the current grant, then its end once served."""

    def __init__(self) -> None:
        self._now_us = 0

    def now_us(self) -> int:
        """Current simulated time in microseconds."""
        return self._now_us

    def set_us(self, t_us: int) -> None:
        """Move to ``t_us`` (granted by the rig); never backwards."""
        if t_us < self._now_us:
            raise ValueError(f"lockstep clock cannot go back from {self._now_us} to {t_us}")
        self._now_us = t_us


class LockstepCamera(Camera):
    """Frames that crossed the lockstep channel, as the CAMIF would hand them over."""

    def __init__(self) -> None:
        self._queue: list[tuple[int, CameraFrame]] = []

    def push(self, blob: ls.FrameBlob) -> None:
        """Queue one frame of a GRANT (pixels copied into a uint8 H x W x C array; None for
        a frame slot that passed while the host had the camera off)."""
        if not blob.pixels:
            self._queue.append((blob.arrival_us, CameraFrame(blob.seq, blob.capture_us, None)))
            return
        rgb = np.frombuffer(blob.pixels, dtype=np.uint8).reshape(
            blob.height, blob.width, blob.channels)
        self._queue.append((blob.arrival_us, CameraFrame(blob.seq, blob.capture_us, rgb)))

    def poll(self) -> CameraFrame | None:
        """The oldest frame not yet returned, or None."""
        return self._queue.pop(0)[1] if self._queue else None

    def close(self) -> None:
        """Drop the frames not polled (the frame ring is the client's to close)."""
        self._queue.clear()

    def poll_with_arrival(self) -> tuple[int, CameraFrame] | None:
        """Like :meth:`poll`, with the simulated arrival time of the frame."""
        return self._queue.pop(0) if self._queue else None


class AnnouncedBytes:
    """The UART bytes of the granted quanta, read from the serial ``port`` as each GRANT
    announces them (any host program's driver: this module's client, the C host's in process)."""

    def __init__(self, port, read_timeout_s: float = 60.0) -> None:
        self.port = port
        self.read_timeout_s = read_timeout_s
        self._ahead = bytearray()  # UART bytes read for grants not served yet

    def take(self, n: int) -> bytes:
        """The next ``n`` bytes. The rig may send grants ahead (pipelining): bytes beyond this
        grant's belong to the next ones and wait in ``_ahead``."""
        buf = self._ahead
        while len(buf) < n:
            chunk = self.port.read()
            if chunk:
                buf += chunk
            elif not self.port.wait_readable(self.read_timeout_s):
                raise ls.LockstepError(f"grant announced {n} UART bytes, only {len(buf)} "
                                       f"arrived within {self.read_timeout_s} s")
        data = bytes(buf[:n])
        del buf[:n]
        return data


class LockstepClient:
    """Serves GRANTs for one :class:`HostApp` over a serial ``port`` (link Transport)."""

    def __init__(self, app: HostApp, port, read_timeout_s: float = 60.0) -> None:
        self.app = app
        self.port = port
        self.clock = LockstepClock()
        self.camera = LockstepCamera()
        self.uart = AnnouncedBytes(port, read_timeout_s)
        self._loads_sent = 0

    def serve(self, grant: ls.Grant) -> ls.Done:
        """Run the host program through one granted quantum; returns the DONE to send."""
        app = self.app
        # a frame's detectors still pending need not run before these bytes are fed: the ones
        # that read the arm pose took it when their frame arrived (HostApp, pose snapshot)
        until_us = grant.until_us
        self.clock.set_us(grant.start_us)
        if grant.uart:  # (most grants bring bytes; a quiet one reads nothing)
            data = self.uart.take(grant.uart_bytes)
            offset = 0
            for arrival_us, n in grant.uart:
                app.on_uart(data[offset:offset + n], arrival_us)
                offset += n
        if grant.frames:  # the camera queue is drained below, so it is empty without frames
            for blob in grant.frames:
                self.camera.push(blob)
            while (item := self.camera.poll_with_arrival()) is not None:
                arrival_us, frame = item
                app.on_frame(frame.seq, frame.capture_us, arrival_us, frame.rgb)
        app.advance_to(until_us)
        out = app.take_output(until_us)
        writes: tuple[tuple[int, int], ...] = ()
        if out:
            self.port.write(b"".join(w for _, w in out))
            writes = tuple((t, len(w)) for t, w in out)
        self.clock.set_us(until_us)
        new = {}
        if until_us // app.config.load_window_us > self._loads_sent:
            # a window may have finished (load_windows holds only windows before now)
            loads = app.load_windows()
            new = {str(k): round(v, 6) for k, v in loads.items() if k >= self._loads_sent}
            if new:
                self._loads_sent = max(loads) + 1
        # plain JSON data already (HostApp.take_events): not walked through jsonable again
        events = app.take_events()
        return ls.Done(until_us=until_us, writes=writes, events=tuple(events),
                       load={"window_us": app.config.load_window_us, "windows": new,
                             "state": app.state, "finished": app.finished,
                             "camera": app.wants_frames(),
                             "quiet_until": app.quiet_until_us()})

    def after_done(self) -> None:
        """Work the DONE just sent did not need (a frame's detectors): done now, while the rig
        simulates. (The pose snapshot and the bounds of HostApp.vision_needed_by would allow
        waiting until after the next control tick's DONE; measured, that only moved the rig's
        wait to the following tick.)"""
        self.app.resolve_vision()

    def bye(self) -> ls.Bye:
        """Final statistics of the host program."""
        return ls.Bye(stats=jsonable(self.app.stats()))


def serve_stream(client: LockstepClient, rfile: ls.SocketReader, wfile: Any,
                 host_id: str = "host", frame_source: Any = None) -> str:
    """Serve a whole run over the Unix socket (``rfile`` reads it, ``wfile`` writes it); returns
    the END reason. ``frame_source`` reads frames the rig sent out of band
    (cosim/frame_ring.FrameRingReader)."""
    wfile.write(ls.encode(ls.Hello(host_id=host_id)))
    wfile.flush()
    out = bytearray()
    while True:
        msg = ls.read_message(rfile, frame_source)
        if isinstance(msg, ls.Grant):
            out += ls.encode(client.serve(msg))
        elif isinstance(msg, ls.End):
            wfile.write(out + ls.encode(client.bye()))
            wfile.flush()
            return msg.reason
        else:
            raise ls.LockstepError(f"host expected GRANT or END, got {type(msg).__name__}")
        if rfile.buffered:
            continue  # more of a batch the rig sent in one write: its DONEs leave together
        wfile.write(out)
        wfile.flush()
        out.clear()
        client.after_done()


def serve_socket(client: LockstepClient, sock: Any, poll_s: float = 0.0) -> str:
    """Serve the rig on the connected Unix socket ``sock`` until it ends the run; its END
    reason. ``poll_s``: poll the socket that long before sleeping (docs/cosim.md, "Busy
    polling"). LinkClosed or OSError when the rig or its pty went away (``client.clock`` says
    how far it got)."""
    frames = FrameRingReader()
    try:
        return serve_stream(client, ls.SocketReader(sock, poll_s=poll_s), sock.makefile("wb"),
                            host_id="mobigrasp-host", frame_source=frames)
    finally:
        frames.close()
