"""`mobigrasp run` as a function: check the options, resolve the scenario, prepare the run
folder, run it (mobigrasp.cosim.run), write trace.mcap and the report.

:func:`execute` returns the summary dict and the exit code (0 grasp succeeded, 1 task failed or
crashed, 2 bad input). The summary is always written, also when the run crashes midway (status
"crashed" with the error and what is known at that point).
"""

from __future__ import annotations

import json
import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.cosim.run import RunSpec, run_scenario
from mobigrasp.mcu_sim.world.scenario import run_time_limit_s
from mobigrasp.resources import data_dir
from mobigrasp.services.host_programs import HOSTS, HostProgram, HostUnavailable, resolve

SCENARIO_DIR = data_dir("mobigrasp.scenarios")
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
log = logging.getLogger(__name__)


class BadInput(ValueError):
    """Unknown scenario, invalid file or bad option: exit code 2."""


def shipped_scenarios() -> list[Path]:
    """The shipped scenario files (package data of ``mobigrasp.scenarios``)."""
    return sorted(SCENARIO_DIR.glob("*.toml"))


def resolve_scenario(name_or_path: str):
    """(path, Scenario) for a file path or the name of a shipped scenario; BadInput otherwise."""
    from mobigrasp.host.task import REGISTRY
    from mobigrasp.mcu_sim.world.scenario import ScenarioError, load_scenario

    p = Path(name_or_path)
    if not p.exists():
        cand = SCENARIO_DIR / f"{name_or_path}.toml"
        if not cand.exists():
            names = ", ".join(s.stem for s in shipped_scenarios())
            raise BadInput(f"unknown scenario {name_or_path!r}: not a file and not one of "
                           f"the shipped scenarios ({names})")
        p = cand
    try:
        return p, load_scenario(p, methods=REGISTRY)
    except ScenarioError as exc:
        raise BadInput(str(exc)) from exc


@dataclass
class RunOptions:
    """Options of one run (validated by :func:`check_options`)."""

    scenario: str
    seed: int | None = None
    transport: str = "pty"
    mcu: str = "python"  # MCU backend (mcu_sim/backend.py): python | native
    host: str = "python"  # the host program (services/host_programs.py): python | c | arm
    # the method the host program runs instead of the scenario's (the world stays the
    # scenario's): "idle" runs the host program around no task, in every host (tests, bench)
    host_method: str | None = None
    speed: float | None = None  # None = as fast as possible ("max")
    out: Path | None = None
    # a display (tools.progress.RunProgress), called as (now_us, state, wall_s); None: none
    progress: Any = None
    quantum_us: int = 5_000
    couple_us: int = 2_500  # MCU <-> world exchange; physics still steps at 1 kHz inside
    # grants one quantum ahead: host and SIM overlap, the host's input is 5 ms later (mcu_sim/rig)
    host_lag_quanta: int = 1
    plots: bool = True
    mcap: bool = True  # trace.mcap for Foxglove (services/mcap_out.py)
    time_limit_s: float | None = None
    scenario_obj: Any = None  # an already loaded Scenario (random campaigns); wins over name
    timer: Any = None  # wall-clock stage timer for the profiler (in-process only)
    # the Python host program's inputs and outputs (HostApp's recorder; in-process only)
    recorder: Any = None
    faults: tuple = ()  # --fault KEY=VALUE overrides of the scenario's [faults] (docs/faults.md)
    # simulated seconds a run goes on after a host crash (the MCU's safe stop is judged in it);
    # None: on to the time limit
    after_crash_s: float | None = 2.0


def parse_speed(text: str) -> float | None:
    """``max`` -> None, else a positive finite factor; BadInput otherwise."""
    if text == "max":
        return None
    try:
        v = float(text)
    except ValueError as exc:
        raise BadInput(f"--speed must be a positive number or 'max', got {text!r}") from exc
    if not math.isfinite(v) or v <= 0:
        raise BadInput(f"--speed must be a positive number or 'max', got {text!r}")
    return v


