"""``pty://``: a new pseudo-terminal; this process holds the master, a peer opens ``slave_path``.

The MCU emulation opens the master and prints the slave path (``/dev/pts/N``); the host opens that
path with pyserial exactly as it would open ``/dev/ttyS1`` on the board. The line is put in raw
mode at once (no echo, no CR/LF translation, 8 bits). Baud rate means nothing on a pty: line
timing comes from the simulated UART, never from the OS.

Linux reports EIO on the master while no process holds the slave open. This end therefore keeps
its own slave descriptor open until the first byte from the peer arrives (so nothing fails before
the peer has connected) and then closes it, after which EIO means "the peer vanished" and read()
raises LinkClosed. Bytes written before the peer opens the slave may be discarded by the peer's
open (pyserial flushes its input on open): peers should greet first, as HELLO does.

``pty://?drop_unread=1`` (``PtyTransport(drop_unread=True)``): while no peer has spoken, a write
that finds the pty buffer full (about 20 KB) flushes the unread old bytes instead of waiting
(counted in ``unread_flushes``), as a UART with nobody listening loses its bytes; an emulated MCU
that sends telemetry before any host connects then never stalls. Off by default, because a peer
that only reads would silently lose data.
"""

from __future__ import annotations

import errno
import os
import select
import termios
import tty

from mobigrasp.link.base import LinkClosed, Transport

_READ_CHUNK = 4096
_WRITE_WAIT_S = 60.0  # generous: a full pty buffer only stays full if the peer stopped reading


def set_raw(fd: int) -> None:
    """Raw 8-bit mode; tolerant of descriptors that refuse some termios calls."""
    try:
        tty.setraw(fd, termios.TCSANOW)
    except termios.error:
        pass


class PtyTransport(Transport):
    """Master end of a fresh pty; ``slave_path`` is what the peer opens."""

    def __init__(self, drop_unread: bool = False) -> None:
        self.drop_unread = bool(drop_unread)
        self._master, slave = os.openpty()
        self._slave: int | None = slave
        set_raw(slave)
        set_raw(self._master)
        os.set_blocking(self._master, False)
        self.slave_path = os.ttyname(slave)
        self.url = f"pty://{self.slave_path}"
        self.unread_flushes = 0
        self._closed = False

    def fileno(self) -> int | None:
        """The master descriptor."""
        return self._master

    def _check_open(self) -> None:
        if self._closed:
            raise LinkClosed(f"{self.url}: closed")

    def _release_slave(self) -> None:
        if self._slave is not None:
            os.close(self._slave)
            self._slave = None

    def read(self) -> bytes:
        """Available bytes from the peer (b"" if none); LinkClosed once the peer closed."""
        self._check_open()
        try:
            data = os.read(self._master, _READ_CHUNK)
        except BlockingIOError:
            return b""
        except OSError as exc:
            if exc.errno == errno.EIO:
                if self._slave is not None:  # no peer has spoken yet: EIO cannot happen then
                    return b""
                raise LinkClosed(f"{self.url}: the peer closed the pty slave") from exc
            raise LinkClosed(f"{self.url}: read failed: {exc}") from exc
        if not data:
            raise LinkClosed(f"{self.url}: end of file on the pty master")
        self._release_slave()
        return data

    def write(self, data: bytes) -> None:
        """Write all of ``data``, waiting while the pty buffer is full."""
        self._check_open()
        view = memoryview(bytes(data))
        while view:
            try:
                n = os.write(self._master, view)
            except BlockingIOError:
                if self.drop_unread and self._slave is not None and self._flush_unread():
                    continue
                _, writable, _ = select.select([], [self._master], [], _WRITE_WAIT_S)
                if not writable:
                    raise LinkClosed(
                        f"{self.url}: peer has not read for {_WRITE_WAIT_S:.0f} s"
                    ) from None
                continue
            except OSError as exc:
                raise LinkClosed(f"{self.url}: write failed: {exc}") from exc
            view = view[n:]

    def _flush_unread(self) -> bool:
        """Drop what sits unread on the way to the slave; True if that made room."""
        termios.tcflush(self._slave, termios.TCIFLUSH)
        self.unread_flushes += 1
        _, writable, _ = select.select([], [self._master], [], 0)
        return bool(writable)

    def wait_readable(self, timeout_s: float) -> bool:
        """select() on the master."""
        self._check_open()
        readable, _, _ = select.select([self._master], [], [], max(0.0, timeout_s))
        return bool(readable)

    def close(self) -> None:
        """Close master (and the slave copy if still held); the peer then sees EOF/EIO."""
        if self._closed:
            return
        self._closed = True
        self._release_slave()
        os.close(self._master)
