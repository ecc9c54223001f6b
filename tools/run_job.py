"""`mobigrasp run` as a function: resolve the scenario, wire SIM and HOST, run, write the folder.

:func:`execute` returns the summary dict and the exit code (0 grasp succeeded, 1 task failed or
crashed, 2 bad input). The summary is always written, also when the run crashes midway (status
"crashed" with the error and what is known at that point).
"""

from __future__ import annotations

import json
import logging
import math
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

SCENARIO_DIR = Path(__file__).resolve().parents[1] / "scenarios"
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
log = logging.getLogger(__name__)


class BadInput(ValueError):
    """Unknown scenario, invalid file or bad option: exit code 2."""


def shipped_scenarios() -> list[Path]:
    """The scenario files shipped in scenarios/."""
    return sorted(SCENARIO_DIR.glob("*.toml"))


def resolve_scenario(name_or_path: str):
    """(path, Scenario) for a file path or the name of a shipped scenario; BadInput otherwise."""
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
        return p, load_scenario(p)
    except ScenarioError as exc:
        raise BadInput(str(exc)) from exc


@dataclass
class RunOptions:
    """Options of one run (validated by :func:`check_options`)."""

    scenario: str
    seed: int | None = None
    transport: str = "pty"
    mcu: str = "python"  # MCU backend (mcu_sim/backend.py): python | native
    speed: float | None = None  # None = as fast as possible ("max")
    out: Path | None = None
    # True: a carriage-return line on stderr; a callable: called as (now_us, state, wall_s)
    progress: Any = True
    quantum_us: int = 5_000
    couple_us: int = 2_500  # MCU <-> world exchange; physics still steps at 1 kHz inside
    # grants one quantum ahead: host and SIM overlap, the host's input is 5 ms later (mcu_sim/rig)
    host_lag_quanta: int = 1
    plots: bool = True
    mcap: bool = True  # trace.mcap for Foxglove (tools/mcap_out.py)
    time_limit_s: float | None = None
    scenario_obj: Any = None  # an already loaded Scenario (random campaigns); wins over name
    timer: Any = None  # wall-clock stage timer for the profiler (in-process only)
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
    check_seed(opts.seed)
    check_time_limit(opts.time_limit_s)


def check_run(opts: RunOptions) -> str:
    """What a run checks before it starts, without starting it or writing anything: the
    options, the scenario, the fault plan, and the world and host program built from them (the
    constructors a run calls). BadInput for bad input; returns a one-line description."""
    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.mcu_sim.rig_plant import WorldPlant

    _check_options(opts)
    path, scenario = resolve_scenario(opts.scenario)
    plan = _fault_plan(scenario, opts.faults)
    seed = scenario.meta.seed if opts.seed is None else int(opts.seed)
    WorldPlant(scenario, seed)
    build_host_app(host_config(scenario, opts.time_limit_s))
    n = len(plan.as_table()) if plan is not None else 0
    return (f"{path}: {scenario.meta.name} (method {scenario.meta.method}, seed {seed}, "
            f"time limit {opts.time_limit_s or scenario.meta.time_limit_s:g} s, "
            f"{len(scenario.obstacles)} obstacles, {n} fault keys): ok")


def _fault_plan(scenario, overrides):
    """The scenario's [faults] plan with the --fault overrides applied; BadInput if invalid."""
    plan = getattr(scenario, "faults", None)
    if not overrides:
        return plan
    from mobigrasp.mcu_sim.faults.plan import FaultError, parse_fault_overrides

    try:
        return parse_fault_overrides(list(overrides), base=plan)
    except FaultError as exc:
        raise BadInput(str(exc)) from exc


def host_config(scenario, time_limit_s: float | None = None) -> dict:
    """What the host program is told: the method, its parameters and the camera calibration,
    for 001 the object position P_i the paper's task is given, and how long it may search: the
    run's time limit (``time_limit_s``, default the scenario's), so a long run is not ended by a
    fixed SEARCH timeout. This is the configuration a real board would be given; nothing else
    of the ground truth."""
    cam = scenario.camera
    params = getattr(scenario, "param_overrides", None) or scenario.params
    limit_s = time_limit_s or scenario.meta.time_limit_s
    cfg = {"method": scenario.meta.method, "params": dict(params),
           "camera": {"f_px": cam.f_px, "u0_px": cam.u0_px, "v0_px": cam.v0_px},
           "task": {"timeouts_us": {"SEARCH": int(round(limit_s * 1e6))}}}
    if scenario.meta.method == "001":
        # Paper 001 plans from the start to the object position P_i, which the task is given
        # (001 §II); the host works in its odometry frame: the start pose, x forward, y left.
        r, t = scenario.robot, scenario.target
        dx, dy = t.x_m - r.x_m, t.y_m - r.y_m
        c, s = math.cos(r.heading_rad), math.sin(r.heading_rad)
        cfg["task"]["object_xy_mm"] = [round(1000 * (c * dx + s * dy)),
                                       round(1000 * (-s * dx + c * dy))]
    return cfg


