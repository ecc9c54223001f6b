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
        try:
            cfg = json.loads(Path(args.config).read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:  # missing, a folder, not UTF-8, not JSON
            raise ValueError(f"--config {args.config}: {exc}") from exc
        if not isinstance(cfg, dict):
            raise ValueError(f"--config {args.config}: expected a JSON object, got "
                             f"{type(cfg).__name__}")
    if args.method:
        cfg["method"] = args.method
    cfg.setdefault("method", "000")
    if cfg["method"] not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {cfg['method']!r}")
    return cfg


def _lockstep(args: argparse.Namespace, cfg: dict, port) -> int:
    import cv2

    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.host.lockstep_client import LockstepClient, serve_stream
    from mobigrasp.link import lockstep as ls
    from mobigrasp.link.base import LinkClosed
    from mobigrasp.link.frame_ring import FrameRingReader

    # one OpenCV thread: the machine's other core runs the rig, whose time this process waits
    # for; a pool would take it mid-frame (results are the same on any number of threads)
    cv2.setNumThreads(1)
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(120.0)  # safety limit only; the rig answers at once
    try:
        sock.connect(args.lockstep)
    except OSError as exc:
        sock.close()
        port.close()
        print(f"mobigrasp host: cannot connect to --lockstep {args.lockstep}: {exc}",
              file=sys.stderr)
        return 2
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
    """Frames from cv2.VideoCapture, stamped with wall time (free-running mode only).

    A live source (a device index, or a URL such as ``mobigrasp sim``'s MJPEG stream) is read
    by a thread as fast as it delivers, keeping only the newest frame: a host loop that falls
    behind for a moment then skips frames, as a CAMIF does, instead of working through a
    growing backlog of old ones (whose scene lags the arm further each time). A video file is
    read one frame per call, at the camera rate."""

    def __init__(self, source: str, t0: float) -> None:
        import threading

        import cv2

        self._cv2 = cv2
        self.live = source.isdigit() or "://" in source
        self.cap = cv2.VideoCapture(int(source) if source.isdigit() else source)
        if not self.cap.isOpened():
            raise ValueError(f"cannot open camera source {source!r}")
        self._t0 = t0
        self.seq = 0
        self._latest = None  # (seq, arrival_us, rgb) from the reader thread
        self._taken = -1
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        if self.live:
            self._thread = threading.Thread(target=self._reader, daemon=True, name="camera")
            self._thread.start()

    def _convert(self, bgr):
        return self._cv2.resize(self._cv2.cvtColor(bgr, self._cv2.COLOR_BGR2RGB), (320, 240))

    def _reader(self) -> None:
        while not self._stop.is_set():
            ok, bgr = self.cap.read()
            if not ok:
                return  # the stream ended
            arrival_us = int((time.monotonic() - self._t0) * 1e6)
            rgb = self._convert(bgr)
            with self._lock:
                self._latest = (self.seq, arrival_us, rgb)
                self.seq += 1

    def read(self, now_us: int):
        """(seq, arrival_us, rgb) of a frame not handed out before, or None."""
        if not self.live:
            ok, bgr = self.cap.read()
            if not ok:
                return None
            self.seq += 1
            return self.seq - 1, now_us, self._convert(bgr)
        with self._lock:
            got = self._latest
        if got is None or got[0] == self._taken:
            return None
        self._taken = got[0]
        return got

    def close(self) -> None:
        """Stop the reader and release the capture."""
        self._stop.set()
        if self._thread is not None:
            # a read blocked on a stream that went quiet ends when the server closes it; the
            # capture is not released under a read still running (the thread is a daemon)
            self._thread.join(timeout=2.0)
            if self._thread.is_alive():
                return
        self.cap.release()


def _free_running(args: argparse.Namespace, cfg: dict, port) -> int:
    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.link.base import LinkClosed

    app = build_host_app(cfg)
    t0 = time.monotonic()
    try:
        camera = _OpenCvCamera(args.camera, t0) if args.camera else None
    except ValueError as exc:
        port.close()
        print(f"mobigrasp host: --camera {args.camera}: {exc}", file=sys.stderr)
        return 2
    next_frame = 0.0
    vanished = False
    print(f"host on {args.port} (method {cfg['method']}), Ctrl-C to stop", file=sys.stderr)
    try:
        while not app.finished:
            now_us = int((time.monotonic() - t0) * 1e6)
            data = port.read()
            if data:
                app.on_uart(data, now_us)
            if camera is not None and (camera.live or now_us >= next_frame):
                got = camera.read(now_us)
                if got is not None:
                    app.on_frame(got[0], got[1], max(got[1], app.now_us), got[2])
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
        if camera is not None:
            camera.close()
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
    from mobigrasp.link.registry import open_transport
    from mobigrasp.tools.heap_tuning import keep_freed_memory

    try:  # a port that does not exist or vanished: one line, as console says it
        port = open_transport(args.port)
    except (OSError, ValueError) as exc:
        print(f"mobigrasp host: cannot open --port {args.port}: {exc}", file=sys.stderr)
        return 2
    keep_freed_memory()  # frame-sized arrays are reused instead of faulted in again
    if args.lockstep:
        return _lockstep(args, cfg, port)
    return _free_running(args, cfg, port)


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
    p.add_argument("--method", default=None, choices=METHODS,
                   help="000, 001 or 002 (overrides --config)")
    p.set_defaults(func=_run)