def check_seed(seed: int | None) -> int | None:
    """``--seed``: None (the scenario's) or an integer in [0, 2^64 - 1]; BadInput otherwise."""
    from mobigrasp.mcu_sim.world.scenario import MAX_SEED

    if seed is not None and not 0 <= seed <= MAX_SEED:
        raise BadInput(f"--seed must be an integer in [0, {MAX_SEED}], got {seed}")
    return seed


def check_time_limit(limit_s: float | None) -> float | None:
    """``--time-limit-s``: None (the scenario's) or a number of simulated seconds in
    (0, MAX_TIME_LIMIT_S] (docs/conventions.md); BadInput otherwise (also for inf and NaN)."""
    from mobigrasp.mcu_sim.world.scenario import MAX_TIME_LIMIT_S

    if limit_s is not None and not 0 < limit_s <= MAX_TIME_LIMIT_S:
        raise BadInput(f"--time-limit-s must be a number of seconds in (0, "
                       f"{MAX_TIME_LIMIT_S:g}], got {limit_s}")
    return limit_s


def _check_options(opts: RunOptions) -> None:
    if opts.transport not in ("pty", "inproc"):
        raise BadInput(f"--transport must be 'pty' or 'inproc', got {opts.transport!r}")
    if opts.host_lag_quanta not in (0, 1) or isinstance(opts.host_lag_quanta, bool):
        raise BadInput(f"--host-lag-quanta must be 0 or 1, got {opts.host_lag_quanta!r}")
    from mobigrasp.mcu_sim.backend import MCU_BACKENDS
    if opts.mcu not in MCU_BACKENDS:
        raise BadInput(f"--mcu must be one of {', '.join(sorted(MCU_BACKENDS))}, got {opts.mcu!r}")
    if opts.host not in HOSTS:
        raise BadInput(f"--host must be one of {', '.join(HOSTS)}, got {opts.host!r}")
    check_seed(opts.seed)
    check_time_limit(opts.time_limit_s)


def host_program(opts: RunOptions, method: str) -> HostProgram:
    """The run's host program, built and checked to have ``method``; BadInput otherwise."""
    try:
        return resolve(opts.host, method, opts.transport)
    except HostUnavailable as exc:
        raise BadInput(str(exc)) from exc


def check_run(opts: RunOptions) -> str:
    """What a run checks before it starts, without starting it or writing anything: the
    options, the scenario, the fault plan, the run folder (taken and checked as the run takes
    it, then let go), and the world and host program built from them (the constructors a run
    calls). BadInput for bad input; returns a one-line description."""
    from mobigrasp.cosim.rig_plant import WorldPlant
    from mobigrasp.host.app_factory import build_host_app

    _check_options(opts)
    path, scenario = resolve_scenario(opts.scenario)
    plan = fault_plan(scenario, opts.faults)
    seed = scenario.meta.seed if opts.seed is None else int(opts.seed)
    _claim_folder(opts, scenario.meta.name, seed, check_only=True)
    WorldPlant(scenario, seed)
    cfg = host_config(scenario, opts.time_limit_s, opts.host_method)
    if opts.host == "python":
        build_host_app(cfg)
    else:
        host_program(opts, cfg["method"])
    n = len(plan.as_table()) if plan is not None else 0
    return (f"{path}: {scenario.meta.name} (method {scenario.meta.method}, seed {seed}, "
            f"host {opts.host}, time limit {run_time_limit_s(scenario, opts.time_limit_s):g} s, "
            f"{len(scenario.obstacles)} obstacles, {n} fault keys): ok")


def fault_plan(scenario, overrides):
    """The scenario's [faults] plan with the --fault overrides applied; BadInput if invalid."""
    plan = getattr(scenario, "faults", None)
    if not overrides:
        return plan
    from mobigrasp.mcu_sim.faults.plan import FaultError, parse_fault_overrides

    try:
        return parse_fault_overrides(list(overrides), base=plan)
    except FaultError as exc:
        raise BadInput(str(exc)) from exc


