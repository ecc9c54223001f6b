"""One run's wiring: host end, MCU, plant, fault wrappers and rig, the session, the run folder.

:func:`run_scenario` is what ``mobigrasp run`` does once its options are checked and its run
folder prepared (mobigrasp.services.run_job). The summary is always written, also when the run
crashes midway (status "crashed" with the error and what is known at that point); while it
runs, summary.json says "running" with the simulated time reached, at least every simulated
``SUMMARY_PERIOD_US`` (cosim/sim_side.py), so a run killed outright leaves a summary that says
how far it got.
SIGTERM ends a run as Ctrl-C does (status "interrupted", everything released).
"""

from __future__ import annotations

import signal
import tempfile
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.cosim import leftovers
from mobigrasp.cosim.hosts import HOST_POLL_MS, InprocHost, SocketHost, host_argv, write_host_config
from mobigrasp.cosim.session import SessionResult
from mobigrasp.link.registry import inproc_pair, open_transport


@dataclass(frozen=True)
class RunSpec:
    """One run, its options checked (mobigrasp.services.run_job.RunOptions) and resolved."""

    scenario: Any  # mobigrasp.mcu_sim.world.scenario.Scenario
    scenario_file: Path
    seed: int
    plan: Any  # mobigrasp.mcu_sim.faults.plan.FaultPlan
    out: Path  # the run folder, prepared and empty
    host_config: dict
    time_limit_s: float
    # builds the host program's lockstep client on an in-process serial end (transport inproc)
    inproc_client: Callable[[Any], Any] | None = None
    transport: str = "pty"
    host: str = "python"  # the host program (services/host_programs.py): python | c | arm
    # its command line over the pty (port, config file, poll ms; without --lockstep)
    host_argv: Callable[[str, Path, float], list[str]] = host_argv
    mcu: str = "python"  # MCU backend (mobigrasp.mcu_sim.backend)
    speed: float | None = None
    # a display (tools.progress.RunProgress), called as (now_us, state, wall_s); None: none
    progress: Any = None
    quantum_us: int = 5_000
    couple_us: int = 2_500
    host_lag_quanta: int = 1
    after_crash_s: float | None = 2.0
    on_frame: Callable[[int, int, Any], None] | None = None  # each captured frame, as well
    # (t_us, bytes) of each write of the MCU to the host's line (SimSide), as well
    on_mcu_bytes: Callable[[int, bytes], None] | None = None


def _terminated(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


@contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """SIGTERM raises KeyboardInterrupt while a run goes on (so its folder is finished and its
    processes, shared memory and temporary folders released, as after Ctrl-C)."""
    if threading.current_thread() is not threading.main_thread():
        yield  # signals reach the main thread only
        return
    before = signal.signal(signal.SIGTERM, _terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, before)


def run_scenario(spec: RunSpec) -> dict:
    """Run ``spec``; the summary (also written to ``spec.out / "summary.json"``)."""
    with _sigterm_as_interrupt():
        return _run(spec)


def _run(spec: RunSpec) -> dict:
    leftovers.sweep()  # what runs killed outright left behind (recorded as theirs)
    scenario, seed, out = spec.scenario, spec.seed, spec.out
    name = scenario.meta.name
    tmpdir = leftovers.temp_dir("run")
    early = port = None
    try:
        if spec.transport == "pty":
            # one OpenCV thread for the renderer: on a two-core machine its default pool takes
            # the host process's core in the middle of a frame (frames are the same either way)
            import cv2
            cv2.setNumThreads(1)
            # the host process boots (~0.5 s of imports) while this side imports and builds
            # its half (docs/cosim.md, "Start-up")
            port = open_transport("pty://")
            cfg_path = write_host_config(Path(tmpdir.name) / "host.json", spec.host_config)
            # at full speed the host polls for its grants and the rig for its DONEs instead of
            # sleeping (HOST_POLL_MS); paced (--speed N) both have time to sleep
            poll_ms = HOST_POLL_MS if spec.speed is None else 0.0
            early = SocketHost(spec.host_argv(port.slave_path, cfg_path, poll_ms),
                               connect=False, poll_ms=poll_ms)
        # the SIM half's heavy imports (pymunk, the renderer) while the host process boots
        from mobigrasp.cosim.sim_side import SimSide

        sim = SimSide(scenario, seed, out, spec.scenario_file, spec.transport, spec.plan,
                      spec.mcu, spec.on_frame, on_mcu_bytes=spec.on_mcu_bytes,
                      host=spec.host)
        if spec.host_config.get("method") != scenario.meta.method:  # the world's is another
            sim.summary["host_method"] = spec.host_config.get("method")
    except BaseException:
        if early is not None:  # not connected yet: it sees the socket go and exits
            early.close()
        if port is not None:
            port.close()
        tmpdir.cleanup()
        raise
    return _session(spec, sim, early, port, tmpdir, name)


def _session(spec: RunSpec, sim: Any, early: SocketHost | None, port: Any,
             tmpdir: tempfile.TemporaryDirectory, name: str) -> dict:
    host: Any = early
    peer = None
    res = SessionResult()
    try:
        with sim.noting_the_end():
            if early is not None:
                early.connect()
            else:
                if spec.inproc_client is None:
                    raise ValueError("an in-process run needs RunSpec.inproc_client")
                port, peer = inproc_pair(f"run-{name}-{spec.seed}")
                host = InprocHost(spec.inproc_client(peer))
            host = sim.wire(spec, host, port)
            rig = sim.rig
            progress = None
            if callable(spec.progress):  # a display of the caller's (tools.progress.RunProgress)
                def progress(r, wall):
                    spec.progress(rig.now_us, r.host_state, wall)
            sim.drive(res, host, spec.time_limit_s, speed=spec.speed, progress=progress,
                      on_host_event=sim.snaps.on_host_event,
                      stop=None if spec.after_crash_s is None else (
                          lambda: sim.fault_rig.stop_reason(int(spec.after_crash_s * 1e6))))
    finally:
        if host is not None:
            host.close()
        for t in (port, peer):
            if t is not None:
                t.close()
        tmpdir.cleanup()
        sim.finish(res, None if host is None else host.traffic(), spec.time_limit_s)
    return sim.summary
