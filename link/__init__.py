"""Serial links by URL: byte transports (pty, pyserial port, in-process pair) and messages on top.

``open_transport(url)`` picks the backend (``pty://``, ``inproc://NAME``, ``/dev/pts/N``,
``loop://``...); ``Link(transport)`` sends and polls protocol messages over it.
"""

from mobigrasp.link.base import LinkClosed, Transport
from mobigrasp.link.inproc import InprocTransport, inproc_pair
from mobigrasp.link.messages import Link, Received
from mobigrasp.link.pty_transport import PtyTransport
from mobigrasp.link.registry import list_backends, open_transport, register_backend
from mobigrasp.link.serial_transport import FdTransport, SerialTransport

__all__ = [
    "FdTransport", "InprocTransport", "Link", "LinkClosed", "PtyTransport", "Received",
    "SerialTransport", "Transport", "inproc_pair", "list_backends", "open_transport",
    "register_backend",
]
