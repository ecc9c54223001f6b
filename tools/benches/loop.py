"""``mobigrasp bench loop``: closed-loop speed over the pty and in process, and a random campaign.

Real-time factor = simulated seconds / wall seconds of paper000-exp1 (capped at ``--rtf-limit-s``
simulated seconds) over the pty (two processes) and in process, the median of ``--rtf-repeats``
runs each; the baseline measured in the same run is the strict alternation (``_lag0``: the host
is granted each quantum only when the rig is at its start), and ``speedup_*_vs_lag0`` the ratio.
The campaign runs ``--runs`` seeded random scenarios per method (tools/random_scenarios.py),
over the pty by default (``--transport``; the trace is the same over either), and reports the
success rate, collisions and the median final error (targets, docs/cosim.md: success >= 95 %,
zero collisions, median final_error_mm <= 10; real-time factor over the pty >= 10).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
from pathlib import Path

NAME = "loop"
HELP = "closed-loop real-time factor (pty, inproc) and success rate of random scenarios"


def add_arguments(parser) -> None:
    """Options of the loop bench."""
    parser.add_argument("--runs", type=int, default=3,
                        help="random scenarios per method (0: the real-time factor only)")
    parser.add_argument("--methods", default="000,001,002",
                        help="comma-separated methods to run (default 000,001,002)")
    parser.add_argument("--seed-base", type=int, default=1000,
                        help="seed of the first run (default 1000)")
    parser.add_argument("--jobs", type=int, default=None, help="parallel runs (default: cores)")
    parser.add_argument("--generator", default="v2", choices=("v1", "v2"),
                        help="random scenario generator version (tools/random_scenarios.py)")
    parser.add_argument("--transport", default="pty", choices=("pty", "inproc"),
                        help="transport of the random runs: pty (two processes, default) or "
                             "inproc; the trace is the same over either")
    parser.add_argument("--time-limit-s", type=float, default=None,
                        help="simulated seconds per random run (default: the scenario's)")
    parser.add_argument("--rtf-limit-s", type=float, default=20.0,
                        help="simulated seconds of the real-time-factor runs")
    parser.add_argument("--rtf-repeats", type=int, default=3,
                        help="runs per real-time-factor figure (the median is reported)")


def progress_enabled() -> bool:
    """Progress lines on stderr when it is a terminal."""
    return sys.stderr.isatty()


def _one(opts) -> dict:
    from mobigrasp.tools.run_job import execute

    summary, _ = execute(opts)
    return summary


def _random_run(method: str, seed: int, folder: Path, version: str = "v2",
                transport: str = "pty", time_limit_s: float | None = None) -> dict:
    """One random scenario over ``transport`` (a top-level function: it runs in worker
    processes); ``graspable`` is False for a board without a cylinder."""
    from mobigrasp.tools.random_scenarios import random_scenario
    from mobigrasp.tools.run_job import RunOptions

    sc = random_scenario(method, seed, version)
    summary = _one(RunOptions(scenario=sc.meta.name, scenario_obj=sc, seed=seed,
                              transport=transport, out=folder / f"{method}-{seed}",
                              progress=False, plots=False, time_limit_s=time_limit_s))
    summary["graspable"] = sc.target.kind != "double-cross"
    return summary


def campaign(methods: list[str], runs: int, seed_base: int, folder: Path,
             progress: bool = True, jobs: int | None = None, version: str = "v2",
             transport: str = "pty", time_limit_s: float | None = None) -> dict:
    """Run ``runs`` random scenarios per method over ``transport``, ``jobs`` at a time (default: the
    number of cores); figures per method and overall. Results do not depend on ``jobs``."""
    from concurrent.futures import ProcessPoolExecutor

    jobs = jobs or os.cpu_count() or 1
    out: dict = {}
    for method in methods:
        seeds = [seed_base + k for k in range(runs)]
        if jobs > 1 and runs > 1:
            with ProcessPoolExecutor(max_workers=jobs) as pool:
                rows = list(pool.map(_random_run, [method] * runs, seeds, [folder] * runs,
                                     [version] * runs, [transport] * runs,
                                     [time_limit_s] * runs))
        else:
            rows = [_random_run(method, seed, folder, version, transport, time_limit_s)
                    for seed in seeds]
        for s in rows:
            if progress:
                print(f"  {method} seed {s['seed']}: {'ok ' if s['success'] else 'FAIL'} "
                      f"{s.get('task_state')}{' FALSE CLAIM' if s.get('false_claim') else ''}"
                      f" t={s.get('sim_time_s', 0):.1f}s "
                      f"err={s.get('final_error_mm')} mm", file=sys.stderr)
        errs = [r["final_error_mm"] for r in rows if r.get("final_error_mm") is not None]
        able = [r for r in rows if r.get("graspable", True)]
        alone = [r for r in rows if not r.get("graspable", True)]
        out[method] = {
            "runs": len(rows),
            "graspable_runs": len(able),
            "graspable_success_rate": sum(r["success"] for r in able) / len(able) if able
            else None,
            # a board without a cylinder must end FAILED (nothing to grasp), never DONE
            "board_alone_runs": len(alone),
            "board_alone_failed": sum(r.get("task_state") == "FAILED" for r in alone),
            "success_rate": sum(r["success"] for r in rows) / len(rows) if rows else 0.0,
            "collisions_total": sum(r.get("collisions", 0) for r in rows),
            "false_claims": sum(bool(r.get("false_claim")) for r in rows),
            "final_error_mm_median": statistics.median(errs) if errs else None,
            "sim_time_s_median": statistics.median(r["sim_time_s"] for r in rows) if rows
            else None,
            "failed_seeds": [r["seed"] for r in rows if not r["success"]],
        }
    return out


def run(args) -> dict:
    """Figures of the loop bench (keys carry units)."""
    from mobigrasp.tools.run_job import RunOptions

    methods = [m for m in args.methods.split(",") if m]
    if args.rtf_repeats < 1:
        raise SystemExit("bench loop: --rtf-repeats must be at least 1")
    results: dict = {}
    with tempfile.TemporaryDirectory(prefix="mobigrasp-bench-") as tmp:
        folder = Path(tmp)
        sha = {}
        # the baseline, measured in the same run: strict alternation (host_lag_quanta = 0), where
        # host and rig take turns at every control tick instead of overlapping. The four
        # configurations take turns run by run: this machine's speed drifts by ~10 % over
        # minutes, and runs in blocks would put that drift into the ratios.
        configs = [(lag, tag, transport) for lag, tag in ((1, ""), (0, "_lag0"))
                   for transport in ("pty", "inproc")]
        rows: dict = {c: [] for c in configs}
        for k in range(args.rtf_repeats):
            for lag, tag, transport in configs:
                s = _one(RunOptions(scenario="paper000-exp1", transport=transport,
                                    out=folder / f"rtf-{transport}{tag}-{k}", progress=False,
                                    plots=False, time_limit_s=args.rtf_limit_s,
                                    host_lag_quanta=lag))
                rows[lag, tag, transport].append(s)
                sha.setdefault((lag, transport), set()).add(s.get("trace_sha256"))
        for (_lag, tag, transport), runs in rows.items():
            wall = statistics.median(r["wall_time_s"] for r in runs)
            sim_s = runs[0]["sim_time_s"]
            results[f"realtime_factor_{transport}{tag}"] = round(sim_s / wall, 3)
            results[f"realtime_factor_{transport}{tag}_runs"] = [
                round(r["realtime_factor"], 3) for r in runs]
            results[f"sim_s_{transport}{tag}"] = sim_s
            results[f"wall_s_{transport}{tag}"] = round(wall, 3)
            # over the pty: the SIM side blocked on the host; in process: running the host
            results[f"wall_host_s_{transport}{tag}"] = round(
                statistics.median(r.get("wall_host_s", 0.0) for r in runs), 3)
            if progress_enabled():
                print(f"  rtf {transport}{tag or ' (lag 1)'}: "
                      f"{results[f'realtime_factor_{transport}{tag}_runs']}", file=sys.stderr)
        for transport in ("pty", "inproc"):
            rtf = results[f"realtime_factor_{transport}"]
            results[f"speedup_{transport}_vs_lag0"] = round(
                rtf / results[f"realtime_factor_{transport}_lag0"], 3)
        results["trace_equal_pty_inproc"] = all(
            len(sha[lag, "pty"] | sha[lag, "inproc"]) == 1 for lag in (0, 1))
        if args.runs <= 0:  # real-time factor only: no campaign figures to report
            return results
        camp = campaign(methods, args.runs, args.seed_base, folder / "campaign", jobs=args.jobs,
                        version=getattr(args, "generator", "v2"), transport=args.transport,
                        time_limit_s=args.time_limit_s)
    results["campaign"] = camp
    total = sum(v["runs"] for v in camp.values())
    results["success_rate"] = (sum(v["success_rate"] * v["runs"] for v in camp.values()) / total
                               if total else 0.0)
    results["collisions_total"] = sum(v["collisions_total"] for v in camp.values())
    results["false_claims"] = sum(v["false_claims"] for v in camp.values())
    return results
