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

from mobigrasp.tools.method_choice import METHOD_CHOICES


def _config(args: argparse.Namespace) -> dict:
    """The configuration file checked (mcu_sim.world.scenario.parse_host_config), then
    ``--method``; ValueError with one line naming the file and the key."""
    from mobigrasp.host.task import METHODS, REGISTRY
    from mobigrasp.host.task.idle import IDLE, PROGRAM_TASKS
    from mobigrasp.mcu_sim import checks
    from mobigrasp.mcu_sim.world.scenario import parse_host_config

    cfg: dict = {}
    if args.config:
        where = f"--config {args.config}"
        text = checks.read_text(args.config, "--config")  # not a FIFO, a device, a folder
        raw = checks.load_json(text, where)
        # the idle method (host/task/idle.py) takes nothing but its name
        cfg = dict(raw) if raw == {"method": IDLE} else parse_host_config(raw, where,
                                                                          methods=REGISTRY)
    if args.method:
        cfg["method"] = args.method
    cfg.setdefault("method", "000")
    if cfg["method"] not in METHODS and cfg["method"] not in PROGRAM_TASKS:
        raise ValueError(f"method must be one of {tuple(METHODS)}, got {cfg['method']!r}")
    return cfg


def _lockstep(args: argparse.Namespace, cfg: dict, port) -> int:
    import cv2

    from mobigrasp.drivers.lockstep import LockstepClient, serve_socket
    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.link.base import LinkClosed

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
    try:
        serve_socket(client, sock, poll_s=args.poll_ms / 1000.0)
    except (LinkClosed, OSError) as exc:
        # the simulator died or closed the pty/socket mid-run (LockstepClosed is a
        # ConnectionError, an OSError): say so in one line and exit non-zero at once
        print(f"mobigrasp host: the simulator went away mid-run at t = "
              f"{client.clock.now_us() / 1e6:.3f} s simulated ({type(exc).__name__}: {exc}); "
              f"stopping", file=sys.stderr, flush=True)
        return 1
    finally:
        sock.close()
        port.close()
    return 0


def _free_running(args: argparse.Namespace, cfg: dict, port) -> int:
    from mobigrasp.drivers import realtime
    from mobigrasp.host.app_factory import build_host_app

    app = build_host_app(cfg)
    clock = realtime.WallClock()
    try:
        camera = realtime.OpenCvCamera(args.camera, clock) if args.camera else None
    except ValueError as exc:
        port.close()
        print(f"mobigrasp host: --camera {args.camera}: {exc}", file=sys.stderr)
        return 2
    print(f"host on {args.port} (method {cfg['method']}), Ctrl-C to stop", file=sys.stderr)
    try:
        why = realtime.run(app, port, clock, camera)
    finally:
        port.close()
        if camera is not None:
            camera.close()
    if why == "port_closed":  # the MCU (or its pty) vanished: a failure whatever the task's state
        print(f"mobigrasp host: the MCU side closed the port {args.port}; stopping",
              file=sys.stderr, flush=True)
    elif why == "interrupted":
        print("host: interrupted", file=sys.stderr)
    st = app.stats()
    print(f"host: state {st['state']}, control steps {st['control_steps']}, frames "
          f"{st['frames_processed']}/{st['frames_received']}, protocol "
          f"{json.dumps({k: v for k, v in st['protocol'].items() if k != 'parser'})}",
          file=sys.stderr)
    return 0 if app.state == "DONE" and why != "port_closed" else 1


def _run(args: argparse.Namespace) -> int:
    try:
        cfg = _config(args)
    except (OSError, ValueError) as exc:
        print(f"mobigrasp host: {exc}", file=sys.stderr)
        return 2
    from mobigrasp.cosim.heap_tuning import keep_freed_memory
    from mobigrasp.link.registry import open_transport

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
    # the rig's own options, set by `run` when it starts the host: not shown in --help
    p.add_argument("--lockstep", default=None, help=argparse.SUPPRESS)
    p.add_argument("--poll-ms", type=_poll_ms, default=0.0, help=argparse.SUPPRESS)
    p.add_argument("--config", default=None, help="host configuration JSON (method, params)")
    p.add_argument("--method", default=None, choices=METHOD_CHOICES, metavar="METHOD",
                   help="a method of the registry, host/task/method.py (overrides --config)")
    p.set_defaults(func=_run)
