"""The acceptance campaign of ``mobigrasp bench loop``: seeded random scenes per method.

Run ``(method, seed)`` is scene ``seed`` of generator ``version`` (services/random_scenarios.py),
written as ``scenes/<name>.toml`` in the campaign folder and run from that file over
``transport`` into ``runs/<method>-<seed>/``, so ``mobigrasp run <scene> --transport pty``
repeats it (:func:`rerun_command`). Each row is appended to ``loop.rows.jsonl`` as its run
finishes; ``resume`` keeps the rows already there and runs only the other seeds, and without
``resume`` a folder that holds rows is refused (nothing recorded is lost).

The figures per method (:func:`aggregate`) are those of the acceptance bar (docs/cosim.md,
"Random scenes of generator v2"): graspable scenes and their successes (DONE with the object
held at the end), false claims (DONE without it), contacts with obstacles, boards without a
cylinder that ended FAILED, and the median final error. :func:`markdown` prints them as the
table of docs/cosim.md, with every run that missed its bar listed with its end state, reason,
folder and the command that re-runs it.
"""

from __future__ import annotations

import json
import logging
import os
import statistics
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from mobigrasp.cosim.run_folder import set_aside, split_rows
from mobigrasp.mcu_sim.world.scenario import MAX_SEED
from mobigrasp.services.host_programs import HOSTS, HostUnavailable, resolve
from mobigrasp.services.random_scenarios import DEFAULT_VERSION, GENERATORS
from mobigrasp.services.run_outcome import outcome
from mobigrasp.services.time_left import elapsed_left

TRANSPORTS = ("pty", "inproc")
ROWS_FILE = "loop.rows.jsonl"  # one row a line, written as each run finishes
# the bars of the acceptance (docs/cosim.md): per method, among graspable scenes
SUCCESS_BAR = 0.97
FINAL_ERROR_BAR_MM = 10.0


class CampaignInputError(ValueError):
    """A bad campaign option or a campaign folder that cannot be used: exit 2, one line."""


@dataclass(frozen=True)
class LoopCampaign:
    """``runs`` scenes per method of ``methods`` from ``seed_base``, into folder ``out``."""

    methods: tuple[str, ...]
    runs: int
    out: Path
    seed_base: int = 1000
    version: str = DEFAULT_VERSION
    transport: str = "pty"
    time_limit_s: float | None = None  # None: each scene's own limit
    jobs: int | None = None  # None: every core
    resume: bool = False
    host: str = "python"  # the host program (services/host_programs.py)

    def __post_init__(self) -> None:
        from mobigrasp.host.task import METHODS

        if not self.methods:
            raise CampaignInputError("--methods: no method given (one or more of "
                                     f"{', '.join(METHODS)})")
        for m in self.methods:
            if m not in METHODS:
                raise CampaignInputError(f"--methods: unknown method {m!r} (one of "
                                         f"{', '.join(METHODS)})")
        if len(set(self.methods)) != len(self.methods):
            raise CampaignInputError(f"--methods: a method is named twice in "
                                     f"{','.join(self.methods)}")
        if isinstance(self.runs, bool) or not isinstance(self.runs, int) or self.runs < 0:
            raise CampaignInputError(f"--runs must be an integer >= 0, got {self.runs!r}")
        if not isinstance(self.seed_base, int) or not 0 <= self.seed_base <= MAX_SEED \
                or self.seed_base + max(self.runs, 1) - 1 > MAX_SEED:
            raise CampaignInputError(f"--seed-base must be in [0, {MAX_SEED} - runs + 1], "
                                     f"got {self.seed_base!r}")
        if self.version not in GENERATORS:
            raise CampaignInputError(f"--generator must be one of {', '.join(GENERATORS)}, "
                                     f"got {self.version!r}")
        if self.transport not in TRANSPORTS:
            raise CampaignInputError(f"--transport must be one of {', '.join(TRANSPORTS)}, "
                                     f"got {self.transport!r}")
        if self.host not in HOSTS:
            raise CampaignInputError(f"--host must be one of {', '.join(HOSTS)}, got "
                                     f"{self.host!r}")
        if self.host == "arm" and self.transport != "pty":
            raise CampaignInputError("--host arm runs over the pty only (--transport pty)")
        if self.jobs is not None and (isinstance(self.jobs, bool) or self.jobs < 1):
            raise CampaignInputError(f"--jobs must be an integer >= 1, got {self.jobs!r}")
        from mobigrasp.services.run_job import BadInput, check_time_limit

        try:
            check_time_limit(self.time_limit_s)
        except BadInput as exc:
            raise CampaignInputError(str(exc)) from None

    def key(self, method: str) -> dict:
        """What a row must share with this campaign to be one of its rows."""
        return {"method": method, "generator": self.version, "transport": self.transport,
                "time_limit_s": self.time_limit_s, "host": self.host}


