"""In-process transport: two connected ends sharing byte queues (threads or one thread).

The null backend of the transports (docs/protocol.md): no OS objects, deterministic, used by the
lockstep rig and unit tests. ``inproc_pair()`` returns both ends; ``inproc://NAME`` opens the
ends of a named pair, the first open gets end A, the second end B.
"""

from __future__ import annotations

import threading

from mobigrasp.link.base import LinkClosed, Transport


class _Pipe:
    def __init__(self, cond: threading.Condition) -> None:
        self.data = bytearray()
        self.cond = cond
        self.writer_closed = False


class InprocTransport(Transport):
    """One end of an in-process pair; bytes written here are read at the other end."""

    def __init__(self, url: str, rx: _Pipe, tx: _Pipe, cond: threading.Condition) -> None:
        self.url = url
        self._rx = rx
        self._tx = tx
        self._cond = cond
        self._closed = False

    def write(self, data: bytes) -> None:
        """Append ``data`` to the peer's receive queue."""
        with self._cond:
            if self._closed:
                raise LinkClosed(f"{self.url}: write on a closed transport")
            if self._rx.writer_closed:  # the peer closed its end: nobody will ever read this
                raise LinkClosed(f"{self.url}: the other end is closed")
            self._tx.data += data
            self._cond.notify_all()

    def read(self) -> bytes:
        """Everything queued for this end; after the peer closed, LinkClosed once drained."""
        with self._cond:
            if self._closed:
                raise LinkClosed(f"{self.url}: read on a closed transport")
            if self._rx.data:
                out = bytes(self._rx.data)
                self._rx.data.clear()
                return out
            if self._rx.writer_closed:
                raise LinkClosed(f"{self.url}: the other end is closed")
            return b""

    def wait_readable(self, timeout_s: float) -> bool:
        """Block until data arrives, the peer closes, or ``timeout_s`` passes."""
        with self._cond:
            return self._cond.wait_for(
                lambda: self._closed or bool(self._rx.data) or self._rx.writer_closed,
                timeout=max(0.0, timeout_s),
            )

    def close(self) -> None:
        """Close this end; the peer's reads raise LinkClosed once it has drained its queue."""
        with self._cond:
            if not self._closed:
                self._closed = True
                self._tx.writer_closed = True
                self._cond.notify_all()


def inproc_pair(name: str = "pair") -> tuple[InprocTransport, InprocTransport]:
    """Two connected in-process ends (A, B)."""
    cond = threading.Condition()
    a_to_b, b_to_a = _Pipe(cond), _Pipe(cond)
    a = InprocTransport(f"inproc://{name}#a", rx=b_to_a, tx=a_to_b, cond=cond)
    b = InprocTransport(f"inproc://{name}#b", rx=a_to_b, tx=b_to_a, cond=cond)
    return a, b


_named: dict[str, InprocTransport] = {}
_named_lock = threading.Lock()


def open_named(url: str) -> InprocTransport:
    """``inproc://NAME``: the first call creates the pair and returns end A, the second end B."""
    name = url[len("inproc://"):]
    if not name:
        raise ValueError(f"inproc URL needs a name, e.g. 'inproc://mcu', got {url!r}")
    with _named_lock:
        waiting = _named.pop(name, None)
        if waiting is not None:
            return waiting
        a, b = inproc_pair(name)
        _named[name] = b
        return a
