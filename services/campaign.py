"""Fault campaigns (docs/faults.md): N seeded random scenarios under a fault plan, run over the
cores.

Run ``k`` uses seed ``seed + k``: the scenario is ``services.random_scenarios`` (target 0.5-3 m away
at any bearing, random heading; obstacles for 001; a moving target for 002) plus the ``[faults]``
section of the plan, and the rig seeds every injector from the same run seed, so one run can be
repeated alone with ``mobigrasp run``. :func:`run_one` is the one adapter to the closed loop
(``mobigrasp.services.run_job.execute`` in process); anything with the same signature can
replace it.

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
from typing import Any, Protocol

from mobigrasp.cosim.run_folder import (
    CAMPAIGN_MARKER,
    OwnedFolder,
    record_written,
    set_aside,
    split_rows,
)
from mobigrasp.host.task import METHODS, REGISTRY
from mobigrasp.mcu_sim import checks
from mobigrasp.mcu_sim.faults.plan import FaultPlan, MotorFail, SonarFail, Window, parse_faults
from mobigrasp.mcu_sim.world.scenario import MAX_SEED, MAX_TIME_LIMIT_S, Scenario, loads_scenario
from mobigrasp.services.host_programs import HOSTS


class ProgressSink(Protocol):
    """What a campaign tells of its progress (the CLI's ``Progress`` bar is one)."""

    def update(self, done: float, text: str = "") -> None: ...

    def close(self) -> None: ...


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
    # the host program (services/host_programs.py); in process but for arm (qemu-arm: the pty)
    host: str = "python"

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ValueError(f"--method must be one of {', '.join(METHODS)}, got "
                             f"{self.method!r}")
        if self.host not in HOSTS:
            raise ValueError(f"--host must be one of {', '.join(HOSTS)}, got {self.host!r}")
        if isinstance(self.runs, bool) or not isinstance(self.runs, int) or self.runs < 1:
            raise ValueError(f"--runs must be an integer >= 1, got {self.runs!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"--seed must be an integer >= 0, got {self.seed!r}")
        if self.jobs is not None and (not isinstance(self.jobs, int) or self.jobs < 1):
            raise ValueError(f"--jobs must be an integer >= 1, got {self.jobs!r}")
        if self.scheduler is not None:
            from mobigrasp.services.campaign_engines import check_scheduler

            check_scheduler(self.scheduler)
        if self.seed + self.runs - 1 > MAX_SEED:
            raise ValueError(f"--seed + --runs - 1 must be <= {MAX_SEED}, got "
                             f"{self.seed + self.runs - 1}")
        if self.time_limit_s is not None and not 0 < self.time_limit_s <= MAX_TIME_LIMIT_S:
            raise ValueError(f"--time-limit-s must be in (0, {MAX_TIME_LIMIT_S:g}] s, got "
                             f"{self.time_limit_s!r}")


def check_host(cfg: CampaignConfig) -> None:
    """The host program built and holding the method, before any run starts (ValueError with
    one line otherwise: a missing tool, a method not in the C host yet)."""
    from mobigrasp.services.host_programs import resolve

    resolve(cfg.host, cfg.method, "pty" if cfg.host == "arm" else "inproc")


def scenario_toml(method: str, seed: int, plan: FaultPlan) -> str:
    """TOML of random scenario ``seed`` of ``method`` with the plan's ``[faults]``."""
    from mobigrasp.services.random_scenarios import random_scenario_toml

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
                     "time_limit_s": cfg.time_limit_s, "host": cfg.host})
    return jobs


