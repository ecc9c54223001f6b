"""Any pyserial port or URL as a Transport: ``/dev/pts/N``, ``/dev/ttyUSB0``, ``loop://``, ``spy://``.

Ptys differ from UARTs (pyserial#59, #133): they may refuse the DTR/RTS modem-control ioctls and
ignore the baud rate. The port is therefore created closed (``do_not_open``), hardware flow
control is switched off, and only then opened; if pyserial still fails on a termios/ioctl call
(EINVAL, ENOTTY), a plain raw-mode descriptor is used instead (``FdTransport``).
"""

from __future__ import annotations

import errno
import os
import select
import termios

import serial

from mobigrasp.link.base import LinkClosed, Transport
from mobigrasp.link.pty_transport import set_raw

DEFAULT_BAUD = 115_200
_IOCTL_ERRNOS = (errno.EINVAL, errno.ENOTTY)
_READ_CHUNK = 4096


class SerialTransport(Transport):
    """A pyserial ``Serial`` (from ``serial_for_url``) in non-blocking mode."""

    def __init__(self, url: str, baudrate: int = DEFAULT_BAUD) -> None:
        self.url = url
        self._closed = False
        self._pushback = b""
        ser = serial.serial_for_url(url, do_not_open=True)
        ser.baudrate = baudrate
        ser.bytesize = serial.EIGHTBITS
        ser.parity = serial.PARITY_NONE
        ser.stopbits = serial.STOPBITS_ONE
        ser.rtscts = False
        ser.dsrdtr = False
        ser.xonxoff = False
        ser.timeout = 0
        ser.write_timeout = 60.0
        ser.open()
        self._ser = ser
        self._fd = self._probe_fileno()

    def fileno(self) -> int | None:
        """The OS descriptor of device ports; None for pure-Python URLs such as loop://."""
        return self._fd

    def _probe_fileno(self) -> int | None:
        try:
            return self._ser.fileno()
        except (AttributeError, NotImplementedError, OSError, ValueError, serial.SerialException):
            return None

    def _check_open(self) -> None:
        if self._closed:
            raise LinkClosed(f"{self.url}: closed")

    def read(self) -> bytes:
        """Available bytes, b"" if none; LinkClosed when the device vanished."""
        self._check_open()
        try:
            waiting = self._ser.in_waiting
            data = self._ser.read(waiting or _READ_CHUNK)
        except (serial.SerialException, OSError, termios.error) as exc:
            raise LinkClosed(f"{self.url}: {exc}") from exc
        if self._pushback:
            data, self._pushback = self._pushback + data, b""
        return bytes(data)

    def write(self, data: bytes) -> None:
        """Write all of ``data``."""
        self._check_open()
        try:
            self._ser.write(bytes(data))
        except (serial.SerialException, OSError, termios.error) as exc:
            raise LinkClosed(f"{self.url}: {exc}") from exc

    def wait_readable(self, timeout_s: float) -> bool:
        """select() on the descriptor, or a blocking 1-byte read for descriptor-less URLs."""
        self._check_open()
        if self._pushback:
            return True
        fd = self.fileno()
        if fd is not None:
            readable, _, _ = select.select([fd], [], [], max(0.0, timeout_s))
            return bool(readable)
        try:
            if self._ser.in_waiting:
                return True
            self._ser.timeout = max(0.0, timeout_s)
            self._pushback = self._ser.read(1)
        except (serial.SerialException, OSError) as exc:
            raise LinkClosed(f"{self.url}: {exc}") from exc
        finally:
            self._ser.timeout = 0
        return bool(self._pushback)

    def close(self) -> None:
        """Close the port."""
        if not self._closed:
            self._closed = True
            self._ser.close()


class FdTransport(Transport):
    """A tty path opened directly (raw mode, non-blocking): the fallback when pyserial refuses
    a pseudo-terminal's ioctls."""

    def __init__(self, path: str) -> None:
        self.url = path
        self._closed = False
        self._fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        set_raw(self._fd)

    def fileno(self) -> int | None:
        """The descriptor."""
        return self._fd

    def read(self) -> bytes:
        """Available bytes, b"" if none; LinkClosed on EOF/EIO."""
        if self._closed:
            raise LinkClosed(f"{self.url}: closed")
        try:
            data = os.read(self._fd, _READ_CHUNK)
        except BlockingIOError:
            return b""
        except OSError as exc:
            raise LinkClosed(f"{self.url}: {exc}") from exc
        if not data:
            raise LinkClosed(f"{self.url}: end of file")
        return data

    def write(self, data: bytes) -> None:
        """Write all of ``data``, waiting while the buffer is full."""
        if self._closed:
            raise LinkClosed(f"{self.url}: closed")
        view = memoryview(bytes(data))
        while view:
            try:
                view = view[os.write(self._fd, view):]
            except BlockingIOError:
                if not select.select([], [self._fd], [], 60.0)[1]:
                    raise LinkClosed(f"{self.url}: peer has not read for 60 s") from None
            except OSError as exc:
                raise LinkClosed(f"{self.url}: {exc}") from exc

    def wait_readable(self, timeout_s: float) -> bool:
        """select() on the descriptor."""
        if self._closed:
            raise LinkClosed(f"{self.url}: closed")
        return bool(select.select([self._fd], [], [], max(0.0, timeout_s))[0])

    def close(self) -> None:
        """Close the descriptor."""
        if not self._closed:
            self._closed = True
            os.close(self._fd)


def open_serial(url: str, baudrate: int = DEFAULT_BAUD) -> Transport:
    """pyserial for ``url``; for a device path whose termios/ioctl setup fails, a raw descriptor."""
    try:
        return SerialTransport(url, baudrate)
    except (serial.SerialException, OSError, termios.error) as exc:
        code = getattr(exc, "errno", None)
        if code is None and isinstance(exc, termios.error) and exc.args:
            code = exc.args[0]
        if "://" not in url and os.path.exists(url) and code in _IOCTL_ERRNOS:
            return FdTransport(url)
        raise
