"""One short closed-loop run of paper000-exp1 in process, wrapped for faults as services/run_job
does (shared by the fault and fast-path tests)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.cosim.faulted_host import wrap_for_faults
from mobigrasp.cosim.hosts import InprocHost
from mobigrasp.cosim.rig import Rig, RigConfig
from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.cosim.run_folder import TraceWriter
from mobigrasp.cosim.session import run_session
from mobigrasp.drivers.lockstep import LockstepClient
from mobigrasp.host.app_factory import build_host_app
from mobigrasp.link.inproc import inproc_pair
from mobigrasp.mcu_sim.faults import FaultPlan
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.services.run_job import host_config, resolve_scenario


@dataclass
class LoopRun:
    res: Any
    faults: dict
    safety: dict
    mcu: Any  # the FaultedMcu (its .inner is the Mcu)
    rig: Rig
    trace: TraceWriter
    trace_path: Path


def faulted_loop(tmp_path: Path, plan: FaultPlan, seconds: float, seed: int = 1,
                 name: str = "trace.jsonl", before: Callable[[Any], None] | None = None,
                 session: Callable[[Any, Any], dict] | None = None) -> LoopRun:
    """Run ``seconds`` simulated; ``before(mcu)`` may change the wrapped MCU first and
    ``session(mcu, plant)`` gives extra run_session arguments (truth, on_quantum...)."""
    _, sc = resolve_scenario("paper000-exp1")
    port, peer = inproc_pair(f"faulted-{seed}-{name}")
    host = InprocHost(LockstepClient(build_host_app(host_config(sc)), peer))
    world = WorldPlant(sc, seed)
    fr, mcu, plant, host = wrap_for_faults(plan, seed, Mcu(), world, host)
    if before is not None:
        before(mcu)
    rig = Rig(mcu, plant, port, RigConfig(quantum_us=5_000, couple_us=2_500))
    trace = TraceWriter(tmp_path / name)
    try:
        res = run_session(rig, host, trace, time_limit_us=int(seconds * 1e6),
                          **(session(mcu, plant) if session is not None else {}))
    finally:
        trace.close()
        host.close()
        port.close()
        peer.close()
    # DONE without the object held is a false claim: it fails every test that runs a scenario
    assert res.host_state != "DONE" or world.final()["grasped"], "false claim of success"
    faults, safety = fr.summary()
    return LoopRun(res, faults, safety, mcu, rig, trace, tmp_path / name)
