"""``mobigrasp sim`` as a function: a scenario's MCU and world, paced to wall time, served to a
host program on a pty with the camera over HTTP; the run folder at the end.

The rig and the session loop are those of ``mobigrasp run`` (cosim/rig.py, cosim/session.py):
simulated time is the rig's, the wall clock only paces it (``speed``). The host side is an
:class:`~mobigrasp.cosim.serve.external_host.ExternalHost` (whatever opens the pty slave) and the
grants' frames go to the :class:`~mobigrasp.cosim.serve.mjpeg.CameraServer`. The session ends when
the program closes the port (after it spoke), at the scenario's time limit, or when ``stop()`` says
so (the command's Ctrl-C/SIGTERM). The run folder is the one ``mobigrasp run`` writes (summary.json,
trace.jsonl; the command adds plots/ and report.html); ``grasped``, the contacts and the safety
block are judged from the world, since an external host reports no task state.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.cosim.run import SUMMARY_PERIOD_US
from mobigrasp.mcu_sim.backend import MCU_BACKENDS, open_mcu

# quantum and coupling step of `mobigrasp run` (tools/run_job.RunOptions); strict alternation:
# the rig reads exactly the bytes the ExternalHost announced
QUANTUM_US = 5_000
COUPLE_US = 2_500

class BadSimInput(ValueError):
    """Unknown scenario, bad option, camera port in use: exit code 2, one line."""


@dataclass
class SimOptions:
    """Options of one ``mobigrasp sim`` session."""

    scenario: str
    speed: float = 1.0
    mcu: str = "python"
    camera_port: int = 0  # 0: any free port
    out: Path | None = None
    seed: int | None = None
    time_limit_s: float | None = None
    # the caller's display: ``update(simulated_s, text)`` and ``close()`` (None: no progress)
    progress: Any = None
    # (path, Scenario) resolved by the caller (mobigrasp.tools.run_job.resolve_scenario)
    resolved: tuple[Path, Any] | None = None
    # the fault plan (the scenario's with --fault applied); None: the scenario's
    plan: Any = None
    # simulated time starts at the host's first valid frame (ExternalHost.wait_for_host)
    wait_host: bool = False
    tcp_port: int | None = None  # the serial line on 127.0.0.1 too (0: any free port)
    # each frame the rig captures, as (seq, capture_us, rgb) (the caller's trace.mcap)
    on_frame: Callable[[int, int, Any], None] | None = None
    # told the run folder once it is taken and ready, before the first frame
    on_folder: Callable[[Path], None] | None = None


def _claim_out(opts: SimOptions, name: str, seed: int) -> Any:
    """The run folder as ``mobigrasp run`` takes it (cosim/run_folder.py), locked, nothing
    changed yet: under runs/ by a sanitised name, the next free one when another session
    holds the default (two default sessions never share a folder)."""
    from mobigrasp.cosim.run_folder import RunFolderError, claim_run_folder

    try:
        return claim_run_folder(Path(opts.out) if opts.out else None, name, seed,
                                suffix="-sim", next_free=opts.out is None)
    except RunFolderError as exc:
        raise BadSimInput(str(exc)) from exc


def serve(opts: SimOptions, on_ready: Callable[[str, str], None],
          stop: Callable[[], str | None] | None = None) -> dict:
    """Run one session; ``on_ready(serial_path, camera_url, serial_tcp_url)`` once all are
    served (the last None without ``tcp_port``). Returns the summary (also written to the run
    folder). Raises BadSimInput for bad input."""
    from mobigrasp.cosim.serve.external_host import ExternalHost
    from mobigrasp.cosim.serve.mjpeg import CameraPortInUse, CameraServer
    from mobigrasp.cosim.serve.tcp_bridge import TcpPortInUse, TcpSerialBridge
    from mobigrasp.link.registry import open_transport

    if opts.mcu not in MCU_BACKENDS:
        raise BadSimInput(f"--mcu must be one of {', '.join(sorted(MCU_BACKENDS))}, "
                          f"got {opts.mcu!r}")
    if not (isinstance(opts.speed, float | int) and 0 < opts.speed <= 100):
        raise BadSimInput(f"--speed must be a number in (0, 100], got {opts.speed!r}")
    if opts.resolved is None:
        raise BadSimInput(f"scenario {opts.scenario!r} not resolved")
    path, scenario = opts.resolved
    seed = scenario.meta.seed if opts.seed is None else int(opts.seed)
    name = scenario.meta.name
    from mobigrasp.cosim.run_folder import RUN_FILES, RunFolderError

    folder = _claim_out(opts, name, seed)
    try:  # the port before the folder is touched: a refused session changes nothing
        camera = CameraServer(opts.camera_port)
    except (CameraPortInUse, ValueError) as exc:
        folder.abandon()
        raise BadSimInput(str(exc)) from exc
    try:
        out = folder.prepare(RUN_FILES)
    except RunFolderError as exc:
        camera.close()
        folder.abandon()
        raise BadSimInput(str(exc)) from exc
    if opts.on_folder is not None:
        opts.on_folder(out)
    transport = bridge = None
    try:
        import cv2

        cv2.setNumThreads(1)  # the host program has the other core
        transport = open_transport("pty://")
        if opts.tcp_port is not None:
            try:
                bridge = TcpSerialBridge(transport.slave_path, opts.tcp_port)
            except (TcpPortInUse, ValueError) as exc:
                raise BadSimInput(str(exc)) from exc
        host = ExternalHost(transport, on_frame=lambda rgb, t_us: camera.publish(rgb))
        return _run(opts, path, scenario, seed, out, camera, host, transport.slave_path,
                    bridge, on_ready, stop)
    finally:
        if bridge is not None:
            bridge.close()
        if transport is not None:
            transport.close()
        camera.close()
        folder.release()


def _run(opts, path, scenario, seed, out, camera, host, serial, bridge, on_ready,
         stop) -> dict:
    from mobigrasp.cosim.faulted_host import wrap_for_faults
    from mobigrasp.cosim.rig import Rig, RigConfig
    from mobigrasp.cosim.rig_plant import WorldPlant
    from mobigrasp.cosim.run_folder import TraceWriter, write_summary
    from mobigrasp.cosim.session import SessionResult, run_session
    from mobigrasp.mcu_sim.faults.plan import FaultPlan

    name = scenario.meta.name
    (out / "plots").mkdir(exist_ok=True)
    summary: dict[str, Any] = {
        "scenario": name, "scenario_file": str(path), "method": "external", "seed": seed,
        "transport": "pty (external host)", "mcu": opts.mcu, "speed": opts.speed,
        "serial": serial, "camera": camera.url, "status": "running", "success": False,
        "grasped": False, "wait_host": opts.wait_host, "sim_time_s": 0.0, "pid": os.getpid(),
    }
    if bridge is not None:
        summary["serial_tcp"] = bridge.url
    # "running" before anything else: a session killed outright leaves a summary that says it
    # did not finish, and how far it got (below, every SUMMARY_PERIOD_US simulated)
    write_summary(out / "summary.json", summary)
    trace = TraceWriter(out / "trace.jsonl")
    plant = WorldPlant(scenario, seed)
    plant.preload()
    mcu = open_mcu(opts.mcu)
    plan = opts.plan or getattr(scenario, "faults", None) or FaultPlan()
    fault_rig, rig_mcu, rig_plant, _ = wrap_for_faults(plan, seed, mcu, plant, None)
    summary["faults_plan"] = plan.as_table()
    rig = Rig(rig_mcu, rig_plant, host.port,
              RigConfig(quantum_us=QUANTUM_US, couple_us=COUPLE_US, host_lag_quanta=0),
              on_frame=opts.on_frame)
    limit_s = opts.time_limit_s or scenario.meta.time_limit_s
    trace.write({"ev": "start", "t_us": 0, "scenario": name, "method": "external", "seed": seed,
                 "robot": [scenario.robot.x_m, scenario.robot.y_m, scenario.robot.heading_rad],
                 "target": [scenario.target.x_m, scenario.target.y_m],
                 "obstacles": [vars(o) for o in scenario.obstacles]})

    def why_stop() -> str | None:
        if host.host_closed:
            return "host_closed"
        return stop() if stop is not None else None

    display = opts.progress

    def progress(res, wall):
        if display is not None:
            display.update(round(rig.now_us / 1e6, 1),
                           f"from host {host.bytes_from_host} B, to host {host.bytes_to_host} B, "
                           f"frames {camera.frames_published}")

    res = SessionResult()
    on_ready(serial, camera.url, None if bridge is None else bridge.url)
    next_summary_us = SUMMARY_PERIOD_US

    def on_quantum(t_us: int) -> None:
        nonlocal next_summary_us
        plant.sample_path()
        if t_us >= next_summary_us:
            write_summary(out / "summary.json", {**summary, "sim_time_s": t_us / 1e6})
            next_summary_us = t_us - t_us % SUMMARY_PERIOD_US + SUMMARY_PERIOD_US

    try:
        if opts.wait_host:
            # the camera shows the robot at t = 0 while the clock waits for the host
            camera.publish(plant.capture(0))
            wall0 = time.perf_counter()
            res.reason = host.wait_for_host(why_stop) or "running"
            summary["host_waited_s"] = round(time.perf_counter() - wall0, 3)
            if res.reason != "running":  # stopped before the host came: the clock never ran
                trace.write({"ev": "end", "t_us": 0, "reason": res.reason,
                             "host_state": "EXTERNAL"})
        if res.reason == "running":
            run_session(rig, host, trace, result=res, time_limit_us=int(limit_s * 1e6),
                        truth=plant.truth, on_quantum=on_quantum,
                        speed=opts.speed, progress=progress, stop=why_stop)
        summary["status"] = "finished"
    except Exception as exc:
        summary["status"] = "crashed"
        summary["error"] = f"{type(exc).__name__}: {exc}"
        print(f"\nsim crashed: {summary['error']}", file=sys.stderr)
    finally:
        # the streams end now, not after the report: a client's blocking read returns
        camera.close()
        if display is not None:
            display.close()
        trace.close()
        summary.update(_figures(res, plant, rig, host, camera, trace, limit_s))
        summary["mcu_stats"] = mcu.stats()
        summary["faults"], summary["safety"] = fault_rig.summary()
        if bridge is not None:
            summary["line"]["tcp"] = bridge.stats()
        write_summary(out / "summary.json", summary)
    summary["run_folder"] = str(out)
    return summary


def _figures(res, plant, rig, host, camera, trace, limit_s: float) -> dict:
    from mobigrasp.cosim.summary import world_figures

    world = world_figures(plant.final())
    wall = res.wall_s
    return {
        # an external host claims nothing mobigrasp can read: success is the world's grasp
        "success": world["grasped"], **world, "task_state": "external",
        "end_reason": res.reason,
        "sim_time_s": res.end_us / 1e6, "time_limit_s": limit_s, "wall_time_s": wall,
        "realtime_factor": (res.end_us / 1e6 / wall) if wall > 0 else None,
        "line": host.stats(),
        "camera_frames": {"captured": rig.stats["frames_captured"],
                          "published": camera.frames_published,
                          "stream_parts_sent": camera.parts_sent},
        "trace_sha256": trace.sha256(), "trace_lines": trace.lines,
        "trace_dropped_events": trace.dropped_events,
        "error": res.error,
    }