def _progress(res, wall: float, now_us: int) -> None:
    rtf = now_us / 1e6 / wall if wall > 0 else 0.0
    print(f"\r  t={now_us / 1e6:7.2f} s  state={res.host_state:<14} rtf={rtf:6.1f}x ",
          end="", file=sys.stderr, flush=True)


def execute(opts: RunOptions) -> tuple[dict, int]:
    """Run one scenario; returns (summary, exit code). Raises BadInput for bad input."""
    from mobigrasp.link.registry import inproc_pair, open_transport
    from mobigrasp.tools.runner import (
        HOST_POLL_MS,
        InprocHost,
        SessionResult,
        SocketHost,
        host_argv,
        run_session,
        write_host_config,
    )

    _check_options(opts)
    if opts.scenario_obj is not None:
        path, scenario = Path(opts.scenario_obj.source), opts.scenario_obj
    else:
        path, scenario = resolve_scenario(opts.scenario)
    plan = _fault_plan(scenario, opts.faults)
    seed = scenario.meta.seed if opts.seed is None else int(opts.seed)
    name = scenario.meta.name
    from mobigrasp.tools.run_folder import RunFolderError, prepare_run_folder

    try:  # under runs/ by a sanitised name; deletes only what an earlier run wrote there
        out = prepare_run_folder(Path(opts.out) if opts.out else None, name, seed)
    except RunFolderError as exc:
        raise BadInput(str(exc)) from exc
    cfg = host_config(scenario, opts.time_limit_s)
    tmpdir = tempfile.TemporaryDirectory(prefix="mobigrasp-run-")
    early = port = None
    if opts.transport == "pty":
        # one OpenCV thread for the renderer: on a two-core machine its default pool takes the
        # host process's core in the middle of a frame (frames are the same either way)
        import cv2
        cv2.setNumThreads(1)
        # the host process boots (~0.5 s of imports) while this side imports and builds its half
        port = open_transport("pty://")
        cfg_path = write_host_config(Path(tmpdir.name) / "host.json", cfg)
        # at full speed the host polls for its grants and the rig for its DONEs instead of
        # sleeping (HOST_POLL_MS); paced (--speed N) both have time to sleep
        poll_ms = HOST_POLL_MS if opts.speed is None else 0.0
        early = SocketHost(host_argv(port.slave_path, cfg_path, poll_ms), connect=False,
                           poll_ms=poll_ms)
    try:
        from mobigrasp.host.app_factory import build_host_app
        from mobigrasp.host.lockstep_client import LockstepClient
        from mobigrasp.mcu_sim.backend import open_mcu
        from mobigrasp.mcu_sim.rig import Rig, RigConfig
        from mobigrasp.mcu_sim.rig_plant import WorldPlant
        from mobigrasp.tools.heap_tuning import keep_freed_memory
        from mobigrasp.tools.mcap_out import CameraLog
        from mobigrasp.tools.run_folder import Snapshots, TraceWriter, write_summary

        (out / "plots").mkdir(exist_ok=True)
        summary: dict[str, Any] = {
            "scenario": name, "scenario_file": str(path), "method": scenario.meta.method,
            "seed": seed, "transport": opts.transport, "mcu_backend": opts.mcu,
            "status": "starting", "success": False, "grasped": False,
        }
        write_summary(out / "summary.json", summary)
        trace = TraceWriter(out / "trace.jsonl")
        snaps = Snapshots(out / "frames")
        camera = CameraLog() if opts.mcap else None  # the frames of trace.mcap
        plant = WorldPlant(scenario, seed)
        plant.preload()  # textures built while the host process boots, not on the run's clock
        mcu = open_mcu(opts.mcu)
    except BaseException:
        if early is not None:  # not connected yet: it sees the socket go and exits
            early.close()
            port.close()
        raise
    limit_s = opts.time_limit_s or scenario.meta.time_limit_s
    trace.write({"ev": "start", "t_us": 0, "scenario": name, "method": scenario.meta.method,
                 "seed": seed, "robot": [scenario.robot.x_m, scenario.robot.y_m,
                                         scenario.robot.heading_rad],
                 "target": [scenario.target.x_m, scenario.target.y_m],
                 "obstacles": [vars(o) for o in scenario.obstacles]})
    host = early
    peer = None
    res = SessionResult()
    rig = fault_rig = None
    try:
        if early is not None:
            early.connect()
        else:
            port, peer = inproc_pair(f"run-{name}-{seed}")
            host = InprocHost(LockstepClient(build_host_app(cfg, timer=opts.timer), peer))
        # the fault wrappers carry the safety monitor, so every run gets them (an empty plan
        # injects nothing and leaves the trace unchanged) and every summary a safety block
        from mobigrasp.mcu_sim.faults.plan import FaultPlan
        from mobigrasp.mcu_sim.faults.wrappers import wrap_for_faults

        plan = plan if plan is not None else FaultPlan()
        fault_rig, rig_mcu, rig_plant, host = wrap_for_faults(plan, seed, mcu, plant, host)
        summary["faults_plan"] = plan.as_table()
        rig = Rig(rig_mcu, rig_plant, port,
                  RigConfig(quantum_us=opts.quantum_us, couple_us=opts.couple_us,
                            host_lag_quanta=opts.host_lag_quanta),
                  on_frame=snaps.on_frame if camera is None else _both(snaps.on_frame,
                                                                       camera.on_frame))
        progress = None
        if callable(opts.progress):  # a display of the caller's (tools.progress.RunProgress)
            def progress(r, wall):
                opts.progress(rig.now_us, r.host_state, wall)
        elif opts.progress:
            def progress(r, wall):
                _progress(r, wall, rig.now_us)
        summary["status"] = "running"
        keep_freed_memory()  # frame-sized arrays are reused instead of faulted in again
        run_session(rig, host, trace, result=res, time_limit_us=int(limit_s * 1e6),
                    truth=plant.truth, on_host_event=snaps.on_host_event,
                    on_quantum=lambda t: plant.sample_path(), speed=opts.speed,
                    progress=progress, stop=None if opts.after_crash_s is None else (
                        lambda: fault_rig.stop_reason(int(opts.after_crash_s * 1e6))))
        summary["status"] = "finished"
    except KeyboardInterrupt:
        summary["status"] = "interrupted"  # written below, then Ctrl-C goes on up
        raise
    except Exception as exc:
        summary["status"] = "crashed"
        summary["error"] = f"{type(exc).__name__}: {exc}"
        log.error("run crashed: %s", summary["error"])
    finally:
        if opts.progress is True:
            print("", file=sys.stderr)
        if host is not None:
            host.close()
        for t in (port, peer):
            if t is not None:
                t.close()
        tmpdir.cleanup()
        trace.close()
        error = summary.get("error")
        summary.update(_figures(res, plant, trace, snaps, limit_s))
        if error:
            summary["error"] = error
        # where the wall time went (profiling only): over the pty the SIM side blocked on the
        # host's DONEs for wall_host_s; in process it ran the host program for that long
        inner = getattr(host, "inner", host)
        summary["wall_host_s"] = round(getattr(inner, "wall_host_s", 0.0), 3)
        # lockstep traffic (profiling only; docs/cosim.md "Fewer messages"): quanta, grants
        # issued a quantum early, grants not sent (their DONE known), socket writes of grants
        summary["lockstep"] = {"quanta": rig.stats["quanta"] if rig else 0,
                               "grants_early": rig.stats["grants_early"] if rig else 0,
                               "grants_elided": getattr(inner, "elided", 0),
                               "grant_writes": getattr(inner, "messages_sent", None)}
        summary["frames_captured"] = rig.stats["frames_captured"] if rig else 0
        summary["frames_skipped_camera_off"] = rig.stats["frames_skipped"] if rig else 0
        summary["mcu"] = mcu.stats() if hasattr(mcu, "stats") else {}
        if fault_rig is not None:
            summary["faults"], summary["safety"] = fault_rig.summary()
            summary["safety"]["contacts"] = summary["collisions"]
        proto = summary["protocol"]
        proto["crc_errors"] = (proto["crc_errors"]
                               + summary["mcu"].get("parser_crc_errors", 0))
        proto["watchdog_trips"] = max(proto["watchdog_trips"],
                                      summary["mcu"].get("watchdog_trips", 0))
        write_summary(out / "summary.json", summary)
    if opts.mcap:
        try:
            from mobigrasp.tools.mcap_out import write_mcap
            from mobigrasp.tools.run_folder import read_trace

            write_mcap(out / "trace.mcap", read_trace(out / "trace.jsonl"), camera.frames,
                       summary)
        except Exception as exc:  # like the report: it must not hide the run's result
            log.error("trace.mcap of %s: %s: %s", out, type(exc).__name__, exc)
    if opts.plots:
        try:
            from mobigrasp.tools.report import write_report
            write_report(out)
        except Exception as exc:  # a plotting failure must not hide the run's result
            log.error("report of %s: %s: %s", out, type(exc).__name__, exc)
    return summary, EXIT_OK if summary["success"] else EXIT_FAILED


