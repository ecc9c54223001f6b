"""``mobigrasp run SCENARIO``: the closed loop, SIM and HOST processes joined by a real pty.

Exit code 0 when the grasp succeeded, 1 when the task failed (or the run crashed), 2 for bad
input (unknown scenario, invalid file, bad option). Progress goes to stderr; the run folder
(summary.json, trace.jsonl, plots/, frames/, report.html) is described in docs/cosim.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mobigrasp.tools.method_choice import add_host_option


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.cosim.run_folder import default_run_folder
    from mobigrasp.services.run_job import (
        BadInput,
        RunOptions,
        check_run,
        execute,
        parse_speed,
        summary_line,
    )
    from mobigrasp.tools.progress import RunProgress

    display = RunProgress(total_s=args.time_limit_s, enabled=not args.quiet)
    try:
        speed = parse_speed(args.speed)
        opts = RunOptions(scenario=args.scenario, seed=args.seed, transport=args.transport,
                          mcu=args.mcu, host=args.host, speed=speed, out=args.out, progress=display,
                          plots=not args.no_plots, time_limit_s=args.time_limit_s,
                          faults=tuple(args.fault or ()),
                          host_lag_quanta=args.host_lag_quanta)
        if args.check:
            print(check_run(opts))
            return 0
        summary, code = execute(opts)
    except BadInput as exc:
        print(f"mobigrasp run: {exc}", file=sys.stderr)
        return 2
    except BaseException:
        display.close()
        raise
    display.finish(summary)
    out = Path(args.out) if args.out else default_run_folder(summary["scenario"], summary["seed"])
    print(summary_line(summary, out))
    return code


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``run`` subcommand."""
    p = sub.add_parser("run", help="run a scenario in closed loop (SIM + HOST over a pty)")
    p.add_argument("scenario", help="scenario file or shipped scenario name (mobigrasp scenarios)")
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scenario's)")
    p.add_argument("--transport", default="pty", choices=("pty", "inproc"),
                   help="pty (two processes, default) or inproc")
    p.add_argument("--mcu", default="python",
                   help="MCU backend: python (the firmware model, default), native (the C "
                        "firmware built with this machine's gcc) or simavr (its avr-gcc ELF "
                        "on simavr)")
    add_host_option(p)
    p.add_argument("--speed", default="max",
                   help="simulated/wall time factor, or 'max' (default); pacing only")
    p.add_argument("--out", type=Path, default=None,
                   help="run folder (default runs/<scenario>-<seed>/)")
    p.add_argument("--time-limit-s", type=float, default=None,
                   help="stop after this many simulated seconds (default: the scenario's)")
    p.add_argument("--fault", action="append", metavar="KEY=VALUE",
                   help="inject a fault (docs/faults.md), e.g. uart_bit_error_rate=1e-3; repeat")
    p.add_argument("--check", action="store_true",
                   help="only check the scenario, the options and the --out folder (as the "
                        "run takes it; nothing is changed) and build the world and host "
                        "program from them, without running: exit 0 or 2")
    p.add_argument("--no-plots", action="store_true", help="skip plots and report.html")
    p.add_argument("--host-lag-quanta", type=int, default=1, metavar="N",
                   help="1 (default): each grant is issued one quantum ahead, so host and "
                        "simulator overlap and the host's input is 5 ms later; 0: strict "
                        "alternation (docs/cosim.md)")
    p.set_defaults(func=_run)
