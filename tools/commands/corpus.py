"""``mobigrasp corpus --out DIR``: record the frames the host's detectors were given in the
shipped scenarios (calib/corpus.py describes the folder). Progress on stderr (none with
``-q``); exit 2 for bad
input (an --out that is a file or a folder that is not a corpus, an unknown scenario)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mobigrasp.mcu_sim import checks
from mobigrasp.mcu_sim.world.scenario import MAX_TIME_LIMIT_S


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.calib.corpus import CorpusError
    from mobigrasp.services.corpus import record
    from mobigrasp.services.run_job import BadInput, shipped_scenarios
    from mobigrasp.tools.progress import StepProgress

    names = args.scenario or [p.stem for p in shipped_scenarios()]
    if args.time_limit_s is not None and not args.time_limit_s > 0:
        print(f"mobigrasp corpus: --time-limit-s must be > 0, got {args.time_limit_s}",
              file=sys.stderr)
        return 2
    try:
        with StepProgress("corpus", "scenarios", enabled=not args.quiet) as recorded:
            index = record(args.out, names, args.time_limit_s, progress=recorded)
    except (CorpusError, BadInput) as exc:
        print(f"mobigrasp corpus: {exc}", file=sys.stderr)
        return 2
    print(f"{args.out}: {len(index['frames'])} frames from {len(index['scenarios'])} scenarios")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``corpus`` subcommand."""
    p = sub.add_parser("corpus", help="record the detector frames of the shipped scenarios")
    p.add_argument("--out", type=Path, required=True, help="corpus folder")
    p.add_argument("--scenario", action="append", metavar="NAME",
                   help="only this scenario (repeat; default: the six shipped)")
    p.add_argument("--time-limit-s", default=None,
                   type=checks.arg_number(0.0, MAX_TIME_LIMIT_S, "s", lo_open=True),
                   help="stop each run after this many simulated seconds")
    p.set_defaults(func=_run)
