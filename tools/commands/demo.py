"""``mobigrasp demo``: the main job of ``make demo``.

Until the closed loop (host + emulated MCU + world) exists, it runs the link demo and says so.
"""

from __future__ import annotations

import argparse

from tools.commands.link_demo import run_link_demo


def _main(args: argparse.Namespace) -> int:
    print("mobigrasp demo: the closed loop is not wired yet, so this runs the link demo "
          "(mobigrasp link-demo): frames over a real pty to a second process and back.")
    result = run_link_demo(args.count)
    return 0 if result["lost"] == 0 else 1


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``demo``."""
    parser = sub.add_parser("demo", help="run the main demo (for now: the link demo)")
    parser.add_argument("--count", type=int, default=300, help="messages for the link demo")
    parser.set_defaults(func=_main)
