"""``mobigrasp profile SCENARIO``: where the ARM9 budget goes, per host stage.

Runs the scenario in process (the modelled figures are transport-independent) with a wall-clock
timer around every host stage. It leads with the run's budget verdict (summary.json's
``budget``, host/budget_verdict.py: "fits: worst control step 8.1 ms of 20 ms"). For each
stage (frame hand-over, each detector, the task step with planning/ranging/control, protocol)
it reports the modelled ARM920T time per call (mean, p95, max),
its share of the budget that applies (a frame period of 66.7 ms for vision stages, the 20 ms
control period for control stages) and the Python wall time per call, as a table and JSON; the ARM9
load over the run is plots/arm9_load.png of the run folder. It names the stage that would miss its
budget first (highest worst-case share).

Below it, the kernels calibrated by ``mobigrasp calibrate`` that the run used (docs/budget.md;
its detectors' stages and its method's planner): each one's modelled
time now beside the time its C took as emulated ARM920T code in the last calibration (median,
p95, max), their ratio and the commit measured, and which of them would miss the frame budget
first on its own (none does unless its emulated maximum exceeds 66.7 ms). The planning stages
(the Bezier candidate evaluation of 000 and 001, per planner call) are listed after the frame
stages: a plan runs in slices of the control steps (host/planning/anytime.py), its time per
call set against the frame period.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from mobigrasp.services.profile import (
    FRAME_BUDGET_US,
    WallTimer,
    calibration_rows,
    profile_table,
)


def _print_calibration(cal: dict | None, rows: list[dict], first: str | None) -> None:
    if not rows:
        print("calibrated kernels: none this run used (or no calibration yet: run mobigrasp "
              "calibrate)")
        return
    print(f"\ncalibrated kernels (calibration of commit {cal.get('commit')}, "
          f"{cal.get('frames')} frames, line fill {cal.get('line_fill_cycles')} cycles):")
    print(f"{'kernel':<18}{'model_us':>10}{'emu_med':>10}{'emu_p95':>10}{'emu_max':>10}"
          f"{'ratio':>7}{'of 66.7ms':>11}")
    for k, r in enumerate(rows):
        if r["kind"] == "planning" and (k == 0 or rows[k - 1]["kind"] != "planning"):
            print("planning (per planner call, in slices of the control steps):")
        print(f"{r['stage']:<18}{r['modelled_us']:>10.0f}{r['emulated_median_us']:>10.0f}"
              f"{r['emulated_p95_us']:>10.0f}{r['emulated_max_us']:>10.0f}"
              f"{r['ratio']:>7.2f}{r['share_max']:>11.1%}")
    total = sum(r["emulated_max_us"] for r in rows if r["kind"] == "frame")
    print(f"emulated worst frame of all frame kernels together (sum of maxima) "
          f"{total / 1000:.1f} ms of the {FRAME_BUDGET_US / 1000:.1f} ms frame budget")
    worst = next(r for r in rows if r["stage"] == first)
    if worst["share_max"] > 1:
        print(f"would miss the {FRAME_BUDGET_US / 1000:.1f} ms frame budget first: {first} "
              f"(emulated max {worst['emulated_max_us'] / 1000:.1f} ms)")
    else:
        print(f"no kernel misses the {FRAME_BUDGET_US / 1000:.1f} ms frame budget on its own "
              f"(largest share: {first})")


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.services.run_job import BadInput, RunOptions, execute
    from mobigrasp.tools.progress import RunProgress

    timer = WallTimer()
    display = RunProgress(enabled=not args.quiet)
    try:
        summary, code = execute(RunOptions(scenario=args.scenario, seed=args.seed,
                                           transport="inproc", out=args.out, mcu=args.mcu,
                                           progress=display, timer=timer))
    except BadInput as exc:
        print(f"mobigrasp profile: {exc}", file=sys.stderr)
        return 2
    except BaseException:
        display.close()
        raise
    display.finish(summary)
    budget = summary.get("budget") or {}
    print(budget.get("verdict", "no budget verdict (the host reported no figures)"))
    rows, first = profile_table(summary.get("stages", {}), timer.wall_s)
    hdr = (f"{'stage':<22}{'calls':>7}{'mean_us':>10}{'p95_us':>9}{'max_us':>9}"
           f"{'budget':>8}{'share':>7}{'max':>7}{'py_ms':>8}")
    print(hdr)
    for r in rows:
        if "arm9_mean_us" in r:
            print(f"{r['stage']:<22}{r['calls']:>7}{r['arm9_mean_us']:>10.0f}{r['arm9_p95_us']:>9}"
                  f"{r['arm9_max_us']:>9}{r['budget_us'] // 1000:>6}ms{r['share_mean']:>7.1%}"
                  f"{r['share_max']:>7.0%}{(r['wall_mean_ms'] or 0):>8.2f}")
        else:
            print(f"{r['stage']:<22}{r['calls']:>7}{'':>50}{r['wall_mean_ms']:>8.2f}")
    print(f"ARM9 load: max {summary.get('arm9_load_max', 0):.0%}, mean "
          f"{summary.get('arm9_load_mean', 0):.0%}; frames dropped "
          f"{summary.get('frames_dropped')}, deadline misses {summary.get('deadline_misses')}")
    print(f"would miss its budget first: {first}")
    from mobigrasp.mcu_sim.simavr.profile import format_rows, profile_rows

    avr_rows = profile_rows(summary.get("mcu") or {})
    if avr_rows:  # an instruction-accurate backend measured the firmware's timing
        print()
        print(format_rows(avr_rows))
    from mobigrasp.calib.calibrate import load_last, stages_used
    from mobigrasp.cosim.run_folder import default_run_folder

    cal = load_last(args.calibration)
    cal_rows, cal_first = calibration_rows(cal, stages_used(summary.get("stages") or {},
                                                            summary.get("method")))
    _print_calibration(cal, cal_rows, cal_first)
    out = Path(args.out) if args.out else default_run_folder(summary["scenario"], summary["seed"])
    result = {"scenario": summary["scenario"], "seed": summary["seed"], "budget": budget,
              "stages": rows,
              "first_to_miss": first, "arm9_load_max": summary.get("arm9_load_max"),
              "arm9_load_mean": summary.get("arm9_load_mean"),
              "frames_dropped": summary.get("frames_dropped"),
              "deadline_misses": summary.get("deadline_misses"),
              "load_plot": str(out / "plots" / "arm9_load.png"),
              "calibrated_kernels": cal_rows, "calibration_commit": (cal or {}).get("commit"),
              "mcu_backend": args.mcu, "avr": avr_rows}
    path = args.json or out / "profile.json"
    Path(path).write_text(json.dumps(result, indent=2, sort_keys=True) + "\n")
    print(f"written {path} (load plot {result['load_plot']})")
    return 0 if code in (0, 1) else code


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``profile`` subcommand."""
    p = sub.add_parser("profile", help="ARM9 budget per host stage over a scenario run")
    p.add_argument("scenario", help="scenario file or shipped scenario name")
    p.add_argument("--seed", type=int, default=None, help="seed (default: the scenario's)")
    p.add_argument("--out", type=Path, default=None,
                   help="run folder (default runs/<scenario>-<seed>/)")
    p.add_argument("--json", type=Path, default=None,
                   help="profile JSON (default OUT/profile.json)")
    p.add_argument("--calibration", type=Path, default=None,
                   help="calibration JSON (default: the last mobigrasp calibrate)")
    p.add_argument("--mcu", default="python",
                   help="MCU backend (python, native, simavr); simavr adds the AVR's ISR, "
                        "main-loop, RX latency, load and stack worst cases with their budgets")
    p.set_defaults(func=_run)