def scene_name(method: str, seed: int, version: str) -> str:
    """The random scene's name (its TOML's ``[scenario] name``)."""
    return f"random-{version}-{method}-{seed}" if version != "v1" else f"random-{method}-{seed}"


def jobs_of(cfg: LoopCampaign) -> list[dict]:
    """One picklable job per run, seed by seed with the methods side by side (so a campaign
    stopped early has figures for every method)."""
    out = Path(cfg.out)
    jobs = []
    for k in range(cfg.runs):
        seed = cfg.seed_base + k
        for method in cfg.methods:
            jobs.append({**cfg.key(method), "seed": seed,
                         "scene": str(out / "scenes" / f"{scene_name(method, seed, cfg.version)}"
                                                       ".toml"),
                         "folder": str(out / "runs" / f"{method}-{seed}")})
    return jobs


def write_scene(job: dict) -> Path:
    """The job's scene TOML (the generator's text) at ``job["scene"]``."""
    from mobigrasp.services.random_scenarios import random_scenario_toml

    path = Path(job["scene"])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(random_scenario_toml(job["method"], job["seed"], job["generator"]),
                    encoding="utf-8")
    return path


def run_job(job: dict) -> dict:
    """One run from its scene file (a top-level function: it runs in worker processes) ->
    its summary."""
    from mobigrasp.services.run_job import RunOptions, execute

    summary, _ = execute(RunOptions(scenario=job["scene"], transport=job["transport"],
                                    host=job["host"], out=Path(job["folder"]), progress=False,
                                    plots=False, mcap=False, time_limit_s=job["time_limit_s"]))
    return summary


def rerun_command(row: dict) -> str:
    """The one command that repeats the run of ``row`` (with its report and trace.mcap)."""
    cmd = f"mobigrasp run {row['scene']} --transport {row['transport']} --out {row['folder']}"
    if row.get("host", "python") != "python":
        cmd += f" --host {row['host']}"
    if row.get("time_limit_s") is not None:
        cmd += f" --time-limit-s {row['time_limit_s']:g}"
    return cmd


