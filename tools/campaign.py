"""Fault campaigns (docs/faults.md): N seeded random scenarios under a fault plan, run over the
cores.

Run ``k`` uses seed ``seed + k``: the scenario is ``tools.random_scenarios`` (target 0.5-3 m away
at any bearing, random heading; obstacles for 001; a moving target for 002) plus the ``[faults]``
section of the plan, and the rig seeds every injector from the same run seed, so one run can be
repeated alone with ``mobigrasp run``. :func:`run_one` is the one adapter to the closed loop
(``mobigrasp.tools.run_job.execute`` in process); anything with the same signature can replace it.

Aggregated figures: success rate, unsafe actuations (the run's safety monitor: servo pulses out of
the joint table, motion during a watchdog stop, late stops after host silence, commands the MCU
had to clamp; plus collisions), watchdog trips, retransmits, stop latencies and recovery times.
"""

from __future__ import annotations

import json
import os
import random
import statistics
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from mobigrasp.cosim.run_folder import json_lines
from mobigrasp.host.task import METHODS, REGISTRY
from mobigrasp.mcu_sim.faults.plan import FaultPlan, MotorFail, SonarFail, Window, parse_faults
from mobigrasp.mcu_sim.world.scenario import MAX_SEED, MAX_TIME_LIMIT_S, Scenario, loads_scenario
from mobigrasp.tools.progress import Progress


