"""``mobigrasp mcu``: the emulated ATmega128 alone on a new pty, serving any host.

Prints the pty slave path on its first line (flushed), then runs the MCU with simulated time
paced to the wall clock (``--speed 1``, default), a multiple of it, or as fast as possible
(``--speed max``). Bytes read from the pty are put on the simulated RX line at the current
simulated time. With no world attached the sonars hear no echo and the encoders follow
``--wheels``: ``bench`` (default) turns them as two unloaded motors with their lag would
(mcu_sim/bench_plant.py), so SetWheels moves the counts; ``still`` keeps them at 0. ``--log``
prints every message the MCU sends, one line each, NACK reasons and telemetry flags by name
(telemetry only with ``--log all``). Exits with a message when the host closes the port (after
it has sent something), after ``--duration`` simulated seconds, or on Ctrl-C; the last line
counts the NACKs sent by reason.
"""

from __future__ import annotations

import argparse
import sys
import time

from mobigrasp.mcu_sim import checks

PUMP_STEP_US = 1_000


def _speed(text: str) -> float | None:
    if text == "max":
        return None
    try:
        value = float(text)
    except ValueError:
        msg = f"--speed must be a number > 0 or 'max', got {text!r}"
        raise argparse.ArgumentTypeError(msg) from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"--speed must be > 0, got {text!r}")
    return value


def _param(text: str) -> tuple[str, int]:
    name, sep, value = text.partition("=")
    try:
        return name, int(value) if sep else int("x")
    except ValueError:
        raise argparse.ArgumentTypeError(f"--param wants NAME=INTEGER, got {text!r}") from None


WHEELS = ("bench", "still")  # mcu_sim.mcu_pty.WHEELS (not imported: --help stays cheap)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``mcu`` subcommand."""
    p = sub.add_parser("mcu", help="run the emulated ATmega128 on a new pty (prints its path)")
    p.add_argument("--speed", type=_speed, default=1.0,
                   help="simulated seconds per wall second, or 'max' (default 1)")
    p.add_argument("--mcu", default="python",
                   help="MCU backend: python (the firmware model, default) or native (the C "
                        "firmware built with this machine's gcc)")
    p.add_argument("--baud-ubrr", type=int, default=16, help="UBRR0 value (default 16)")
    p.add_argument("--u2x", type=int, choices=(0, 1), default=1, help="U2X0 bit (default 1)")
    p.add_argument("--duration", type=checks.arg_number(0.0, 1e6, "s", lo_open=True), default=None,
                   help="stop after this many simulated seconds (default: run until closed)")
    p.add_argument("--param", type=_param, action="append", default=[],
                   help="firmware PARAM default, NAME=VALUE (repeatable), e.g. watchdog_ms=500")
    p.add_argument("--wheels", choices=WHEELS, default=WHEELS[0],
                   help="wheel plant without a world: 'bench' (default) turns the encoders as "
                        "unloaded motors with their lag; 'still' keeps them at 0")
    p.add_argument("--log", choices=("replies", "all"), default=None,
                   help="print the MCU's messages on stderr: 'replies' (all but telemetry) "
                        "or 'all'")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Serve until the host closes the port, the duration ends, or Ctrl-C."""
    from mobigrasp.mcu_sim.mcu import McuConfig
    from mobigrasp.mcu_sim.mcu_pty import PtyMcu
    from mobigrasp.mcu_sim.wire_names import describe, nack_reason_name
    from mobigrasp.protocol.messages import Nack, Telemetry

    nacks: dict[str, int] = {}

    def on_sent(t_us: int, msg: object) -> None:
        if isinstance(msg, Nack):
            name = nack_reason_name(msg.reason)
            nacks[name] = nacks.get(name, 0) + 1
        if args.log == "all" or (args.log and not isinstance(msg, Telemetry)):
            print(f"{t_us / 1e6:10.6f} s  {describe(msg)}", file=sys.stderr, flush=True)

    try:
        config = McuConfig(ubrr=args.baud_ubrr, u2x=args.u2x, params=dict(args.param))
        pty = PtyMcu(config, record=False, wheels=args.wheels, on_sent=on_sent, mcu=args.mcu)
    except ValueError as exc:
        print(f"mobigrasp mcu: {exc}", file=sys.stderr)
        return 2
    print(pty.port, flush=True)
    mcu = pty.mcu
    print(f"emulated ATmega128 on {pty.port}: UBRR={args.baud_ubrr} U2X={args.u2x} -> "
          f"{mcu.baud:.0f} baud ({mcu.baud_error_pct:+.2f} % from 115200); speed "
          f"{'max' if args.speed is None else args.speed}; wheels {args.wheels}",
          file=sys.stderr, flush=True)
    end_us = None if args.duration is None else int(args.duration * 1_000_000)
    wall0 = time.monotonic()
    reason = "duration reached"
    try:
        while end_us is None or mcu.now_us < end_us:
            now = mcu.now_us
            if args.speed is None:
                target = now + 10 * PUMP_STEP_US
            else:
                target = int((time.monotonic() - wall0) * args.speed * 1_000_000)
                if target < now + PUMP_STEP_US:
                    wait_s = (now + PUMP_STEP_US - target) / args.speed / 1e6
                    pty.pump_from_host(timeout_s=min(0.05, max(wait_s, 1e-4)))
                    if pty.host_closed:
                        reason = "the host closed the port"
                        break
                    continue
            if end_us is not None:
                target = min(target, end_us)
            if target > now:
                pty.advance_to(target, PUMP_STEP_US)
            if pty.host_closed:
                reason = "the host closed the port"
                break
    except KeyboardInterrupt:
        reason = "interrupted"
    finally:
        pty.close()
    stats = mcu.stats()
    print(f"mobigrasp mcu: {reason} at t = {mcu.now_us / 1e6:.3f} s simulated; "
          f"rx {stats['rx_bytes']} B, tx {stats['tx_bytes']} B, "
          f"corrupt frames {stats['corrupt_frames']}, overruns {stats['overruns']}, "
          f"watchdog trips {stats['watchdog_trips']}; NACKs sent: "
          f"{', '.join(f'{k} {v}' for k, v in sorted(nacks.items())) or 'none'}",
          file=sys.stderr, flush=True)
    # the host going away mid-run is a failure for whoever waits on this process
    return 1 if pty.host_closed else 0
