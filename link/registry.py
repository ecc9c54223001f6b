"""Open a byte transport by URL; backends are registered by scheme (as python-can's interfaces).

- ``pty://``         a new pseudo-terminal master (``.slave_path`` is what the peer opens);
                     ``pty://?drop_unread=1`` never blocks before a peer has spoken
- ``inproc://NAME``  one end of a named in-process pair (first open: end A, second: end B)
- anything else      pyserial: a device path (``/dev/pts/3``, ``/dev/ttyUSB0``, ``/dev/ttyS1``)
                     or a pyserial URL (``loop://``, ``spy://``, ``socket://``, ``rfc2217://``)
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable

import serial

from mobigrasp.link.base import Transport
from mobigrasp.link.inproc import inproc_pair, open_named
from mobigrasp.link.pty_transport import PtyTransport
from mobigrasp.link.serial_transport import open_serial

__all__ = ["inproc_pair", "list_backends", "open_transport", "register_backend"]

_BACKENDS: dict[str, Callable[[str], Transport]] = {}


def register_backend(scheme: str, factory: Callable[[str], Transport]) -> None:
    """Make ``open_transport("<scheme>://...")`` call ``factory(url)``."""
    if not scheme.isidentifier():
        raise ValueError(f"backend scheme must be an identifier, got {scheme!r}")
    _BACKENDS[scheme] = factory


def _open_pty(url: str) -> Transport:
    rest = url[len("pty://"):]
    path, _, query = rest.partition("?")
    if path:
        raise ValueError(f"pty URL takes no path (it creates a new pty): use 'pty://', got {url!r}")
    options = dict(part.partition("=")[::2] for part in query.split("&") if part)
    unknown = set(options) - {"drop_unread"}
    if unknown:
        raise ValueError(f"unknown pty URL option(s) {sorted(unknown)} in {url!r}; "
                         "known: drop_unread")
    drop = options.get("drop_unread", "0")
    if drop not in ("0", "1"):
        raise ValueError(f"pty URL option drop_unread must be 0 or 1, got {drop!r}")
    return PtyTransport(drop_unread=drop == "1")


register_backend("pty", _open_pty)
register_backend("inproc", open_named)


def _pyserial_schemes() -> list[str]:
    schemes = []
    for package in serial.protocol_handler_packages:
        for name in ("loop", "spy", "socket", "rfc2217", "alt", "hwgrep", "cp2110"):
            if importlib.util.find_spec(f"{package}.protocol_{name}") is not None:
                schemes.append(name)
    return schemes


def list_backends() -> list[str]:
    """Schemes ``open_transport`` understands; ``serial`` stands for a plain device path."""
    return sorted(set(_BACKENDS) | set(_pyserial_schemes())) + ["serial"]


def open_transport(url: str) -> Transport:
    """The Transport for ``url``; ValueError naming an unknown scheme."""
    if not isinstance(url, str) or not url:
        raise ValueError(f"transport URL must be a non-empty str, got {url!r}")
    if "://" in url:
        scheme = url.split("://", 1)[0]
        factory = _BACKENDS.get(scheme)
        if factory is not None:
            return factory(url)
        found = any(
            importlib.util.find_spec(f"{package}.protocol_{scheme}") is not None
            for package in serial.protocol_handler_packages
            if scheme.isidentifier()
        )
        if not found:
            raise ValueError(
                f"unknown transport scheme {scheme!r} in {url!r}; known: "
                + ", ".join(list_backends())
            )
    return open_serial(url)