def host_config(scenario, time_limit_s: float | None = None,
                host_method: str | None = None) -> dict:
    """What the host program is told: the method, its parameters and the camera calibration,
    for 001 the object position P_i the paper's task is given, and how long it may search: the
    run's time limit (``time_limit_s``, default the scenario's), so a long run is not ended by a
    fixed SEARCH timeout. This is the configuration a real board would be given; nothing else
    of the ground truth. ``host_method`` (RunOptions.host_method): that method alone, nothing
    else."""
    if host_method is not None:
        return {"method": host_method}
    cam = scenario.camera
    params = getattr(scenario, "param_overrides", None) or scenario.params
    limit_s = run_time_limit_s(scenario, time_limit_s)
    cfg = {"method": scenario.meta.method, "params": dict(params),
           "camera": {"f_px": cam.f_px, "u0_px": cam.u0_px, "v0_px": cam.v0_px},
           "task": {"timeouts_us": {"SEARCH": int(round(limit_s * 1e6))}}}
    from mobigrasp.host.task import method_rules

    if method_rules(scenario.meta.method).object_given:
        # Paper 001 plans from the start to the object position P_i, which the task is given
        # (001 §II); the host works in its odometry frame: the start pose, x forward, y left.
        r, t = scenario.robot, scenario.target
        dx, dy = t.x_m - r.x_m, t.y_m - r.y_m
        c, s = math.cos(r.heading_rad), math.sin(r.heading_rad)
        cfg["task"]["object_xy_mm"] = [round(1000 * (c * dx + s * dy)),
                                       round(1000 * (-s * dx + c * dy))]
    return cfg


def execute(opts: RunOptions) -> tuple[dict, int]:
    """Run one scenario; returns (summary, exit code). Raises BadInput for bad input."""
    _check_options(opts)
    if opts.scenario_obj is not None:
        path, scenario = Path(opts.scenario_obj.source), opts.scenario_obj
    else:
        path, scenario = resolve_scenario(opts.scenario)
    plan = fault_plan(scenario, opts.faults)
    seed = scenario.meta.seed if opts.seed is None else int(opts.seed)
    name = scenario.meta.name
    cfg = host_config(scenario, opts.time_limit_s, opts.host_method)
    program = host_program(opts, cfg["method"])  # built and checked before the folder is made
    folder, out = _claim_folder(opts, name, seed)
    try:
        summary = _run_in(opts, out, path, scenario, plan, seed, cfg, program)
    finally:
        folder.release()
    return summary, EXIT_OK if summary["success"] else EXIT_FAILED


def _claim_folder(opts: RunOptions, name: str, seed: int, check_only: bool = False
                  ) -> tuple[Any, Path]:
    """The run folder, under runs/ by a sanitised name or ``--out``, locked for this run and
    prepared: an earlier run's listed files removed, nothing else (cosim/run_folder.py);
    (the held folder, its path). ``check_only``: taken and checked the same way, then let go
    with nothing changed (``run --check``). BadInput when it cannot be used."""
    # (the run folder's module needs numpy and cv2, which the base install has not: imported
    # once a run is certain to need them)
    from mobigrasp.cosim.run_folder import RUN_FILES, RunFolderError, claim_run_folder

    try:
        folder = claim_run_folder(Path(opts.out) if opts.out else None, name, seed)
    except RunFolderError as exc:
        raise BadInput(str(exc)) from exc
    try:
        if check_only:
            folder.check(RUN_FILES)
            return folder, folder.path
        return folder, folder.prepare(RUN_FILES)
    except RunFolderError as exc:
        folder.abandon()
        raise BadInput(str(exc)) from exc
    finally:
        if check_only:
            folder.abandon()


