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

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.mcu_sim.backend import MCU_BACKENDS

# quantum and coupling step of `mobigrasp run` (services/run_job.RunOptions); strict alternation:
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
    # (path, Scenario) resolved by the caller (mobigrasp.services.run_job.resolve_scenario)
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
    # the frames raw on a Unix socket there too (cosim/serve/raw_frames.py); None: not served
    raw_frames: Path | None = None


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
    from mobigrasp.cosim.serve.raw_frames import RawFrameServer, RawFramesPathInUse
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
    raw = None
    try:
        if opts.raw_frames is not None:
            raw = RawFrameServer(opts.raw_frames)
        out = folder.prepare(RUN_FILES)
    except (RunFolderError, RawFramesPathInUse) as exc:
        if raw is not None:
            raw.close()
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
        def on_frame(rgb: Any, t_us: int) -> None:
            camera.publish(rgb)
            if raw is not None:
                raw.publish(rgb, t_us)

        host = ExternalHost(transport, on_frame=on_frame)
        return _run(opts, path, scenario, seed, out, camera, host, transport.slave_path,
                    bridge, on_ready, stop, raw)
    finally:
        if raw is not None:
            raw.close()
        if bridge is not None:
            bridge.close()
        if transport is not None:
            transport.close()
        camera.close()
        folder.release()


def _run(opts, path, scenario, seed, out, camera, host, serial, bridge, on_ready,
         stop, raw) -> dict:
    from mobigrasp.cosim.rig import RigConfig
    from mobigrasp.cosim.session import SessionResult
    from mobigrasp.cosim.sim_side import SimSide
    from mobigrasp.mcu_sim.faults.plan import FaultPlan
    from mobigrasp.mcu_sim.world.scenario import run_time_limit_s

    plan = opts.plan or getattr(scenario, "faults", None) or FaultPlan()
    sim = SimSide(scenario, seed, out, path, "pty (external host)", plan, opts.mcu,
                  on_frame=opts.on_frame, external_host=True)
    sim.summary.update(speed=opts.speed, serial=serial, camera=camera.url,
                       wait_host=opts.wait_host)
    if bridge is not None:
        sim.summary["serial_tcp"] = bridge.url
    if raw is not None:
        sim.summary["raw_frames"] = raw.url
    # "running" before anything else: a session killed outright leaves a summary that says it
    # did not finish, and how far it got (SimSide.drive: every SUMMARY_PERIOD_US simulated)
    sim.summary["status"] = "running"
    sim.write_running(0)
    limit_s = run_time_limit_s(scenario, opts.time_limit_s)
    display = opts.progress

    def why_stop() -> str | None:
        if host.host_closed:
            return "host_closed"
        return stop() if stop is not None else None

    def progress(res, wall):
        if display is not None:
            display.update(round(sim.rig.now_us / 1e6, 1),
                           f"from host {host.bytes_from_host} B, to host {host.bytes_to_host} B, "
                           f"frames {camera.frames_published}")

    res = SessionResult()
    try:
        with sim.noting_the_end():
            # the external host is not wrapped for faults: it is the user's program
            sim.wire(RigConfig(quantum_us=QUANTUM_US, couple_us=COUPLE_US, host_lag_quanta=0),
                     None, host.port)
            on_ready(serial, camera.url, None if bridge is None else bridge.url)
            if opts.wait_host:
                # the camera shows the robot at t = 0 while the clock waits for the host
                camera.publish(sim.plant.capture(0))
                wall0 = time.perf_counter()
                res.reason = host.wait_for_host(why_stop) or "running"
                sim.summary["host_waited_s"] = round(time.perf_counter() - wall0, 3)
            if not opts.wait_host or res.reason == "running":
                sim.drive(res, host, limit_s, speed=opts.speed, progress=progress,
                          stop=why_stop)
            else:  # stopped before the host came: the clock never ran
                sim.trace.write({"ev": "end", "t_us": 0, "reason": res.reason,
                                 "host_state": "EXTERNAL"})
                sim.summary["status"] = "finished"
    finally:
        # the streams end now, not after the report: a client's blocking read returns
        camera.close()
        if raw is not None:
            raw.close()
        if display is not None:
            display.close()
        line = host.stats()
        if bridge is not None:
            line["tcp"] = bridge.stats()
        rig = sim.rig
        sim.finish(res, None, limit_s, extra={
            "line": line,
            "camera_frames": {"captured": rig.stats["frames_captured"] if rig else 0,
                              "published": camera.frames_published,
                              "stream_parts_sent": camera.parts_sent,
                              "raw_published": raw.frames_published if raw else 0,
                              "raw_sent": raw.messages_sent if raw else 0}})
    sim.summary["run_folder"] = str(out)
    return sim.summary

