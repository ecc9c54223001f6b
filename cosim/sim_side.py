"""The SIM half of a run: run folder, plant, MCU, fault wrappers and rig, the session loop and
the summary; the one wiring of ``mobigrasp run`` (cosim/run.py, also campaigns) and of
``mobigrasp sim`` (cosim/serve/session.py, also the pytest plugin's robot), so both write the
same summary.json (docs/outputs.md).

Imported by mobigrasp.cosim.run only once the host process was started, so that the host boots
while this process imports pymunk and the renderer and builds the world (docs/cosim.md,
"Start-up").
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from mobigrasp.cosim.faulted_host import wrap_for_faults
from mobigrasp.cosim.handshake import HostEnd, HostTraffic
from mobigrasp.cosim.heap_tuning import keep_freed_memory
from mobigrasp.cosim.rig import Rig, RigConfig
from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.cosim.run_folder import Snapshots, TraceWriter, write_summary
from mobigrasp.cosim.session import SessionResult, run_session
from mobigrasp.cosim.summary import figures
from mobigrasp.mcu_sim.backend import open_mcu
from mobigrasp.mcu_sim.faults.plan import FaultPlan

log = logging.getLogger(__name__)
SUMMARY_PERIOD_US = 5_000_000  # a running summary at least this often, in simulated time


class _TappedPort:
    """The rig's serial port, each write also told to ``tap``."""

    def __init__(self, port: Any, tap: Callable[[bytes], None]) -> None:
        self._port = port
        self._tap = tap

    def write(self, data: bytes) -> None:
        self._port.write(data)
        self._tap(data)

    def read(self) -> bytes:
        return self._port.read()

    def wait_readable(self, timeout_s: float) -> bool:
        return self._port.wait_readable(timeout_s)