def _run_in(opts: RunOptions, out: Path, path: Path, scenario: Any, plan: Any, seed: int,
            cfg: dict, program: HostProgram) -> dict:
    """The run into its prepared folder with the host program's configuration ``cfg``, then
    its trace.mcap's end and its report."""
    camera = None
    if opts.mcap:
        from mobigrasp.services.mcap_out import McapLog

        camera = McapLog(out / "trace.mcap",  # written as the run goes
                         info=mcap_info(scenario, seed, opts.mcu, opts.transport, program.name),
                         camera=mcap_camera(scenario))
    spec = RunSpec(scenario=scenario, scenario_file=path, seed=seed, plan=plan, out=out,
                   host_config=cfg, time_limit_s=run_time_limit_s(scenario, opts.time_limit_s),
                   inproc_client=program.inproc and program.inproc(cfg, opts.timer,
                                                                      opts.recorder),
                   transport=opts.transport, host=program.name, host_argv=program.argv,
                   mcu=opts.mcu, speed=opts.speed, progress=opts.progress,
                   quantum_us=opts.quantum_us, couple_us=opts.couple_us,
                   host_lag_quanta=opts.host_lag_quanta, after_crash_s=opts.after_crash_s,
                   on_frame=None if camera is None else camera.on_frame,
                   on_mcu_bytes=None if camera is None else camera.on_mcu_bytes)
    try:
        summary = run_scenario(spec)
    finally:
        if camera is not None:
            _finish_mcap(camera, out)
    if opts.plots:
        write_report_logged(out)
    return summary


def write_report_logged(folder: Path) -> None:
    """plots/ and report.html of a finished run folder; a failure is logged, never hides the
    run's result."""
    try:
        # matplotlib is imported after the run, not before the host process is started
        # (docs/cosim.md, "Start-up")
        from mobigrasp.services.report import write_report

        write_report(folder)
    except Exception as exc:
        log.error("report of %s: %s: %s", folder, type(exc).__name__, exc)


def mcap_info(scenario: Any, seed: int, mcu: str, transport: str,
              host: str = "python") -> dict[str, str]:
    """trace.mcap's metadata record: what a reader needs to know which run it holds."""
    from mobigrasp.provenance import source_commit

    return {"scenario": scenario.meta.name, "seed": str(seed), "method": scenario.meta.method,
            "mcu_backend": mcu, "transport": transport, "host": host,
            "commit": source_commit()}


def mcap_camera(scenario: Any) -> dict:
    """The scenario's pinhole camera for trace.mcap's /camera/calibration."""
    from mobigrasp.mcu_sim.world.camera import Intrinsics

    cam, size = scenario.camera, Intrinsics()
    return {"f_px": cam.f_px, "u0_px": cam.u0_px, "v0_px": cam.v0_px, "width": size.width,
            "height": size.height}


def _finish_mcap(camera: Any, out: Path) -> None:
    """trace.mcap's last trace lines, the summary's totals and its index."""
    try:
        camera.finish(json.loads((out / "summary.json").read_text()))
    except Exception as exc:  # like the report: it must not hide the run's result
        log.error("trace.mcap of %s: %s: %s", out, type(exc).__name__, exc)


def summary_line(summary: dict, out: Path) -> str:
    """One human line for the terminal."""
    host = summary.get("host", "python")
    over = summary["transport"] + ("" if host == "python" else f", host {host}")
    return (f"{summary['scenario']} seed {summary['seed']} over {over}: "
            f"{'SUCCESS' if summary['success'] else 'FAILED'} ({summary.get('task_state')}, "
            f"{summary.get('end_reason')}) in {summary.get('sim_time_s', 0):.1f} s simulated, "
            f"{summary.get('wall_time_s', 0):.1f} s wall; report: {out / 'report.html'}")


def dumps(summary: dict) -> str:
    """Summary as pretty JSON."""
    return json.dumps(summary, indent=2, sort_keys=True)