def run_one(job: dict) -> dict:
    """The adapter: one closed-loop run in process (services.run_job.execute) -> its summary."""
    from mobigrasp.services.run_job import RunOptions, execute

    sc = make_scenario(job["method"], job["seed"], parse_faults(job["faults"], "campaign"))
    host = job.get("host", "python")
    summary, _ = execute(RunOptions(scenario=sc.meta.name, scenario_obj=sc, seed=job["seed"],
                                    transport="pty" if host == "arm" else "inproc",
                                    host=host, out=Path(job["out"]), progress=False,
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
        "host": job.get("host", "python"),
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
DAMAGED_FILE = "campaign.rows.damaged"  # lines of ROWS_FILE a resume could not read
CAMPAIGN_FILES = ("campaign.json", ROWS_FILE, "campaign.png", DAMAGED_FILE)
_COUNT_MAX = 2**63 - 1
_LIST_MAX = 1_000_000
_OUTCOMES = (None, "recovered", "failed_cleanly", "stuck")


class RowError(checks.BadValue):
    """A row of campaign.rows.jsonl that is JSON but not a row (exit code 2)."""


def _count(v, where, key):
    return checks.integer(v, where, key, 0, _COUNT_MAX, error=RowError)


def _flag(v, where, key):
    if not isinstance(v, bool):
        checks.fail(where, key, "true or false", v, RowError)


def _ms_list(v, where, key):
    if not isinstance(v, list) or len(v) > _LIST_MAX:
        checks.fail(where, key, f"a list of at most {_LIST_MAX} numbers", v, RowError)
    for k, x in enumerate(v):
        checks.number(x, where, f"{key}[{k}]", 0.0, None, "ms", RowError)


def _text_or_none(v, where, key):
    if v is not None and not isinstance(v, str):
        checks.fail(where, key, "a string or null", v, RowError)


# the fields aggregate() and the resume read, and their checks
ROW_FIELDS = {
    "seed": lambda v, w, k: checks.integer(v, w, k, 0, MAX_SEED, error=RowError),
    "method": lambda v, w, k: v in METHODS or checks.fail(w, k, f"one of {METHODS}", v, RowError),
    "faults": lambda v, w, k: isinstance(v, dict) or checks.fail(w, k, "a table", v, RowError),
    "success": _flag, "false_claim": _flag, "safety_monitored": _flag, "faults_applied": _flag,
    "status": lambda v, w, k: isinstance(v, str) or checks.fail(w, k, "a string", v, RowError),
    "collisions": _count, "unsafe_actuations": _count, "watchdog_trips": _count,
    "retransmits": _count, "crc_errors": _count, "unrecovered": _count, "late_stops": _count,
    "stop_latency_ms": _ms_list, "recovery_ms": _ms_list,
    "fault_outcome": lambda v, w, k: v in _OUTCOMES or checks.fail(
        w, k, f"one of {_OUTCOMES}", v, RowError),
    "task_state": _text_or_none, "error": _text_or_none,
}


def check_row(row: dict, where: str) -> dict:
    """``row`` when every field of :data:`ROW_FIELDS` is there and of its type; RowError
    naming ``where`` (file and line) and the field otherwise."""
    for key, check in ROW_FIELDS.items():
        if key not in row:
            checks.fail(where, key, "a field of a campaign row (missing)", error=RowError)
        check(row[key], where, key)
    return row


def load_rows(path: Path, jobs: list[dict]) -> tuple[list[dict], list[str]]:
    """The rows an interrupted campaign wrote, by seed, and a note (file and line) for every
    line set aside: damaged (not a JSON row: torn by a kill, garbled) or a repeat of a seed
    already read. RowError when a line is JSON but not a row; ValueError when a row is not of
    this campaign (another method, other faults or a seed outside it). The rows file is
    rewritten with the rows kept; the lines set aside go to DAMAGED_FILE beside it."""
    by_seed = {job["seed"]: job for job in jobs}
    if not path.is_file():
        return [], []
    lines, damaged = split_rows(path)
    rows: dict[int, dict] = {}
    notes = [f"{path}: line {n}: damaged row set aside in {DAMAGED_FILE} (not a JSON row: "
             f"{checks.shown(text)})" for n, text in damaged]
    aside = [text for _, text in damaged]
    for n, row in lines:
        check_row(row, f"{path}: line {n}")
        job = by_seed.get(row["seed"])
        if job is None or row["method"] != job["method"] or row["faults"] != job["faults"] \
                or row.get("host", "python") != job.get("host", "python"):
            raise ValueError(f"{path}: line {n} is a row of another campaign (seed "
                             f"{row['seed']}, method or faults differ): use another --out or "
                             f"run without --resume")
        if row["seed"] in rows:
            notes.append(f"{path}: line {n}: a second row of seed {row['seed']} set aside in "
                         f"{DAMAGED_FILE}")
            aside.append(json.dumps(row, sort_keys=True))
            continue
        rows[row["seed"]] = row
    if aside:
        record_written(path.parent, DAMAGED_FILE, marker=CAMPAIGN_MARKER)
        set_aside(path, [json.dumps(r, sort_keys=True) for r in rows.values()], aside,
                  path.parent / DAMAGED_FILE)
    return [rows[s] for s in sorted(rows)], notes


def claim_out(cfg: CampaignConfig) -> OwnedFolder:
    """Lock ``cfg.out`` for this campaign and make it ready: refused (RunFolderError, exit 2,
    nothing changed) when another process holds it or it holds files and is not a campaign's;
    the previous campaign's files are replaced, except with ``cfg.resume``."""
    folder = OwnedFolder.take(Path(cfg.out), CAMPAIGN_MARKER, "campaign")
    try:
        folder.prepare(CAMPAIGN_FILES, remove_previous=not cfg.resume)
    except ValueError:
        folder.release()
        raise
    return folder


def run_campaign(cfg: CampaignConfig, run_fn: Callable[[dict], dict] = run_one,
                 progress: ProgressSink | None = None, folder: OwnedFolder | None = None) -> dict:
    """Run every job; {"summary": ..., "rows": [...], "set_aside": [notes]} (rows by seed).

    Where: on the Dask cluster at ``cfg.scheduler``, else a local process pool when more than
    one job runs at once, else this process (services.campaign_engines). Each row is appended to
    ``out/campaign.rows.jsonl`` as its run finishes, with the worker that ran it; with
    ``cfg.resume`` the rows already there are kept and only the other seeds run. ``folder``:
    ``cfg.out`` already taken (:func:`claim_out`); None: taken and let go here.
    ``progress`` is told the runs done and how many succeeded."""
    if folder is None:
        with claim_out(cfg) as held:
            return run_campaign(cfg, run_fn, progress, held)
    from mobigrasp.services.campaign_engines import open_engine

    jobs = jobs_of(cfg)
    out = Path(cfg.out)
    rows_path = out / ROWS_FILE
    rows, notes = load_rows(rows_path, jobs) if cfg.resume else ([], [])
    finished = {r["seed"] for r in rows}
    todo = [job for job in jobs if job["seed"] not in finished]
    workers = min(cfg.jobs or os.cpu_count() or 1, max(1, len(todo)))
    name = "dask" if cfg.scheduler else "serial" if workers <= 1 else "processes"
    engine = open_engine(name)
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
    return {"summary": aggregate(rows, cfg), "rows": rows, "set_aside": notes}


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
    """campaign.json and campaign.png (services.plots.campaign) in ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    js = out / "campaign.json"
    js.write_text(json.dumps(result, indent=2, sort_keys=True))
    from mobigrasp.services.plots import campaign as campaign_plot

    png = out / campaign_plot(result, out)
    return js, png
