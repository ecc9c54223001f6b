"""``mobigrasp sim SCENARIO``: the simulated robot served to your own host program, in wall time.

The scenario's emulated ATmega128 and world run paced to the wall clock (``--speed 1``, default;
0.5 for a slow host). The serial line is a new pty, exactly as ``mobigrasp mcu`` serves it; the
eye-in-hand camera (320x240, rendered from the arm's current pose at the camera rate) is an MJPEG
stream on 127.0.0.1 that ``cv2.VideoCapture(URL)`` opens, and ``/frame.png`` the latest frame.
The first two lines on stdout are ``serial: /dev/pts/N`` and ``camera: http://127.0.0.1:PORT/
stream.mjpg``; with ``--raw-frames PATH`` the frames are also served raw on a Unix socket
(cosim/serve/raw_frames.py), printed as ``raw-frames: unix:PATH``. The session ends when the
host closes the port, at the scenario's time limit, or on Ctrl-C/SIGTERM, and writes the run
folder as ``mobigrasp run`` does (grasped, contacts and the safety block judged from the world;
the host's traffic decoded in the trace).

Exit code 0 when the object is grasped, 1 when not, 2 for bad input (unknown scenario, bad
option, camera port in use), with one line on stderr.
"""

from __future__ import annotations

import argparse
import math
import signal
import sys
from pathlib import Path


def _speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0 < value <= 100):
        raise argparse.ArgumentTypeError(f"must be a number in (0, 100], got {text!r}")
    return value


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be a TCP port in [0, 65535], got {text!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``sim`` subcommand."""
    p = sub.add_parser("sim", help="serve a scenario's robot (pty + MJPEG camera) to your host")
    p.add_argument("scenario", help="scenario file or shipped scenario name (mobigrasp scenarios)")
    p.add_argument("--speed", type=_speed, default=1.0,
                   help="simulated seconds per wall second (default 1); pacing only")
    p.add_argument("--mcu", default="python", metavar="NAME",
                   help="MCU backend from mobigrasp.mcu_sim.backend.MCU_BACKENDS: python (the "
                        "firmware model, default), native (the C firmware), ...")
    p.add_argument("--camera-port", type=_port, default=0,
                   help="TCP port of the camera on 127.0.0.1 (default 0: any free port, so two "
                        "sessions never collide)")
    p.add_argument("--tcp-port", type=_port, default=None, metavar="N",
                   help="serve the serial line on 127.0.0.1:N too (0: any free port), printed "
                        "as 'serial-tcp: tcp://127.0.0.1:PORT'")
    p.add_argument("--wait-host", action=argparse.BooleanOptionalAction, default=None,
                   help="start the simulated clock at the host's first valid frame (default: "
                        "wait when stdin is not a terminal, as in CI; not at a terminal)")
    p.add_argument("--fault", action="append", metavar="KEY=VALUE",
                   help="inject a fault (docs/faults.md), e.g. uart_bit_error_rate=1e-3; repeat")
    p.add_argument("--out", type=Path, default=None,
                   help="run folder (default runs/<scenario>-<seed>-sim/, or -sim-2, ... when "
                        "another session holds it)")
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scenario's)")
    p.add_argument("--time-limit-s", type=float, default=None,
                   help="end after this many simulated seconds (default: the scenario's)")
    p.add_argument("--raw-frames", type=Path, default=None, metavar="PATH",
                   help="serve the camera's frames raw on a Unix socket at PATH too (a 32-byte "
                        "header, then 320x240 RGB; docs/porting.md), for a host without a JPEG "
                        "decoder: the C host's --camera unix:PATH; printed as 'raw-frames: "
                        "unix:PATH'")
    p.add_argument("--no-plots", action="store_true", help="skip plots and report.html")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.cosim.serve.session import SimOptions
    from mobigrasp.services.run_job import BadInput
    from mobigrasp.services.sim_job import exit_code, serve_scenario
    from mobigrasp.tools.progress import Progress

    asked: list[str] = []

    def on_signal(signum, frame) -> None:
        asked.append("interrupted" if signum == signal.SIGINT else "terminated")

    def on_ready(serial: str, camera: str, serial_tcp: str | None) -> None:
        print(f"serial: {serial}", flush=True)
        print(f"camera: {camera}", flush=True)
        if serial_tcp is not None:
            print(f"serial-tcp: {serial_tcp}", flush=True)
        if args.raw_frames is not None:
            print(f"raw-frames: unix:{args.raw_frames}", flush=True)

    def display(total_s: float, name: str) -> Progress:
        return Progress(total=total_s, desc=f"sim {name}", unit="s simulated",
                        enabled=not args.quiet)

    wait_host = (not sys.stdin.isatty()) if args.wait_host is None else args.wait_host
    opts = SimOptions(scenario=args.scenario, speed=args.speed, mcu=args.mcu,
                      camera_port=args.camera_port, tcp_port=args.tcp_port,
                      wait_host=wait_host, out=args.out, seed=args.seed,
                      time_limit_s=args.time_limit_s, raw_frames=args.raw_frames)
    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        summary = serve_scenario(opts, on_ready, stop=lambda: asked[0] if asked else None,
                                 faults=tuple(args.fault or ()), plots=not args.no_plots,
                                 progress=display)
    except BadInput as exc:
        print(f"mobigrasp sim: {exc}", file=sys.stderr)
        return 2
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
    print(f"{summary['scenario']} served to an external host: "
          f"{'GRASPED' if summary['grasped'] else 'not grasped'} ({summary['end_reason']}) in "
          f"{summary['sim_time_s']:.1f} s simulated, {summary['wall_time_s']:.1f} s wall; "
          f"run folder: {summary['run_folder']}", flush=True)
    if summary.get("host_traffic"):
        from mobigrasp.services.wire_traffic import traffic_lines

        for line in traffic_lines(summary["host_traffic"]):
            print(f"  {line}", flush=True)
    return exit_code(summary)
