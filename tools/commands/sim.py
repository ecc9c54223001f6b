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


def _mcu_names() -> list[str]:
    from mobigrasp.mcu_sim.backend import MCU_BACKENDS

    return sorted(MCU_BACKENDS)


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
    from mobigrasp.cosim.serve.session import BadSimInput, SimOptions, serve
    from mobigrasp.services.run_job import (
        BadInput,
        check_seed,
        check_time_limit,
        fault_plan,
        resolve_scenario,
    )

    names = _mcu_names()
    mcu = args.mcu
    if mcu not in names:
        print(f"mobigrasp sim: --mcu must be one of {', '.join(names)}, got {mcu!r}",
              file=sys.stderr)
        return 2
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

    try:
        check_seed(args.seed)
        check_time_limit(args.time_limit_s)
        resolved = resolve_scenario(args.scenario)
        plan = fault_plan(resolved[1], args.fault)
    except BadInput as exc:
        print(f"mobigrasp sim: {exc}", file=sys.stderr)
        return 2
    from mobigrasp.mcu_sim.world.scenario import run_time_limit_s
    from mobigrasp.services.mcap_out import McapLog
    from mobigrasp.services.run_job import mcap_camera, mcap_info
    from mobigrasp.tools.progress import Progress

    wait_host = (not sys.stdin.isatty()) if args.wait_host is None else args.wait_host
    scenario = resolved[1]
    seed = scenario.meta.seed if args.seed is None else args.seed
    # trace.mcap, written as the session goes once its folder is taken
    frames = McapLog(info={**mcap_info(scenario, seed, mcu, "pty"), "host": "external"},
                     camera=mcap_camera(scenario))
    display = Progress(total=round(run_time_limit_s(scenario, args.time_limit_s), 1),
                       desc=f"sim {scenario.meta.name}", unit="s simulated",
                       enabled=not args.quiet)
    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        summary = serve(SimOptions(scenario=args.scenario, speed=args.speed, mcu=mcu,
                                   camera_port=args.camera_port, out=args.out, seed=args.seed,
                                   time_limit_s=args.time_limit_s, progress=display,
                                   resolved=resolved, plan=plan, wait_host=wait_host,
                                   tcp_port=args.tcp_port, on_frame=frames.on_frame,
                                   raw_frames=args.raw_frames,
                                   on_folder=lambda out: frames.start(out / "trace.mcap")),
                        on_ready, stop=lambda: asked[0] if asked else None)
    except BadSimInput as exc:
        print(f"mobigrasp sim: {exc}", file=sys.stderr)
        return 2
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
    folder = Path(summary["run_folder"])
    _write_traffic(folder, summary, frames)
    if not args.no_plots:
        try:
            from mobigrasp.services.report import write_report

            write_report(Path(summary["run_folder"]))
        except Exception as exc:  # a plotting failure must not hide the run's result
            print(f"report: {type(exc).__name__}: {exc}", file=sys.stderr)
    print(f"{summary['scenario']} served to an external host: "
          f"{'GRASPED' if summary['grasped'] else 'not grasped'} ({summary['end_reason']}) in "
          f"{summary['sim_time_s']:.1f} s simulated, {summary['wall_time_s']:.1f} s wall; "
          f"run folder: {folder}", flush=True)
    if summary.get("host_traffic"):
        from mobigrasp.services.wire_traffic import traffic_lines

        for line in traffic_lines(summary["host_traffic"]):
            print(f"  {line}", flush=True)
    return 0 if summary["grasped"] else 1


def _write_traffic(folder: Path, summary: dict, frames) -> None:
    """The host's traffic from the trace into summary.json, and trace.mcap; a failure is
    reported, never hides the session's result."""
    from mobigrasp.cosim.run_folder import read_trace, write_summary
    from mobigrasp.services.wire_traffic import host_traffic

    try:
        events = read_trace(folder / "trace.jsonl")
        summary["host_traffic"] = host_traffic(events)
        stored = {k: v for k, v in summary.items() if k != "run_folder"}
        write_summary(folder / "summary.json", stored)
        frames.finish(summary)
    except Exception as exc:
        print(f"trace.mcap: {type(exc).__name__}: {exc}", file=sys.stderr)
