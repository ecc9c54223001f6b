"""A host program the rig does not run: whatever opened the pty slave, in wall time.

The rig (cosim/rig.py) asks its host for a DONE per quantum listing the bytes it wrote. A
program on the far end of a pty tells nothing: :class:`ExternalHost` answers for it. At each
grant it reads what the program has written to the pty so far and reports it as written at the
quantum's start; the rig then puts those bytes on the MCU's RX line at that time, serialised at
the line's baud rate. The MCU's bytes go to the pty as the rig writes them (never blocking: a
program that does not read loses them, counted in ``dropped_to_host_bytes``), and the grant's
camera frames go to ``on_frame`` (the MJPEG server). Simulated time stays the rig's: pacing to
the wall clock is the caller's policy; a program that writes more often than once per quantum
is seen at quantum resolution (5 ms), as a UART polled once per quantum would see it.

The program's bytes cross a 115 200-baud line: what it writes faster than the line carries
waits in a buffer of :data:`HOST_BUFFER_BYTES` (a tty's), and what does not fit is dropped and
counted (``dropped_from_host_bytes``), so a flood reaches neither the MCU nor the trace beyond
what the line could carry.

Both directions are decoded into events for the run's trace (``{"ev": "wire", "dir": "to_mcu" |
"to_host", "t_us", "seq", "msg", "fields"}``), so the trace holds the program's traffic.
"""

from __future__ import annotations

import dataclasses
import errno
import os
from collections.abc import Callable
from typing import Any

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.handshake import HostTraffic
from mobigrasp.cosim.rig import BITS_PER_BYTE, HOST_BAUD, byte_time_us
from mobigrasp.link.base import LinkClosed
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.protocol.messages import MessageError, decode_frame

HOST_BUFFER_BYTES = 4096  # the program's bytes waiting for the line (Linux's tty buffer)


def _jsonable(value: Any) -> Any:
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    return value


def wire_event(direction: str, t_us: int, frame) -> dict:
    """One decoded frame as a trace event (an undecodable payload keeps its type number)."""
    ev: dict = {"ev": "wire", "dir": direction, "t_us": int(t_us), "seq": frame.seq}
    try:
        msg = decode_frame(frame)
    except MessageError as exc:
        ev.update(msg_type=frame.msg_type, error=str(exc))
        return ev
    ev["msg"] = type(msg).__name__
    ev["fields"] = {f.name: _jsonable(getattr(msg, f.name)) for f in dataclasses.fields(msg)}
    return ev


class _RigPort:
    """The rig's end of the serial line: writes go to the pty master, reads give what
    :class:`ExternalHost` announced in its last DONE."""

    def __init__(self, owner: ExternalHost) -> None:
        self._owner = owner

    def write(self, data: bytes) -> None:
        self._owner.write_to_host(data)

    def read(self) -> bytes:
        return self._owner.take_from_host()

    def wait_readable(self, timeout_s: float) -> bool:
        return self._owner.from_host_pending()