class SimSide:
    """Everything of a run on the rig's side of the lockstep channel."""

    def __init__(self, scenario: Any, seed: int, out: Path, scenario_file: Path,
                 transport: str, plan: Any, mcu_backend: str = "python",
                 on_frame: Callable[[int, int, Any], None] | None = None,
                 external_host: bool = False,
                 on_mcu_bytes: Callable[[int, bytes], None] | None = None,
                 host: str = "python") -> None:
        """``external_host``: the host is a program of the user's (``mobigrasp sim``), which
        reports no task state: the method is "external" and success is the world's grasp.
        ``on_mcu_bytes(t_us, data)``: told every write of the MCU's bytes to the host's line
        (trace.mcap's telemetry topics; the trace is not changed by it). ``host``: the host
        program the run drives (python | c | arm), for the summary."""
        self.out = out
        name = scenario.meta.name
        method = "external" if external_host else scenario.meta.method
        self.external_host = external_host
        (out / "plots").mkdir(exist_ok=True)
        self.summary: dict[str, Any] = {
            "scenario": name, "scenario_file": str(scenario_file),
            "method": method, "seed": seed, "transport": transport,
            "host": "external" if external_host else host, "mcu_backend": mcu_backend,
            "status": "starting", "success": False, "grasped": False,
        }
        write_summary(out / "summary.json", self.summary)
        self.trace = TraceWriter(out / "trace.jsonl")
        self.snaps = Snapshots(out / "frames")
        self.plant = WorldPlant(scenario, seed)
        self.summary["robot"] = self.plant.robot_geometry()  # for the plots (services/plots.py)
        self.plant.preload()  # textures built while the host process boots, not on its clock
        self.mcu = open_mcu(mcu_backend)
        self.seed = seed
        # the fault wrappers carry the safety monitor, so every run gets them (an empty plan
        # injects nothing and leaves the trace unchanged) and every summary a safety block
        self.plan = plan if plan is not None else FaultPlan()
        self._on_frame = on_frame
        self._on_mcu_bytes = on_mcu_bytes
        self.rig: Rig | None = None
        self.fault_rig: Any = None
        self._next_running_us = 0
        self.trace.write({"ev": "start", "t_us": 0, "scenario": name,
                          "method": method, "seed": seed,
                          "robot": [scenario.robot.x_m, scenario.robot.y_m,
                                    scenario.robot.heading_rad],
                          "target": [scenario.target.x_m, scenario.target.y_m],
                          "obstacles": [vars(o) for o in scenario.obstacles]})

    def wire(self, spec: Any, host: HostEnd | None, port: Any) -> HostEnd | None:
        """Wrap MCU, plant and ``host`` for the fault plan and build the rig on ``port`` with
        ``spec``'s ``quantum_us``, ``couple_us`` and ``host_lag_quanta``; the host end the
        session drives (None for None: an external host is not wrapped)."""
        self.fault_rig, rig_mcu, rig_plant, wrapped = wrap_for_faults(
            self.plan, self.seed, self.mcu, self.plant, host)
        self.summary["faults_plan"] = self.plan.as_table()
        if self._on_mcu_bytes is not None:
            port = _TappedPort(port, lambda data: self._on_mcu_bytes(self.rig.now_us, data))
        self.rig = Rig(rig_mcu, rig_plant, port,
                       RigConfig(quantum_us=spec.quantum_us, couple_us=spec.couple_us,
                                 host_lag_quanta=spec.host_lag_quanta),
                       on_frame=self._frame_callback())
        keep_freed_memory()  # frame-sized arrays are reused instead of faulted in again
        return wrapped

    def _frame_callback(self) -> Callable[[int, int, Any], None]:
        snap, extra = self.snaps.on_frame, self._on_frame
        if extra is None:
            return snap

        def both(seq: int, t_us: int, rgb: Any) -> None:
            snap(seq, t_us, rgb)
            extra(seq, t_us, rgb)
        return both

    def write_running(self, t_us: int, period_us: int = SUMMARY_PERIOD_US) -> int:
        """summary.json as "running" at ``t_us`` simulated; the time of the next one."""
        write_summary(self.out / "summary.json",
                      {**self.summary, "sim_time_s": t_us / 1e6, "pid": os.getpid()})
        return t_us - t_us % period_us + period_us

    def _on_quantum(self, t_us: int) -> None:
        self.plant.sample_path()
        if t_us >= self._next_running_us:
            self._next_running_us = self.write_running(t_us)

    def drive(self, res: SessionResult, host: HostEnd, limit_s: float, *,
              speed: float | None = None,
              progress: Callable[[SessionResult, float], None] | None = None,
              stop: Callable[[], str | None] | None = None,
              on_host_event: Callable[[dict], None] | None = None) -> None:
        """The session on the wired rig (cosim/session.py) until it ends, ``res`` filled in
        place (the caller still has it when the loop raises)."""
        self.summary["status"] = "running"
        self._next_running_us = self.write_running(0)
        run_session(self.rig, host, self.trace, result=res, time_limit_us=int(limit_s * 1e6),
                    truth=self.plant.truth, on_host_event=on_host_event,
                    on_quantum=self._on_quantum, speed=speed, progress=progress, stop=stop)
        self.summary["status"] = "finished"

    @contextlib.contextmanager
    def noting_the_end(self) -> Iterator[None]:
        """The summary's status says how the block ended: a crash is noted with its error and
        not raised (finish() still writes the run folder); Ctrl-C (and SIGTERM, cosim/run.py)
        is noted and goes on up."""
        try:
            yield
        except KeyboardInterrupt:
            self.summary["status"] = "interrupted"
            raise
        except Exception as exc:
            self.summary["status"] = "crashed"
            self.summary["error"] = f"{type(exc).__name__}: {exc}"
            log.error("run crashed: %s", self.summary["error"])

    def finish(self, res: SessionResult, traffic: HostTraffic | None, limit_s: float,
               extra: dict | None = None) -> None:
        """Close the trace and write the final summary.json (with the caller's ``extra``)."""
        summary, rig = self.summary, self.rig
        self.trace.close()
        error = summary.get("error")
        summary.update(figures(res, self.plant, self.trace, self.snaps, limit_s))
        if self.external_host:
            # an external host claims nothing mobigrasp can read: success is the world's grasp
            summary.update(success=summary["grasped"], task_state="external")
        if error:
            summary["error"] = error
        traffic = traffic or HostTraffic()
        # where the wall time went (profiling only): over the pty the SIM side blocked on the
        # host's DONEs for wall_host_s; in process it ran the host program for that long
        summary["wall_host_s"] = round(traffic.wall_host_s, 3)
        # lockstep traffic (profiling only; docs/cosim.md "Fewer messages"): quanta, grants
        # issued a quantum early, grants not sent (their DONE known), socket writes of grants
        summary["lockstep"] = {"quanta": rig.stats["quanta"] if rig else 0,
                               "grants_early": rig.stats["grants_early"] if rig else 0,
                               "grants_elided": traffic.elided,
                               "grant_writes": traffic.messages_sent}
        summary["frames_captured"] = rig.stats["frames_captured"] if rig else 0
        summary["frames_skipped_camera_off"] = rig.stats["frames_skipped"] if rig else 0
        summary["mcu"] = self.mcu.stats()
        if self.fault_rig is not None:
            summary["faults"], summary["safety"] = self.fault_rig.summary()
            summary["safety"]["contacts"] = summary["contacts"]
        proto = summary["protocol"]
        proto["crc_errors"] = (proto["crc_errors"]
                               + summary["mcu"].get("parser_crc_errors", 0))
        proto["watchdog_trips"] = max(proto["watchdog_trips"],
                                      summary["mcu"].get("watchdog_trips", 0))
        summary.update(extra or {})
        write_summary(self.out / "summary.json", summary)
