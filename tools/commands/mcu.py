"""``mobigrasp mcu``: the emulated ATmega128 alone on a new pty, serving any host.

Prints the pty slave path on its first line (flushed), then runs the MCU with simulated time
paced to the wall clock (``--speed 1``, default), a multiple of it, or as fast as possible
(``--speed max``). Bytes read from the pty are put on the simulated RX line at the current
simulated time. With no world attached, the encoders follow the "wheels in the air" plant
(mcu_sim/bench_plant.py) and the sonars hear no echo. Exits with a message when the host closes
the port (after it has sent something), after ``--duration`` simulated seconds, or on Ctrl-C.
"""

from __future__ import annotations

import argparse
import sys
import time

PLANT_STEP_US = 10_000
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


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``mcu`` subcommand."""
    p = sub.add_parser("mcu", help="run the emulated ATmega128 on a new pty (prints its path)")
    p.add_argument("--speed", type=_speed, default=1.0,
                   help="simulated seconds per wall second, or 'max' (default 1)")
    p.add_argument("--baud-ubrr", type=int, default=16, help="UBRR0 value (default 16)")
    p.add_argument("--u2x", type=int, choices=(0, 1), default=1, help="U2X0 bit (default 1)")
    p.add_argument("--duration", type=float, default=None,
                   help="stop after this many simulated seconds (default: run until closed)")
    p.add_argument("--param", type=_param, action="append", default=[],
                   help="firmware PARAM default, NAME=VALUE (repeatable), e.g. watchdog_ms=500")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Serve until the host closes the port, the duration ends, or Ctrl-C."""
    from mobigrasp.mcu_sim.bench_plant import WheelsInTheAir
    from mobigrasp.mcu_sim.mcu import McuConfig
    from mobigrasp.mcu_sim.mcu_pty import PtyMcu

    try:
        config = McuConfig(ubrr=args.baud_ubrr, u2x=args.u2x, params=dict(args.param))
        pty = PtyMcu(config, record=False)
    except ValueError as exc:
        print(f"mobigrasp mcu: {exc}", file=sys.stderr)
        return 2
    print(pty.port, flush=True)
    mcu = pty.mcu
    print(f"emulated ATmega128 on {pty.port}: UBRR={args.baud_ubrr} U2X={args.u2x} -> "
          f"{mcu.baud:.0f} baud ({mcu.baud_error_pct:+.2f} % from 115200); speed "
          f"{'max' if args.speed is None else args.speed}", file=sys.stderr, flush=True)
    end_us = None if args.duration is None else int(args.duration * 1_000_000)
    plant = WheelsInTheAir()
    next_plant = 0
    wall0 = time.monotonic()
    reason = "duration reached"
    try:
        while end_us is None or mcu.now_us < end_us:
            now = mcu.now_us
            if args.speed is None:
                target = now + PLANT_STEP_US
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
            while mcu.now_us < target:
                if mcu.now_us >= next_plant:
                    ticks = plant.step(mcu.wheel_duty(), PLANT_STEP_US)
                    next_plant = mcu.now_us + PLANT_STEP_US
                    mcu.set_encoder_ticks(ticks[0], ticks[1], next_plant)
                pty.pump_from_host()
                mcu.advance_to(min(target, mcu.now_us + PUMP_STEP_US, next_plant))
                pty.forward_tx()
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
          f"watchdog trips {stats['watchdog_trips']}", file=sys.stderr, flush=True)
    # the host going away mid-run is a failure for whoever waits on this process (issue 9)
    return 1 if pty.host_closed else 0
