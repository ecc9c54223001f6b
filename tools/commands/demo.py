"""``mobigrasp demo``: the main job of ``make demo``: paper000-exp1 in closed loop over the pty.

The emulated MCU + world (this process) and the host program (a second process) are joined by a
real pseudo-terminal in lockstep simulated time; at the end it prints where the report is.
``--count N`` runs only the link demo instead (frames over a pty to an echo process and back).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mobigrasp.mcu_sim import checks


def _main(args: argparse.Namespace) -> int:
    if args.count is not None:
        from mobigrasp.tools.commands.link_demo import run_link_demo

        print("mobigrasp demo --count: runs the link demo (mobigrasp link-demo): frames over a "
              "real pty to a second process and back.")
        result = run_link_demo(args.count)
        return 0 if result["lost"] == 0 else 1
    from mobigrasp.services.run_job import BadInput, RunOptions, execute, summary_line
    from mobigrasp.tools.progress import RunProgress

    out = args.out or Path("runs") / "demo-paper000-exp1"
    print("mobigrasp demo: paper000-exp1 (paper 000, experiment 1) in closed loop: emulated "
          "ATmega128 + pymunk world + eye-in-hand camera here, the S3C2440 host program in a "
          "second process, joined by a real pty in lockstep simulated time.")
    display = RunProgress(enabled=not args.quiet)
    try:
        summary, code = execute(RunOptions(scenario="paper000-exp1", transport="pty", out=out,
                                           progress=display))
    except BadInput as exc:
        print(f"mobigrasp demo: {exc}", file=sys.stderr)
        return 2
    except BaseException:
        display.close()
        raise
    display.finish(summary)
    print(summary_line(summary, out))
    print(f"report: {(out / 'report.html').resolve()}")
    return code


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``demo``."""
    parser = sub.add_parser("demo", help="run paper000-exp1 in closed loop over the pty")
    parser.add_argument("--out", type=Path, default=None,
                        help="run folder (default runs/demo-paper000-exp1)")
    parser.add_argument("--count", type=checks.arg_int(1, 1_000_000), default=None,
                        help="run only the link demo with this many messages")
    parser.set_defaults(func=_main)
