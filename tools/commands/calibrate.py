"""``mobigrasp calibrate [--corpus DIR] [--json FILE]``: the host's modelled ARM9 time per stage
against the same stage's C run as ARM920T code under a static timing model (calib/, the table
and its reading in docs/budget.md). Without --corpus the corpus of the six shipped scenarios (or
of each ``--scenario NAME``) is recorded into a temporary folder first; ``--scenario`` also
limits what a given corpus is timed on. The shipped scenarios of each method the C program has
are then run again with the Python host program recorded and replayed on the C program as
ARM920T code: its whole control steps and frame pipelines (calib/program.py; not with
``--no-programs``). Progress on stderr (scenarios recorded, then frames, planner calls and scenario
replays emulated, a replay one step: done/total, elapsed, ~left; none with ``-q``); the table on
stdout; the result is also kept as the last calibration that ``mobigrasp profile`` shows. Exit 1
when an emulated result differs from the Python kernel's (or a replay from the Python
program's), 2 for bad input."""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from mobigrasp.mcu_sim import checks


def _table(result: dict) -> str:
    lines = [f"{'stage':<20}{'frames':>7}{'model_us':>10}{'emu_us':>10}{'emu_p95':>10}"
             f"{'emu_max':>10}{'ratio':>7}{'cpi':>6}{'fill':>7}"]
    for name, s in result["stages"].items():
        lines.append(f"{name:<20}{s['frames']:>7}{s['modelled_median_us']:>10.0f}"
                     f"{s['emulated_median_us']:>10.0f}{s['emulated_p95_us']:>10.0f}"
                     f"{s['emulated_max_us']:>10.0f}{s['ratio_median']:>7.2f}{s['cpi']:>6.2f}"
                     f"{s['line_fill_share']:>7.1%}")
    lines.append(f"commit {result['commit']}, line fill {result['line_fill_cycles']} cycles, "
                 f"{result['frames']} frames")
    return "\n".join(lines)


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.calib import calibrate, corpus, plan_corpus
    from mobigrasp.calib.arm import ToolchainError, progress_stderr
    from mobigrasp.services.corpus import record as record_corpus
    from mobigrasp.services.corpus import record_steps
    from mobigrasp.services.run_job import BadInput, shipped_scenarios
    from mobigrasp.tools.progress import StepProgress

    if args.frames_per_scenario is not None and args.frames_per_scenario < 1:
        print(f"mobigrasp calibrate: --frames-per-scenario must be >= 1, got "
              f"{args.frames_per_scenario}", file=sys.stderr)
        return 2
    if not 0 <= args.line_fill_cycles <= 1000:
        print(f"mobigrasp calibrate: --line-fill-cycles must be 0..1000, got "
              f"{args.line_fill_cycles}", file=sys.stderr)
        return 2
    if args.json is not None and (args.json.is_dir() or any(
            p.exists() and not p.is_dir() for p in args.json.parents)):
        print(f"mobigrasp calibrate: --json {args.json} is a folder or lies under a file",
              file=sys.stderr)
        return 2
    per = None if args.all else args.frames_per_scenario
    try:
        with tempfile.TemporaryDirectory(prefix="mobigrasp-calib-") as tmp:
            folder = args.corpus
            if folder is None:
                folder = Path(tmp) / "corpus"
                with StepProgress("calibrate: corpus of the shipped scenarios", "scenarios",
                                  enabled=not args.quiet) as recorded:
                    record_corpus(folder, args.scenario or
                                  [p.stem for p in shipped_scenarios()], progress=recorded)
            with StepProgress("calibrate: emulated", "frames and planner calls",
                              enabled=not args.quiet) as emulated:
                result = calibrate.calibrate(folder, per, args.line_fill_cycles,
                                             progress=None if args.quiet else progress_stderr,
                                             on_step=emulated,
                                             record=None if args.no_programs else record_steps,
                                             scenarios=args.scenario)
    except (corpus.CorpusError, plan_corpus.PlanCorpusError, ToolchainError, BadInput) as exc:
        print(f"mobigrasp calibrate: {exc}", file=sys.stderr)
        return 2
    if args.corpus is None:
        result["corpus"] = "recorded (shipped scenarios)"
    for path in (None, args.json) if args.json is not None else (None,):
        try:
            calibrate.write(result, path)
        except OSError as exc:
            print(f"mobigrasp calibrate: cannot write {path or calibrate.default_path()}: "
                  f"{exc.strerror or exc}", file=sys.stderr)
            return 2
    print(_table(result))
    bad = [n for n, s in result["stages"].items() if s["result_mismatches"]]
    if bad:
        print(f"mobigrasp calibrate: emulated results differ from Python in {bad}",
              file=sys.stderr)
        return 1
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``calibrate`` subcommand."""
    p = sub.add_parser("calibrate", help="modelled vs emulated ARM920T time per host stage")
    p.add_argument("--corpus", type=Path, default=None,
                   help="corpus folder (mobigrasp corpus); default: record one first")
    p.add_argument("--json", type=Path, default=None, help="write the result here too")
    p.add_argument("--scenario", action="append", metavar="NAME",
                   help="only this shipped scenario (repeat; default: all of the corpus, or "
                   "the six shipped): its frames, planner calls and replay")
    p.add_argument("--frames-per-scenario", type=checks.arg_int(1, 10_000), default=10, metavar="N",
                   help="frames per scenario, spread evenly (default 10); as many control "
                   "steps and frame pipelines per replayed scenario")
    p.add_argument("--all", action="store_true",
                   help="every frame of the corpus (and every step of the replays)")
    p.add_argument("--no-programs", action="store_true",
                   help="the kernels and planners only: no whole steps replayed on the C program")
    p.add_argument("--line-fill-cycles", type=checks.arg_int(0, 1000), default=40, metavar="C",
                   help="core cycles of one D-cache line fill (default 40)")
    p.set_defaults(func=_run)
