"""``mobigrasp host --port PATH [--camera SOURCE] [--lockstep SOCKET]``: the S3C2440 program.

With ``--lockstep`` (started by ``mobigrasp run``) the host's time is granted by the rig over the
Unix socket and the bytes cross the pty in simulated time (docs/cosim.md). Without it, the host
drives whatever is on PORT (``mobigrasp mcu``'s pty, or a real ATmega128 on /dev/ttyUSB0) in wall
time, with frames from an OpenCV capture (``--camera 0`` or a video file); the host program is the
same object, only the driver loop below differs.
"""

from __future__ import annotations

import argparse
import json
import socket
import sys
import time
from pathlib import Path

METHODS = ("000", "001", "002")


def _config(args: argparse.Namespace) -> dict:
    cfg: dict = {}
    if args.config:
        cfg = json.loads(Path(args.config).read_text())
    if args.method:
        cfg["method"] = args.method
    cfg.setdefault("method", "000")
    if cfg["method"] not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {cfg['method']!r}")
    return cfg


def _lockstep(args: argparse.Namespace, cfg: dict) -> int:
    import cv2

    from mobigrasp.cosim import lockstep as ls
    from mobigrasp.cosim.frame_ring import FrameRingReader
    from mobigrasp.drivers.lockstep import LockstepClient, serve_stream
    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.link.base import LinkClosed
    from mobigrasp.link.registry import open_transport

    # one OpenCV thread: the machine's other core runs the rig, whose time this process waits
    # for; a pool would take it mid-frame (results are the same on any number of threads)
    cv2.setNumThreads(1)
    port = open_transport(args.port)
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(120.0)  # safety limit only; the rig answers at once
    sock.connect(args.lockstep)
    client = LockstepClient(build_host_app(cfg), port)
    frames = FrameRingReader()
    try:
        serve_stream(client, ls.SocketReader(sock, poll_s=args.poll_ms / 1000.0),
                     sock.makefile("wb"),
                     host_id="mobigrasp-host", frame_source=frames)
    except (LinkClosed, OSError) as exc:
        # the simulator died or closed the pty/socket mid-run (LockstepClosed is a
        # ConnectionError, an OSError): say so in one line and exit non-zero at once (issue 9)
        print(f"mobigrasp host: the simulator went away mid-run at t = "
              f"{client.clock.now_us() / 1e6:.3f} s simulated ({type(exc).__name__}: {exc}); "
              f"stopping", file=sys.stderr, flush=True)
        return 1
    finally:
        frames.close()
        sock.close()
        port.close()
    return 0


class _OpenCvCamera:
    """Frames from cv2.VideoCapture, stamped with wall time (free-running mode only)."""

    def __init__(self, source: str) -> None:
        import cv2

        self._cv2 = cv2
        self.cap = cv2.VideoCapture(int(source) if source.isdigit() else source)
        if not self.cap.isOpened():
            raise ValueError(f"cannot open camera source {source!r}")
        self.seq = 0

    def read(self):
        ok, bgr = self.cap.read()
        if not ok:
            return None
        rgb = self._cv2.resize(self._cv2.cvtColor(bgr, self._cv2.COLOR_BGR2RGB), (320, 240))
        self.seq += 1
        return self.seq - 1, rgb


def _free_running(args: argparse.Namespace, cfg: dict) -> int:
    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.link.base import LinkClosed
    from mobigrasp.link.registry import open_transport

    port = open_transport(args.port)
    app = build_host_app(cfg)
    camera = _OpenCvCamera(args.camera) if args.camera else None
    t0 = time.monotonic()
    next_frame = 0.0
    vanished = False
    print(f"host on {args.port} (method {cfg['method']}), Ctrl-C to stop", file=sys.stderr)
    try:
        while not app.finished:
            now_us = int((time.monotonic() - t0) * 1e6)
            data = port.read()
            if data:
                app.on_uart(data, now_us)
            if camera is not None and now_us >= next_frame:
                got = camera.read()
                if got is not None:
                    app.on_frame(got[0], now_us, now_us, got[1])
                next_frame = now_us + 1e6 / 15
            app.advance_to(now_us + 1)
            # the detectors now, between steps (the pose they read was taken with the frame;
            # in wall time there is no rig to keep waiting, so no reason to defer them)
            app.resolve_vision()
            out = app.take_output(now_us + 1)
            if out:
                port.write(b"".join(w for _, w in out))
            port.wait_readable(0.002)
    except LinkClosed:
        # the MCU (or its pty) vanished: a failure whatever the task's state (issue 9)
        print(f"mobigrasp host: the MCU side closed the port {args.port}; stopping",
              file=sys.stderr, flush=True)
        vanished = True
    except KeyboardInterrupt:
        print("host: interrupted", file=sys.stderr)
    finally:
        port.close()
    st = app.stats()
    print(f"host: state {st['state']}, control steps {st['control_steps']}, frames "
          f"{st['frames_processed']}/{st['frames_received']}, protocol "
          f"{json.dumps({k: v for k, v in st['protocol'].items() if k != 'parser'})}",
          file=sys.stderr)
    return 0 if app.state == "DONE" and not vanished else 1


def _run(args: argparse.Namespace) -> int:
    try:
        cfg = _config(args)
    except (OSError, ValueError) as exc:
        print(f"mobigrasp host: {exc}", file=sys.stderr)
        return 2
    from mobigrasp.cosim.heap_tuning import keep_freed_memory

    keep_freed_memory()  # frame-sized arrays are reused instead of faulted in again
    if args.lockstep:
        return _lockstep(args, cfg)
    return _free_running(args, cfg)


def _poll_ms(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 <= value <= 10_000.0:  # also refuses NaN
        raise argparse.ArgumentTypeError(f"must be a number of ms in [0, 10000], got {text!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``host`` subcommand."""
    p = sub.add_parser("host", help="run the S3C2440 host program on a serial port")
    p.add_argument("--port", required=True, help="serial port: /dev/pts/N, /dev/ttyUSB0, ...")
    p.add_argument("--camera", default=None,
                   help="OpenCV capture source (index or file) in free-running mode")
    p.add_argument("--lockstep", default=None, help="Unix socket of the rig (set by 'run')")
    p.add_argument("--poll-ms", type=_poll_ms, default=0.0,
                   help="with --lockstep: poll the socket up to this long before sleeping, so "
                        "the next grant finds the host running (set by 'run' at full speed)")
    p.add_argument("--config", default=None, help="host configuration JSON (method, params)")
    p.add_argument("--method", default=None, help="000, 001 or 002 (overrides --config)")
    p.set_defaults(func=_run)
