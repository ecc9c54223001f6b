"""The byte transport interface every link backend implements (pty, pyserial port, in-process).

A Transport moves bytes, never messages: framing and decoding happen above it in
``link.messages.Link``. ``read()`` never blocks; waiting is explicit through ``wait_readable`` so
callers (the rig, the host loop, tests) decide how long they are prepared to wait.
"""

from __future__ import annotations

from abc import ABC, abstractmethod


class LinkClosed(Exception):
    """The transport is closed, or the other end vanished (EIO on a pty, serial exception...)."""


class Transport(ABC):
    """A bidirectional byte pipe chosen by URL (see ``mobigrasp.link.registry.open_transport``)."""

    url: str = ""

    @abstractmethod
    def write(self, data: bytes) -> None:
        """Send all of ``data`` (may wait while the OS buffer is full); LinkClosed if gone."""

    @abstractmethod
    def read(self) -> bytes:
        """Bytes received so far, b"" when there are none; never blocks; LinkClosed if gone."""

    @abstractmethod
    def wait_readable(self, timeout_s: float) -> bool:
        """Wait up to ``timeout_s`` seconds for data (or for the peer to vanish); True if
        ``read()`` now has something to report (data, or a LinkClosed to raise)."""

    def fileno(self) -> int | None:
        """A descriptor usable with select/poll, or None when the backend has none."""
        return None

    @abstractmethod
    def close(self) -> None:
        """Release the transport; idempotent. Later read/write raise LinkClosed."""

    @property
    def closed(self) -> bool:
        """True once ``close()`` was called."""
        return getattr(self, "_closed", False)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.url!r}{' closed' if self.closed else ''}>"
