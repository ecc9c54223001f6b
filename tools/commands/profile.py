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
import time
from pathlib import Path

from mobigrasp.host.budget_verdict import FRAME_BUDGET_US, stage_budget_us


class WallTimer:
    """``timer(stage, fn, *args)`` hook for HostApp: calls fn and records its wall time."""

    def __init__(self) -> None:
        self.wall_s: dict[str, list[float]] = {}

    def __call__(self, stage, fn, *args):
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            self.wall_s.setdefault(stage, []).append(time.perf_counter() - t0)


def profile_table(stages: dict, wall_s: dict) -> tuple[list[dict], str | None]:
    """Rows per stage and the name of the stage with the highest worst-case budget share."""
    rows = []
    for name, st in sorted(stages.items()):
        budget = stage_budget_us(name)
        wall = wall_s.get(name, [])
        rows.append({
            "stage": name, "calls": st["calls"], "arm9_mean_us": round(st["mean_us"], 1),
            "arm9_p95_us": st["p95_us"], "arm9_max_us": st["max_us"], "budget_us": budget,
            "share_mean": round(st["mean_us"] / budget, 4),
            "share_max": round(st["max_us"] / budget, 4),
            "wall_mean_ms": round(1e3 * sum(wall) / len(wall), 3) if wall else None,
        })
    for name, wall in sorted(wall_s.items()):  # wall-only stages (the task step's Python)
        if name not in stages:
            rows.append({"stage": name + " (python)", "calls": len(wall),
                         "wall_mean_ms": round(1e3 * sum(wall) / len(wall), 3)})
    ranked = [r for r in rows if "share_max" in r and r["calls"]]
    first = max(ranked, key=lambda r: r["share_max"])["stage"] if ranked else None
    return rows, first


def calibration_rows(cal: dict | None, used: set[str] | None = None
                     ) -> tuple[list[dict], str | None]:
    """Per calibrated kernel (those in ``used`` when given: the run's): modelled µs now (at
    the calibrated frame size), the emulated figures of the last calibration and the ratio;
    and the kernel whose emulated maximum takes the largest share of the frame budget."""
    if not cal or not isinstance(cal.get("stages"), dict):
        return [], None
    from mobigrasp.calib.calibrate import PLANNING_STAGES, modelled_us

    h, w = cal.get("frame_shape") or (0, 0)  # none: a corpus of planner calls only
    rows = []
    for name, st in sorted(cal["stages"].items(), key=lambda kv: (kv[0] in PLANNING_STAGES,
                                                                   kv[0])):
        if used is not None and name not in used:
            continue
        try:
            if not h:
                raise KeyError(name)
            mod = modelled_us(name, h, w)
        except KeyError:  # a detector's stage: its cost depends on the frame, as calibrated
            mod = st.get("modelled_median_us")
            if not isinstance(mod, int | float):
                continue
        emu = st["emulated_median_us"]
        rows.append({"stage": name, "kind": "planning" if name in PLANNING_STAGES else "frame",
                     "modelled_us": round(mod, 1), "emulated_median_us": emu,
                     "emulated_p95_us": st["emulated_p95_us"],
                     "emulated_max_us": st["emulated_max_us"],
                     "ratio": round(mod / emu, 3) if emu else None,
                     "share_max": round(st["emulated_max_us"] / FRAME_BUDGET_US, 4)})
    first = max(rows, key=lambda r: r["share_max"])["stage"] if rows else None
    return rows, first


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
    from mobigrasp.tools.progress import RunProgress
    from mobigrasp.tools.run_job import BadInput, RunOptions, execute

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