@dataclass(frozen=True)
class CampaignConfig:
    """What to run: ``runs`` scenarios of ``method`` from seed ``seed`` under ``faults``."""

    method: str
    runs: int
    faults: FaultPlan = field(default_factory=FaultPlan)
    seed: int = 0
    jobs: int | None = None  # None: every core
    out: Path = Path("runs/campaign")
    time_limit_s: float | None = None  # None: the scenario's own limit
    random_times: bool = False  # each run draws every fault time uniformly in [0, given time]
    scheduler: str | None = None  # tcp://HOST:PORT of a Dask scheduler; None: this machine
    resume: bool = False  # keep the rows of out/campaign.rows.jsonl, run only the other seeds

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ValueError(f"--method must be one of {', '.join(METHODS)}, got "
                             f"{self.method!r}")
        if isinstance(self.runs, bool) or not isinstance(self.runs, int) or self.runs < 1:
            raise ValueError(f"--runs must be an integer >= 1, got {self.runs!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"--seed must be an integer >= 0, got {self.seed!r}")
        if self.jobs is not None and (not isinstance(self.jobs, int) or self.jobs < 1):
            raise ValueError(f"--jobs must be an integer >= 1, got {self.jobs!r}")
        if self.scheduler is not None:
            from mobigrasp.tools.campaign_engines import check_scheduler

            check_scheduler(self.scheduler)
        if self.seed + self.runs - 1 > MAX_SEED:
            raise ValueError(f"--seed + --runs - 1 must be <= {MAX_SEED}, got "
                             f"{self.seed + self.runs - 1}")
        if self.time_limit_s is not None and not 0 < self.time_limit_s <= MAX_TIME_LIMIT_S:
            raise ValueError(f"--time-limit-s must be in (0, {MAX_TIME_LIMIT_S:g}] s, got "
                             f"{self.time_limit_s!r}")


def scenario_toml(method: str, seed: int, plan: FaultPlan) -> str:
    """TOML of random scenario ``seed`` of ``method`` with the plan's ``[faults]``."""
    from mobigrasp.tools.random_scenarios import random_scenario_toml

    return random_scenario_toml(method, seed, "v1") + "\n" + plan.to_toml()  # its own faults


def make_scenario(method: str, seed: int, plan: FaultPlan) -> Scenario:
    """The validated scenario of one campaign run."""
    return loads_scenario(scenario_toml(method, seed, plan), f"campaign-{method}-{seed}",
                          methods=REGISTRY)


def randomize_times(plan: FaultPlan, seed: int) -> FaultPlan:
    """The plan with every fault time drawn uniformly in [0, its value], seeded by ``seed``
    ("a host crash at any time": ``--fault host_crash_at_s=60 --random-times``)."""
    rng = random.Random(f"fault-times-{seed}")

    def draw(t_s: float) -> float:
        return round(rng.uniform(0.0, t_s), 3)

    changes: dict = {}
    if plan.host_crash_at_s is not None:
        changes["host_crash_at_s"] = draw(plan.host_crash_at_s)
    if plan.mcu_reset_at_s is not None:
        changes["mcu_reset_at_s"] = draw(plan.mcu_reset_at_s)
    for key in ("uart_burst", "host_stall"):
        w = getattr(plan, key)
        if w is not None:
            changes[key] = Window(draw(w.start_s), w.duration_s)
    if plan.motor_fail is not None:
        changes["motor_fail"] = MotorFail(plan.motor_fail.wheel, draw(plan.motor_fail.at_s))
    if plan.sonar_fail is not None:
        changes["sonar_fail"] = SonarFail(plan.sonar_fail.index, draw(plan.sonar_fail.at_s))
    return replace(plan, **changes)


def jobs_of(cfg: CampaignConfig) -> list[dict]:
    """One picklable job per run."""
    jobs = []
    for k in range(cfg.runs):
        seed = cfg.seed + k
        plan = randomize_times(cfg.faults, seed) if cfg.random_times else cfg.faults
        jobs.append({"method": cfg.method, "seed": seed, "faults": plan.as_table(),
                     "out": str(Path(cfg.out) / "runs" / f"{cfg.method}-{seed}"),
                     "time_limit_s": cfg.time_limit_s})
    return jobs


def run_one(job: dict) -> dict:
    """The adapter: one closed-loop run in process (tools.run_job.execute) -> its summary."""
    from mobigrasp.tools.run_job import RunOptions, execute

    sc = make_scenario(job["method"], job["seed"], parse_faults(job["faults"], "campaign"))
    summary, _ = execute(RunOptions(scenario=sc.meta.name, scenario_obj=sc, seed=job["seed"],
                                    transport="inproc", out=Path(job["out"]), progress=False,
                                    plots=False, time_limit_s=job["time_limit_s"]))
    return summary


def row_of(job: dict, summary: dict | None, error: str | None = None) -> dict:
    """The campaign's figures of one run, from its summary (None: the run function raised)."""
    s = summary or {}
    safety = s.get("safety")
    proto = s.get("protocol") or {}
    collisions = int(s.get("contacts") or 0)
    monitored = isinstance(safety, dict)
    unsafe = (int(safety.get("unsafe_actuations", 0)) if monitored else 0) + collisions
    wd = safety.get("watchdog_trips") if monitored else None
    row = {
        "seed": job["seed"], "method": job.get("method"), "faults": job.get("faults", {}),
        "success": bool(s.get("success")), "trace_sha256": s.get("trace_sha256"),
        "false_claim": bool(s.get("false_claim")),
        "status": s.get("status", "crashed") if summary is not None else "crashed",
        "task_state": s.get("task_state"), "sim_time_s": s.get("sim_time_s"),
        "collisions": collisions, "unsafe_actuations": unsafe, "safety_monitored": monitored,
        "watchdog_trips": int(wd if wd is not None else proto.get("watchdog_trips", 0)),
        "retransmits": int(proto.get("retransmits", 0)),
        "crc_errors": int(proto.get("crc_errors", 0)),
        "stop_latency_ms": list(safety.get("stop_latency_ms", [])) if monitored else [],
        "recovery_ms": list(safety.get("recovery_ms", [])) if monitored else [],
        "unrecovered": int(safety.get("unrecovered", 0)) if monitored else 0,
        "late_stops": int(safety.get("late_stops", 0)) if monitored else 0,
        "faults_applied": "faults" in s,
        "error": error or s.get("error"),
    }
    row["fault_outcome"] = _fault_outcome(row)
    return row


def _fault_outcome(row: dict) -> str | None:
    """For runs with a fault to recover from (stall, burst, MCU reset): "recovered" (the link
    came back and the task then succeeded), "failed_cleanly" (the task ended FAILED without
    unsafe actuation) or "stuck" (anything else: the run hit its time limit in the middle of
    the task, or reported DONE without the object). A link that came back is not enough: after
    an MCU reset the host once resumed with frozen odometry and turned in place for 90 s."""
    if not row["recovery_ms"] and not row["unrecovered"]:
        return None
    if not row["unrecovered"] and row["success"]:
        return "recovered"
    if row["task_state"] == "FAILED" and row["unsafe_actuations"] == 0:
        return "failed_cleanly"
    return "stuck"


def _stats(values: list[float]) -> dict:
    if not values:
        return {"n": 0, "median": None, "max": None}
    return {"n": len(values), "median": statistics.median(values), "max": max(values)}


def aggregate(rows: list[dict], cfg: CampaignConfig | None = None) -> dict:
    """Campaign figures over the rows of :func:`row_of`."""
    n = len(rows)
    stops = [v for r in rows for v in r["stop_latency_ms"]]
    recov = [v for r in rows for v in r["recovery_ms"]]
    out: dict[str, Any] = {
        "runs": n,
        "successes": sum(r["success"] for r in rows),
        "success_rate": sum(r["success"] for r in rows) / n if n else 0.0,
        "crashed_runs": sum(r["status"] == "crashed" for r in rows),
        "unsafe_actuations": sum(r["unsafe_actuations"] for r in rows),
        "runs_with_unsafe_actuation": sum(r["unsafe_actuations"] > 0 for r in rows),
        "collisions": sum(r["collisions"] for r in rows),
        "false_claims": sum(r["false_claim"] for r in rows),
        "watchdog_trips": sum(r["watchdog_trips"] for r in rows),
        "retransmits": sum(r["retransmits"] for r in rows),
        "crc_errors": sum(r["crc_errors"] for r in rows),
        "stop_latency_ms": _stats(stops),
        # silences that hit a robot in motion (a latency of 0: the wheels were already still)
        "stops_while_moving": sum(v > 0 for v in stops),
        "recovery_ms": _stats(recov),
        "unrecovered_faults": sum(r["unrecovered"] for r in rows),
        "late_stops": sum(r["late_stops"] for r in rows),
        "fault_outcomes": {k: sum(r["fault_outcome"] == k for r in rows)
                           for k in ("recovered", "failed_cleanly", "stuck")},
        "runs_safety_monitored": sum(r["safety_monitored"] for r in rows),
        "runs_faults_applied": sum(r["faults_applied"] for r in rows),
        "failed_seeds": sorted(r["seed"] for r in rows if not r["success"]),
    }
    if cfg is not None:
        out.update({"method": cfg.method, "seed": cfg.seed, "faults": cfg.faults.as_table(),
                    "random_times": cfg.random_times})
    return out


ROWS_FILE = "campaign.rows.jsonl"  # one row a line, written as each run finishes


def load_rows(path: Path, jobs: list[dict]) -> list[dict]:
    """The rows an interrupted campaign wrote (a torn last line is dropped); ValueError when a
    row is not of this campaign (another method, other faults or a seed outside it)."""
    by_seed = {job["seed"]: job for job in jobs}
    rows: dict[int, dict] = {}
    if not path.is_file():
        return []
    for n, row in json_lines(path):
        job = by_seed.get(row.get("seed")) if isinstance(row, dict) else None
        if job is None or row.get("method") != job["method"] \
                or row.get("faults") != job["faults"]:
            raise ValueError(f"{path}: line {n} is a row of another campaign (seed "
                             f"{row.get('seed') if isinstance(row, dict) else '?'}, method "
                             f"or faults differ): use another --out or run without --resume")
        rows[row["seed"]] = row
    return [rows[s] for s in sorted(rows)]


def run_campaign(cfg: CampaignConfig, run_fn: Callable[[dict], dict] = run_one,
                 progress: Progress | None = None) -> dict:
    """Run every job; {"summary": ..., "rows": [...]} (rows by seed).

    Where: on the Dask cluster at ``cfg.scheduler``, else a local process pool when more than
    one job runs at once, else this process (tools.campaign_engines). Each row is appended to
    ``out/campaign.rows.jsonl`` as its run finishes, with the worker that ran it; with
    ``cfg.resume`` the rows already there are kept and only the other seeds run.
    ``progress`` (tools.progress) is told the runs done and how many succeeded."""
    from mobigrasp.tools.campaign_engines import open_engine

    jobs = jobs_of(cfg)
    out = Path(cfg.out)
    rows_path = out / ROWS_FILE
    rows = load_rows(rows_path, jobs) if cfg.resume else []
    finished = {r["seed"] for r in rows}
    todo = [job for job in jobs if job["seed"] not in finished]
    workers = min(cfg.jobs or os.cpu_count() or 1, max(1, len(todo)))
    name = "dask" if cfg.scheduler else "serial" if workers <= 1 else "processes"
    engine = open_engine(name)
    out.mkdir(parents=True, exist_ok=True)
    with rows_path.open("a" if cfg.resume else "w", encoding="utf-8") as fh:
        if progress is not None and rows:
            ok = sum(r["success"] for r in rows)
            progress.update(len(rows), f"{ok} ok, {len(rows) - ok} not (resumed)")
        for job, summary, error, worker in engine(run_fn, todo, workers=workers,
                                                  scheduler=cfg.scheduler):
            row = {**row_of(job, summary, error), "worker": worker}
            fh.write(json.dumps(row, sort_keys=True) + "\n")
            fh.flush()
            rows.append(row)
            if progress is not None:
                ok = sum(r["success"] for r in rows)
                progress.update(len(rows), f"{ok} ok, {len(rows) - ok} not")
    if progress is not None:
        progress.close()
    rows.sort(key=lambda r: r["seed"])
    return {"summary": aggregate(rows, cfg), "rows": rows}


def format_table(agg: dict) -> str:
    """The campaign figures as a small text table."""
    def fmt(st: dict) -> str:
        if not st["n"]:
            return "-"
        return f"median {st['median']:.1f}, max {st['max']:.1f} (n={st['n']})"

    lines = [
        f"method {agg.get('method', '?')}, {agg['runs']} runs from seed {agg.get('seed', '?')}, "
        f"faults: {json.dumps(agg.get('faults', {}), sort_keys=True) or '{}'}"
        f"{' (times random per run)' if agg.get('random_times') else ''}",
        f"  {'success rate':<28} {agg['success_rate'] * 100:6.1f} %  "
        f"({agg['successes']}/{agg['runs']}, {agg['crashed_runs']} crashed)",
        f"  {'unsafe actuations':<28} {agg['unsafe_actuations']:6d}    "
        f"(in {agg['runs_with_unsafe_actuation']} runs; collisions {agg['collisions']})",
        f"  {'false claims of success':<28} {agg['false_claims']:6d}",
        f"  {'watchdog trips':<28} {agg['watchdog_trips']:6d}",
        f"  {'retransmits':<28} {agg['retransmits']:6d}    (CRC errors {agg['crc_errors']})",
        f"  {'wheel stop latency ms':<28} {fmt(agg['stop_latency_ms'])}"
        f"  late stops {agg['late_stops']}, {agg['stops_while_moving']} from motion",
        f"  {'recovery time ms':<28} {fmt(agg['recovery_ms'])}"
        f"  unrecovered {agg['unrecovered_faults']}",
        f"  {'runs after a fault':<28} " + ", ".join(
            f"{k.replace('_', ' ')} {v}" for k, v in agg["fault_outcomes"].items()),
    ]
    if agg["runs_safety_monitored"] < agg["runs"]:
        lines.append(f"  NOTE: only {agg['runs_safety_monitored']}/{agg['runs']} runs carried a "
                     f"safety monitor; unsafe actuations of the others are collisions only")
    if agg.get("faults") and agg["runs_faults_applied"] < agg["runs"]:
        lines.append(f"  NOTE: the rig applied the faults in only {agg['runs_faults_applied']}/"
                     f"{agg['runs']} runs (summary without a 'faults' block)")
    return "\n".join(lines)


def write_outputs(result: dict, out: Path) -> tuple[Path, Path]:
    """campaign.json and campaign.png (tools.plots.campaign) in ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    js = out / "campaign.json"
    js.write_text(json.dumps(result, indent=2, sort_keys=True))
    from mobigrasp.tools.plots import campaign as campaign_plot

    png = out / campaign_plot(result, out)
    return js, png