def _last_transition(folder: Path) -> str | None:
    """The reason the host gave for its last state change (trace.jsonl), if any."""
    why = None
    try:
        with (folder / "trace.jsonl").open(encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if '"ev":"state"' in line:
                    try:
                        why = json.loads(line).get("why", why)
                    except json.JSONDecodeError:
                        break
    except OSError:
        return None
    return why


def graspable(job: dict) -> bool:
    """False for a board without a cylinder (nothing to grasp: the run must end FAILED)."""
    from mobigrasp.services.random_scenarios import random_scenario_toml

    return 'kind = "double-cross"' not in random_scenario_toml(job["method"], job["seed"],
                                                                job["generator"])


def row_of(job: dict, summary: dict | None, error: str | None = None) -> dict:
    """The campaign's figures of one run from its summary (None: the run function raised)."""
    s = summary or {}
    able = graspable(job)
    row = {**{k: job[k] for k in ("method", "seed", "generator", "transport", "time_limit_s",
                                  "host", "scene", "folder")},
           "graspable": able,
           "status": s.get("status", "raised") if summary is not None else "raised",
           "success": bool(s.get("success")), "claimed_success": bool(s.get("claimed_success")),
           "grasped": bool(s.get("grasped")), "false_claim": bool(s.get("false_claim")),
           "task_state": s.get("task_state"), "end_reason": s.get("end_reason"),
           "contacts": int(s.get("contacts") or 0),
           "final_error_mm": s.get("final_error_mm"), "sim_time_s": s.get("sim_time_s"),
           "wall_time_s": s.get("wall_time_s"), "trace_sha256": s.get("trace_sha256"),
           "error": error or s.get("error")}
    row["reason"] = (row["error"] if row["error"] else
                     _last_transition(Path(job["folder"])) if row["task_state"] == "FAILED"
                     else f"time limit in {row['task_state']}"
                     if row["end_reason"] == "time_limit" else row["end_reason"])
    row["met_bar"] = met_bar(row)
    return row


def met_bar(row: dict) -> bool:
    """A graspable scene succeeds without contact; a board alone ends FAILED without
    contact; neither ever claims a grasp it does not hold."""
    if row["false_claim"] or row["contacts"] or row["status"] == "raised":
        return False
    return row["success"] if row["graspable"] else row["task_state"] == "FAILED"


DAMAGED_FILE = "loop.rows.damaged"  # lines of ROWS_FILE a resume could not read
log = logging.getLogger(__name__)


def load_rows(path: Path, cfg: LoopCampaign) -> list[dict]:
    """The rows an interrupted campaign wrote (rows of runs that raised are run again);
    CampaignInputError when a row is of another campaign. A line that is not a JSON row (torn
    by a kill, garbled) or repeats a (method, seed) is moved to DAMAGED_FILE and named in the
    log with its line: never read again, its run done again, no intact row repeated."""
    if not path.is_file():
        return []
    keys = {m: cfg.key(m) for m in cfg.methods}
    seeds = range(cfg.seed_base, cfg.seed_base + cfg.runs)
    lines, damaged = split_rows(path)
    aside = [text for _, text in damaged]
    notes = [f"line {n}: damaged row" for n, _ in damaged]
    rows: dict[tuple[str, int], dict] = {}
    for n, row in lines:
        key = keys.get(row.get("method")) if isinstance(row.get("method"), str) else None
        seed = row.get("seed")
        if key is None or any(row.get(k) != v for k, v in key.items()) \
                or isinstance(seed, bool) or not isinstance(seed, int) or seed not in seeds \
                or not isinstance(row.get("status"), str):
            raise CampaignInputError(
                f"{path}: line {n} is a row of another campaign (method, seed, generator, "
                f"transport, time limit or host differ, or a field is missing): use another --json "
                f"or the same options")
        if (row["method"], seed) in rows and rows[row["method"], seed]["status"] != "raised":
            notes.append(f"line {n}: a second row of {row['method']} seed {seed}")
            aside.append(json.dumps(row, sort_keys=True))
            continue
        rows[row["method"], seed] = row  # a run that raised and ran again: the later row
    for note in notes:
        log.warning("%s: %s set aside in %s", path, note, DAMAGED_FILE)
    if aside:
        set_aside(path, [json.dumps(r, sort_keys=True) for r in rows.values()], aside,
                  path.parent / DAMAGED_FILE)
    return [r for r in rows.values() if r["status"] != "raised"]





def progress_text(done: int, total: int, rows: list[dict], elapsed_s: float,
                  done_here: int) -> str:
    """``done/total`` is the display's; this is the rest: successes, misses, false claims,
    elapsed and the time left estimated from the runs finished in this session."""
    ok = sum(r["met_bar"] for r in rows)
    fc = sum(r["false_claim"] for r in rows)
    text = f"{ok} met the bar, {len(rows) - ok} missed"
    if fc:
        text += f" ({fc} FALSE CLAIMS)"
    return f"{text}, {elapsed_left(elapsed_s, done_here, total - done)}"


def run_campaign(cfg: LoopCampaign, run_fn: Callable[[dict], dict] | None = None,
                 progress=None, clock: Callable[[], float] = time.monotonic) -> dict:
    """Run every job not already recorded with ``run_fn`` (default :func:`run_job`);
    {"commit", "rows", "methods": {m: figures}}.

    ``progress`` (any display with ``update`` and ``close``) is told the runs done and
    :func:`progress_text`. Wall time is for that display only, never a result."""
    from mobigrasp.provenance import source_commit
    from mobigrasp.services.campaign_engines import open_engine

    commit = source_commit(untracked=False)  # of the tree that starts the runs
    out = Path(cfg.out)
    if out.exists() and not out.is_dir():
        raise CampaignInputError(f"campaign folder {out} exists and is a file")
    rows_path = out / ROWS_FILE
    if not cfg.resume and rows_path.is_file() and rows_path.stat().st_size:
        raise CampaignInputError(f"{rows_path} holds the rows of an earlier campaign: "
                                 f"--resume to continue it, or another --json")
    try:  # the host program built and holding every method before any run starts
        for method in cfg.methods:
            resolve(cfg.host, method, cfg.transport)
    except HostUnavailable as exc:
        raise CampaignInputError(str(exc)) from None
    jobs = jobs_of(cfg)
    rows = load_rows(rows_path, cfg) if cfg.resume else []
    finished = {(r["method"], r["seed"]) for r in rows}
    todo = [job for job in jobs if (job["method"], job["seed"]) not in finished]
    out.mkdir(parents=True, exist_ok=True)
    for job in todo:
        write_scene(job)
    workers = min(cfg.jobs or os.cpu_count() or 1, max(1, len(todo)))
    engine = open_engine("serial" if workers <= 1 else "processes")
    start = clock()
    if progress is not None and rows:
        progress.update(len(rows), progress_text(len(rows), len(jobs), rows, 0.0, 0))
    with rows_path.open("a", encoding="utf-8") as fh:
        results: Iterator = (engine(run_fn or run_job, todo, workers=workers) if todo
                             else iter(()))
        for done_here, (job, summary, error, _worker) in enumerate(results, 1):
            row = row_of(job, summary, error)
            fh.write(json.dumps(row, sort_keys=True) + "\n")
            fh.flush()
            rows.append(row)
            if progress is not None:
                progress.update(len(rows), progress_text(len(rows), len(jobs), rows,
                                                         clock() - start, done_here))
    if progress is not None:
        progress.close()
    order = {m: i for i, m in enumerate(cfg.methods)}
    rows.sort(key=lambda r: (order[r["method"]], r["seed"]))
    return {"commit": commit, "generator": cfg.version, "transport": cfg.transport,
            "seed_base": cfg.seed_base, "rows": rows,
            "methods": {m: aggregate([r for r in rows if r["method"] == m])
                        for m in cfg.methods}}


def aggregate(rows: list[dict]) -> dict:
    """The figures of one method's rows (keys carry units)."""
    able = [r for r in rows if r["graspable"]]
    alone = [r for r in rows if not r["graspable"]]
    errs = [r["final_error_mm"] for r in rows if r.get("final_error_mm") is not None]
    ok = sum(r["success"] for r in able)
    return {
        "runs": len(rows),
        "graspable_runs": len(able), "graspable_successes": ok,
        "graspable_success_rate": ok / len(able) if able else None,
        "board_alone_runs": len(alone),
        "board_alone_failed": sum(r["task_state"] == "FAILED" for r in alone),
        "success_rate": sum(r["success"] for r in rows) / len(rows) if rows else 0.0,
        "false_claims": sum(r["false_claim"] for r in rows),
        "contacts": sum(r["contacts"] for r in rows),
        "collisions_total": sum(r["contacts"] for r in rows),
        "crashed_runs": sum(r["status"] in ("raised", "crashed") for r in rows),
        "final_error_mm_median": statistics.median(errs) if errs else None,
        "sim_time_s_median": statistics.median(r["sim_time_s"] for r in rows
                                               if r["sim_time_s"] is not None)
        if any(r["sim_time_s"] is not None for r in rows) else None,
        "failed_seeds": [r["seed"] for r in rows if not r["met_bar"]],
        "outcomes": {k: sum(outcome(r) == k for r in rows)
                     for k in sorted({outcome(r) for r in rows})},
    }


def bar_misses(fig: dict) -> list[str]:
    """Which bars of the acceptance a method's figures miss (empty: it holds them all)."""
    misses = []
    rate = fig["graspable_success_rate"]
    if rate is not None and rate < SUCCESS_BAR:
        misses.append(f"success {fig['graspable_successes']}/{fig['graspable_runs']} "
                      f"< {SUCCESS_BAR:.0%}")
    if fig["false_claims"]:
        misses.append(f"{fig['false_claims']} false claims")
    if fig["contacts"]:
        misses.append(f"{fig['contacts']} contacts")
    if fig["board_alone_failed"] < fig["board_alone_runs"]:
        misses.append(f"board alone FAILED {fig['board_alone_failed']}/"
                      f"{fig['board_alone_runs']}")
    med = fig["final_error_mm_median"]
    if med is None or med > FINAL_ERROR_BAR_MM:
        misses.append(f"median final error {med} mm > {FINAL_ERROR_BAR_MM:g}")
    return misses


TABLE_HEAD = ("| method | commit | graspable scenes | success | false claims | contacts "
              "| board alone FAILED | median final error |\n"
              "|---|---|---|---|---|---|---|---|")


def table_row(method: str, commit: str, fig: dict) -> str:
    """One line of the docs/cosim.md table."""
    n, ok = fig["graspable_runs"], fig["graspable_successes"]
    success = f"{ok}/{n} ({100 * ok / n:.1f} %)" if n else "-"
    alone = (f"{fig['board_alone_failed']}/{fig['board_alone_runs']}"
             if fig["board_alone_runs"] else "-")
    med = fig["final_error_mm_median"]
    return (f"| {method} | {commit} | {n} | {success} | {fig['false_claims']} | "
            f"{fig['contacts']} | {alone} | {f'{med:.1f} mm' if med is not None else '-'} |")


def failure_lines(rows: list[dict]) -> list[str]:
    """Every run that missed its bar: end state, reason, folder and the re-run command."""
    lines = []
    for r in rows:
        if r["met_bar"]:
            continue
        what = "board alone" if not r["graspable"] else "graspable"
        why = _why(r)
        lines.append(f"- {r['method']} seed {r['seed']} ({what}), ended {r['task_state']} "
                     f"({r['end_reason']}), contacts {r['contacts']}: {why}\n"
                     f"  folder {r['folder']}\n  re-run: `{rerun_command(r)}`")
    return lines


def _why(row: dict) -> str:
    """The cause of a missed bar in words: the host's reason when it gave one."""
    cause, reason = outcome(row), row.get("reason")
    if cause == "false claim":
        return "false claim: DONE without the object held at the end"
    if reason and cause.startswith(f"{row['task_state']}: "):
        return str(reason)
    return f"{cause}: {reason}" if reason and str(reason) not in cause else cause


def markdown(result: dict) -> str:
    """The campaign as the markdown of docs/cosim.md: the table, then every run that missed."""
    rows = result["rows"]
    seeds = sorted({r["seed"] for r in rows})
    head = (f"`mobigrasp bench loop`: generator {result['generator']}, over "
            f"{result['transport']}, seeds {seeds[0]}-{seeds[-1]}" if seeds else
            "`mobigrasp bench loop`: no runs")
    lines = [head, "", TABLE_HEAD]
    lines += [table_row(m, result["commit"], fig) for m, fig in result["methods"].items()]
    misses = failure_lines(rows)
    lines += ["", f"Runs that missed their bar: {len(misses)}" + (":" if misses else ".")]
    lines += misses
    return "\n".join(lines) + "\n"
