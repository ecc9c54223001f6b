"""The serial line of ``mobigrasp sim`` on TCP as well: 127.0.0.1:PORT relayed to the pty.

A host in a container or on another machine (through a tunnel) cannot open a pty; ArduPilot SITL,
Renode and PX4 offer their serial ports on TCP for that. :class:`TcpSerialBridge` accepts one
client at a time and relays its bytes both ways to the pty slave, which it opens while the client
is connected, as ``socat`` would: to the session the client is a program on the pty. When the
client disconnects the bridge closes the slave, so a session whose only host came over TCP sees
its host close the port. Two hosts at once (one on the pty, one on TCP) would share one line:
use one. Bound to 127.0.0.1 only.
"""

from __future__ import annotations

import errno
import os
import select
import socket
import threading

from mobigrasp.link.pty_transport import set_raw

HOST = "127.0.0.1"
_CHUNK = 4096


class TcpPortInUse(OSError):
    """The TCP port could not be bound."""


class TcpSerialBridge:
    """A listening socket on 127.0.0.1 relayed to ``slave_path`` (see the module docstring)."""

    def __init__(self, slave_path: str, port: int = 0) -> None:
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
            raise ValueError(f"--tcp-port must be an integer in [0, 65535], got {port!r}")
        self.slave_path = slave_path
        try:
            self._sock = socket.create_server((HOST, port))
        except OSError as exc:
            raise TcpPortInUse(f"--tcp-port {port}: cannot listen on {HOST}: "
                               f"{exc.strerror or exc}") from exc
        self.port: int = self._sock.getsockname()[1]
        self.url = f"tcp://{HOST}:{self.port}"
        self.clients = 0
        self.bytes_to_pty = 0
        self.bytes_to_client = 0
        self._stop_r, self._stop_w = os.pipe()
        self._thread = threading.Thread(target=self._serve, daemon=True, name="serial-tcp")
        self._thread.start()

    def _serve(self) -> None:
        while True:
            ready, _, _ = select.select([self._sock, self._stop_r], [], [])
            if self._stop_r in ready:
                return
            conn, _ = self._sock.accept()
            self.clients += 1
            with conn:
                if self._relay(conn):
                    return

    def _relay(self, conn: socket.socket) -> bool:
        """Relay until the client or the pty goes; True if the bridge was closed meanwhile."""
        fd = os.open(self.slave_path, os.O_RDWR | os.O_NOCTTY)
        try:
            set_raw(fd)  # no echo, no line editing: the bytes as they are
            while True:
                ready, _, _ = select.select([conn, fd, self._stop_r], [], [])
                if self._stop_r in ready:
                    return True
                if conn in ready:
                    data = conn.recv(_CHUNK)
                    if not data:
                        return False
                    os.write(fd, data)  # blocking: the session reads the pty every quantum
                    self.bytes_to_pty += len(data)
                if fd in ready:
                    try:
                        data = os.read(fd, _CHUNK)
                    except OSError as exc:
                        if exc.errno == errno.EIO:  # the session closed the pty
                            return False
                        raise
                    conn.sendall(data)
                    self.bytes_to_client += len(data)
        except (BrokenPipeError, ConnectionResetError):
            return False
        finally:
            os.close(fd)

    def stats(self) -> dict:
        """Clients served and bytes relayed each way."""
        return {"clients": self.clients, "bytes_to_pty": self.bytes_to_pty,
                "bytes_to_client": self.bytes_to_client}

    def close(self) -> None:
        """Stop listening and drop the client."""
        os.write(self._stop_w, b"x")
        self._thread.join(5.0)
        self._sock.close()
        os.close(self._stop_r)
        os.close(self._stop_w)