def _both(first, second):
    """One rig callback calling two."""
    def call(*args):
        first(*args)
        second(*args)
    return call


def _figures(res, plant, trace, snaps, limit_s: float) -> dict:
    fin = plant.final()
    hs = (res.host_stats if res else {}) or {}
    proto = hs.get("protocol", {})
    mcu_t = hs.get("mcu", {})
    end_us = res.end_us if res else 0
    wall = res.wall_s if res else 0.0
    state = res.host_state if res else "INIT"
    grasped = bool(fin["grasped"] or fin["grasps"])
    claimed = state == "DONE"
    success = claimed and bool(fin["grasped"])  # DONE with the object held at the end
    enter = res.state_enter_us if res else {}
    grasp_us = fin.get("grasp_us")
    return {
        "success": success, "grasped": grasped, "task_state": state,
        # the host ended DONE; a DONE without the object in the gripper at the end (world
        # truth) is a false claim
        "claimed_success": claimed, "false_claim": claimed and not fin["grasped"],
        "end_reason": res.reason if res else "crashed",
        "time_to_grasp_s": grasp_us / 1e6 if grasp_us is not None else None,
        "final_error_mm": fin.get("final_error_mm"),
        "collisions": int(fin["collisions"].get("obstacle", 0)),
        "collisions_target": int(fin["collisions"].get("target", 0)),
        "min_obstacle_clearance_m": fin["min_obstacle_clearance_m"],
        "path_length_m": fin["path_length_m"],
        "replans": int(hs.get("replans", 0)),
        "frames_captured": int(hs.get("frames_received", 0)),
        "frames_processed": int(hs.get("frames_processed", 0)),
        "frames_dropped": int(hs.get("frames_dropped", 0)),
        "deadline_misses": int(hs.get("deadline_misses", 0)),
        "arm9_load_max": hs.get("arm9_load_max", 0.0),
        "arm9_load_mean": hs.get("arm9_load_mean", 0.0),
        "sim_time_s": end_us / 1e6, "time_limit_s": limit_s,
        "wall_time_s": wall, "realtime_factor": (end_us / 1e6 / wall) if wall > 0 else None,
        "protocol": {"tx_frames": proto.get("tx_frames", 0),
                     "rx_frames": proto.get("rx_frames", 0),
                     "crc_errors": proto.get("crc_errors", 0),
                     "retransmits": proto.get("retransmits", 0),
                     "watchdog_trips": mcu_t.get("watchdog_trips", 0),
                     "nacks": proto.get("nacks", 0),
                     "rejected_outputs": proto.get("rejected_outputs", 0)},
        "state_durations_s": {k: v / 1e6 for k, v in
                              (res.state_durations_us if res else {}).items()},
        "state_enter_s": {k: v / 1e6 for k, v in enter.items()},
        "snapshots": snaps.written,
        "trace_sha256": trace.sha256(), "trace_lines": trace.lines,
        "host": {k: hs.get(k) for k in ("control_steps", "ticks_skipped", "frames_idle")},
        "stages": hs.get("stages", {}),
        "error": res.error if res and res.error else None,
    }


def summary_line(summary: dict, out: Path) -> str:
    """One human line for the terminal."""
    return (f"{summary['scenario']} seed {summary['seed']} over {summary['transport']}: "
            f"{'SUCCESS' if summary['success'] else 'FAILED'} ({summary.get('task_state')}, "
            f"{summary.get('end_reason')}) in {summary.get('sim_time_s', 0):.1f} s simulated, "
            f"{summary.get('wall_time_s', 0):.1f} s wall; report: {out / 'report.html'}")


def dumps(summary: dict) -> str:
    """Summary as pretty JSON."""
    return json.dumps(summary, indent=2, sort_keys=True)
