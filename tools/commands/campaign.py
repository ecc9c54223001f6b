"""``mobigrasp campaign --method M --runs N [--fault KEY=VALUE ...]``: a fault campaign.

Runs N seeded random scenarios under the faults, in parallel over the cores or on a Dask cluster
(``--scheduler``), with progress on stderr; every row lands in ``campaign.rows.jsonl`` as its run
finishes (``--resume`` continues an interrupted campaign). Prints the table (success rate, unsafe
actuations, watchdog trips, retransmits, stop latency, recovery times) and writes
``campaign.json`` and ``campaign.png`` in ``--out``. Exit 0 when every run finished (whatever its
success), 1 when a run crashed, 2 for bad input.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mobigrasp.mcu_sim import checks
from mobigrasp.mcu_sim.world.scenario import MAX_SEED, MAX_TIME_LIMIT_S
from mobigrasp.tools.method_choice import METHOD_CHOICES, add_host_option


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.mcu_sim.faults.plan import FaultError, parse_fault_overrides
    from mobigrasp.services.campaign import (
        CampaignConfig,
        check_host,
        claim_out,
        format_table,
        run_campaign,
        write_outputs,
    )
    from mobigrasp.tools.progress import Progress

    try:
        plan = parse_fault_overrides(args.fault or [])
        cfg = CampaignConfig(method=args.method, runs=args.runs, faults=plan, seed=args.seed,
                             jobs=args.jobs, out=args.out, time_limit_s=args.time_limit_s,
                             random_times=args.random_times, scheduler=args.scheduler,
                             resume=args.resume, host=args.host)
        check_host(cfg)
    except (FaultError, ValueError) as exc:
        print(f"mobigrasp campaign: {exc}", file=sys.stderr)
        return 2
    try:  # the folder locked before anything in it is touched
        folder = claim_out(cfg)
    except ValueError as exc:  # in use, not a campaign's folder, a file
        print(f"mobigrasp campaign: {exc}", file=sys.stderr)
        return 2
    with folder:
        display = Progress(total=cfg.runs, desc="campaign", unit="runs", enabled=not args.quiet)
        try:
            result = run_campaign(cfg, progress=display, folder=folder)
        except ValueError as exc:  # EngineError (scheduler unreachable), a row of another
            display.close()        # campaign or not a row
            print(f"mobigrasp campaign: {exc}", file=sys.stderr)
            return 2
        for note in result["set_aside"]:
            print(f"mobigrasp campaign: {note}", file=sys.stderr)
        print(format_table(result["summary"]))
        js, png = write_outputs(result, cfg.out)
    print(f"wrote {js} and {png}")
    return 1 if result["summary"]["crashed_runs"] else 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``campaign`` subcommand."""
    p = sub.add_parser("campaign", help="N seeded random scenarios under injected faults")
    p.add_argument("--method", required=True, choices=METHOD_CHOICES, metavar="METHOD",
                   help="the method that runs, a name of the registry (host/task/method.py)")
    p.add_argument("--runs", type=checks.arg_int(1, 1_000_000),
                   default=10, help="number of runs (default 10)")
    p.add_argument("--fault", action="append", metavar="KEY=VALUE",
                   help="a fault (docs/faults.md), repeatable; dotted keys for tables, e.g. "
                        "uart_bit_error_rate=1e-3 or uart_burst.start_s=3")
    p.add_argument("--seed", type=checks.arg_int(0, MAX_SEED),
                   default=0, help="seed of the first run (run k: seed+k)")
    p.add_argument("--jobs", type=checks.arg_int(1, 1024),
                   default=None, help="parallel runs (default: cores)")
    p.add_argument("--out", type=Path, default=Path("runs/campaign"),
                   help="folder for campaign.json, campaign.png and the run folders")
    p.add_argument("--time-limit-s", default=None,
                   type=checks.arg_number(0.0, MAX_TIME_LIMIT_S, "s", lo_open=True),
                   help="simulated seconds per run (default: the scenario's limit)")
    p.add_argument("--random-times", action="store_true",
                   help="each run draws every fault time uniformly in [0, the given time]")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help="run the runs as tasks on this Dask scheduler (mobigrasp[cluster]; "
                        "docs/campaigns.md); default: this machine's cores")
    p.add_argument("--resume", action="store_true",
                   help="keep the finished rows of OUT/campaign.rows.jsonl, run the rest")
    add_host_option(p)
    p.set_defaults(func=_run)
