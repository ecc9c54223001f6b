"""``python -m link.echo PORT``: open PORT, greet, and echo every valid frame back unchanged.

The second process of the link demo and of the two-process pty test. It first sends one LOG frame
("echo ready", seq 0) so the opener knows the slave is open (bytes written to a pty before the
peer opens it may be flushed by that open). Exits 0 when the other end closes.
"""

from __future__ import annotations

import sys

from mobigrasp.link.base import LinkClosed
from mobigrasp.link.registry import open_transport
from mobigrasp.protocol.frame import FrameParser, encode_frame
from mobigrasp.protocol.messages import Log, encode_message

READY_TEXT = "echo ready"


def serve(url: str) -> int:
    """Echo frames on ``url`` until the peer goes away; returns the number of frames echoed."""
    echoed = 0
    with open_transport(url) as transport:
        parser = FrameParser()
        transport.write(encode_message(Log(code=0, text=READY_TEXT), 0))
        try:
            while True:
                if not transport.wait_readable(1.0):
                    continue
                out = b"".join(encode_frame(f) for f in parser.feed(transport.read()))
                if out:
                    echoed += out.count(0)
                    transport.write(out)
        except LinkClosed:
            pass
    return echoed


def main(argv: list[str] | None = None) -> int:
    """Entry point: ``python -m mobigrasp.link.echo PORT``."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python -m mobigrasp.link.echo PORT", file=sys.stderr)
        return 2
    n = serve(args[0])
    print(f"echo: {n} frames echoed, peer closed", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
