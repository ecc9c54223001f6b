"""The SIM half of a run: run folder, plant, MCU, fault wrappers and rig, and its summary.

Imported by mobigrasp.cosim.run only once the host process was started, so that the host boots
while this process imports pymunk and the renderer and builds the world (docs/cosim.md,
"Start-up").
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mobigrasp.cosim.faulted_host import wrap_for_faults
from mobigrasp.cosim.handshake import HostEnd, HostTraffic
from mobigrasp.cosim.heap_tuning import keep_freed_memory
from mobigrasp.cosim.rig import Rig, RigConfig
from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.cosim.run_folder import Snapshots, TraceWriter, write_summary
from mobigrasp.cosim.session import SessionResult
from mobigrasp.cosim.summary import figures
from mobigrasp.mcu_sim.backend import open_mcu
from mobigrasp.mcu_sim.faults.plan import FaultPlan


class SimSide:
    """Everything of a run on the rig's side of the lockstep channel."""

    def __init__(self, scenario: Any, seed: int, out: Path, scenario_file: Path,
                 transport: str, plan: Any, mcu_backend: str = "python",
                 on_frame: Callable[[int, int, Any], None] | None = None) -> None:
        self.out = out
        name = scenario.meta.name
        (out / "plots").mkdir(exist_ok=True)
        self.summary: dict[str, Any] = {
            "scenario": name, "scenario_file": str(scenario_file),
            "method": scenario.meta.method, "seed": seed, "transport": transport,
            "mcu_backend": mcu_backend, "status": "starting", "success": False, "grasped": False,
        }
        write_summary(out / "summary.json", self.summary)
        self.trace = TraceWriter(out / "trace.jsonl")
        self.snaps = Snapshots(out / "frames")
        self.plant = WorldPlant(scenario, seed)
        self.summary["robot"] = self.plant.robot_geometry()  # for the plots (tools/plots.py)
        self.plant.preload()  # textures built while the host process boots, not on its clock
        self.mcu = open_mcu(mcu_backend)
        self.seed = seed
        # the fault wrappers carry the safety monitor, so every run gets them (an empty plan
        # injects nothing and leaves the trace unchanged) and every summary a safety block
        self.plan = plan if plan is not None else FaultPlan()
        self._on_frame = on_frame
        self.rig: Rig | None = None
        self.fault_rig: Any = None
        self.trace.write({"ev": "start", "t_us": 0, "scenario": name,
                          "method": scenario.meta.method, "seed": seed,
                          "robot": [scenario.robot.x_m, scenario.robot.y_m,
                                    scenario.robot.heading_rad],
                          "target": [scenario.target.x_m, scenario.target.y_m],
                          "obstacles": [vars(o) for o in scenario.obstacles]})

    def wire(self, spec: Any, host: HostEnd, port: Any) -> HostEnd:
        """Wrap MCU, plant and ``host`` for the fault plan and build the rig on ``port``; the
        host end the session drives."""
        self.fault_rig, rig_mcu, rig_plant, wrapped = wrap_for_faults(
            self.plan, self.seed, self.mcu, self.plant, host)
        self.summary["faults_plan"] = self.plan.as_table()
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

    def write_running(self, t_us: int, period_us: int) -> int:
        """summary.json as "running" at ``t_us`` simulated; the time of the next one."""
        write_summary(self.out / "summary.json",
                      {**self.summary, "sim_time_s": t_us / 1e6, "pid": os.getpid()})
        return t_us - t_us % period_us + period_us

    def finish(self, res: SessionResult, traffic: HostTraffic | None, limit_s: float) -> None:
        """Close the trace and write the final summary.json."""
        summary, rig = self.summary, self.rig
        self.trace.close()
        error = summary.get("error")
        summary.update(figures(res, self.plant, self.trace, self.snaps, limit_s))
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
        write_summary(self.out / "summary.json", summary)