class ExternalHost:
    """The host side of a rig whose host is a program on ``transport`` (a ``pty://`` master).

    Give :attr:`port` to the Rig as its serial port and this object to the session loop as its
    host (a :class:`~mobigrasp.cosim.handshake.HostEnd`)."""

    def __init__(self, transport: Any, on_frame: Callable[[Any, int], None] | None = None,
                 trace_wire: bool = True, hold_to_host: bool = False) -> None:
        """``hold_to_host``: keep the MCU's bytes until :meth:`release_to_host` instead of
        writing them to the pty as the rig sends them (a caller that hands time over in steps
        writes each step's bytes at once: a program reading several small writes right after
        them may see only the first ones, the pty handing them over in the background)."""
        self.transport = transport
        self.port = _RigPort(self)
        self.on_frame = on_frame
        self.trace_wire = trace_wire
        self.host_closed = False
        self.host_spoke = False
        self.bytes_from_host = 0
        self.bytes_to_host = 0
        self.dropped_to_host_bytes = 0
        self.dropped_from_host_bytes = 0  # beyond what the line and its buffer carry
        self.frames_out = 0
        self._line_free_us = 0  # when the line has sent every byte accepted so far
        self._from_host = bytearray()  # read from the pty, announced, not taken by the rig yet
        self._written = bytearray()  # written to the pty, not yet announced by a grant
        self._early = bytearray()  # read while waiting for the program: sent at the first grant
        self.hold_to_host = hold_to_host
        self._held = bytearray()  # the MCU's bytes kept for release_to_host
        self._rx_parser = FrameParser()  # host -> MCU
        self._tx_parser = FrameParser()  # MCU -> host

    # -- the rig's port ------------------------------------------------------------------------
    def write_to_host(self, data: bytes) -> None:
        """The MCU's bytes onto the pty now (never blocking), kept for the next grant's
        decoding."""
        self._written += data
        if self.host_closed:
            return
        if self.hold_to_host:
            self._held += data
            return
        self._write_pty(data)

    def release_to_host(self) -> None:
        """Write the bytes held (``hold_to_host``) to the pty in one write."""
        data = bytes(self._held)
        self._held.clear()
        if data and not self.host_closed:
            self._write_pty(data)

    def _write_pty(self, data: bytes) -> None:
        fd = self.transport.fileno()
        view = memoryview(bytes(data))
        while view:
            try:
                n = os.write(fd, view)
            except BlockingIOError:  # the program does not read: the bytes are lost
                self.dropped_to_host_bytes += len(view)
                return
            except OSError as exc:
                if exc.errno == errno.EIO:
                    return  # nobody holds the slave (yet, or any more)
                raise
            self.bytes_to_host += n
            view = view[n:]

    def take_from_host(self) -> bytes:
        """The program's bytes announced in the last DONE, for the rig to read."""
        data = bytes(self._from_host)
        self._from_host.clear()
        return data

    def from_host_pending(self) -> bool:
        """Whether announced bytes wait for the rig."""
        return bool(self._from_host)

    # -- the session's host --------------------------------------------------------------------
    def _read_pty(self) -> bytes:
        if self.host_closed:
            return b""
        chunks = []
        try:
            while True:
                data = self.transport.read()
                if not data:
                    break
                chunks.append(data)
        except LinkClosed:
            self.host_closed = True
        data = b"".join(chunks)
        if data:
            self.host_spoke = True
            self.bytes_from_host += len(data)
        return data

    def wait_for_host(self, stop: Callable[[], str | None] | None = None,
                      poll_s: float = 0.2) -> str | None:
        """Block (wall clock) until the program has written a valid frame; what it wrote
        meanwhile goes to the MCU at the next grant's start. ``stop()``'s reason, or
        ``host_closed``, if the wait ended without one."""
        parser = FrameParser()
        while not self.host_closed:
            if stop is not None and (why := stop()):
                return why
            if self.transport.wait_readable(poll_s):
                data = self._read_pty()
                self._early += data
                if parser.feed(data):
                    return None
        return "host_closed"

    def exchange(self, grant: ls.Grant) -> ls.Done:
        """The DONE for ``grant``: what the program wrote since the last one, at its start."""
        events: list[dict] = []
        for blob in grant.frames:
            if blob.width and self.on_frame is not None:
                import numpy as np

                rgb = np.frombuffer(blob.pixels, np.uint8).reshape(
                    blob.height, blob.width, blob.channels).copy()
                self.on_frame(rgb, blob.capture_us)
                self.frames_out += 1
        for t_us, n in grant.uart:
            data = bytes(self._written[:n])
            del self._written[:n]
            if self.trace_wire:
                events += [wire_event("to_host", t_us, f) for f in self._tx_parser.feed(data)]
        data = self._read_pty()
        if self._early:
            data = bytes(self._early) + data
            self._early.clear()
        data = self._line_carries(data, grant.start_us)
        writes: tuple = ()
        if data:
            self._from_host += data
            writes = ((grant.start_us, len(data)),)
            if self.trace_wire:
                events += [wire_event("to_mcu", grant.start_us, f)
                           for f in self._rx_parser.feed(data)]
        return ls.Done(until_us=grant.until_us, writes=writes, events=tuple(events),
                       load={"camera": True, "state": "EXTERNAL", "finished": False})

    def _line_carries(self, data: bytes, start_us: int) -> bytes:
        """The part of ``data`` (written by the program at ``start_us``) that fits in the
        line's buffer behind the bytes still queued; the rest is dropped and counted."""
        if not data:
            return data
        free_us = max(self._line_free_us, start_us)
        queued = (free_us - start_us) * HOST_BAUD // (BITS_PER_BYTE * 1_000_000)
        room = max(0, HOST_BUFFER_BYTES - queued)
        if len(data) > room:
            self.dropped_from_host_bytes += len(data) - room
            data = data[:room]
        self._line_free_us = free_us + byte_time_us(len(data))
        return data

    def submit(self, grant: ls.Grant) -> ls.Done:
        """:meth:`exchange`: the grant is served at once (no pipelining)."""
        return self.exchange(grant)

    def early_wanted(self, start_us: int) -> bool:
        """Every early grant: an external host is answered at once."""
        return True

    def traffic(self) -> HostTraffic:
        """No lockstep channel to count."""
        return HostTraffic()

    def finish(self, end: ls.End) -> ls.Bye:
        """End of the run: the line's counters as the host's stats."""
        return ls.Bye(stats=self.stats())

    def stats(self) -> dict:
        """Bytes both ways, drops, frames handed to the camera server, parser counters."""
        return {"bytes_from_host": self.bytes_from_host, "bytes_to_host": self.bytes_to_host,
                "dropped_to_host_bytes": self.dropped_to_host_bytes,
                "dropped_from_host_bytes": self.dropped_from_host_bytes,
                "frames_to_camera": self.frames_out,
                "host_parser": self._rx_parser.stats.as_dict(), "host_closed": self.host_closed}

    def close(self) -> None:
        """Close the pty master (the program then sees EOF/EIO)."""
        self.transport.close()
