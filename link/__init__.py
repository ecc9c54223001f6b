"""Serial links by URL: byte transports (pty, pyserial port, in-process pair) and messages on top.

``open_transport(url)`` picks the backend (``pty://``, ``inproc://NAME``, ``/dev/pts/N``,
``loop://``...); ``Link(transport)`` sends and polls protocol messages over it.
"""

from link.base import LinkClosed, Transport
from link.inproc import InprocTransport, inproc_pair
from link.messages import Link, Received
from link.pty_transport import PtyTransport
from link.registry import list_backends, open_transport, register_backend
from link.serial_transport import FdTransport, SerialTransport

__all__ = [
    "FdTransport", "InprocTransport", "Link", "LinkClosed", "PtyTransport", "Received",
    "SerialTransport", "Transport", "inproc_pair", "list_backends", "open_transport",
    "register_backend",
]
