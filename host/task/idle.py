"""The idle method: no paper's task, the host program around it only (hostc/task_idle.c in the
C host). It holds still in INIT and commands nothing: the handshake, heartbeat, telemetry,
camera frames, ARM9 budget and trace of the host program, in any host (``--host python|c|arm``)
before a paper method is in all of them. Not a paper method: not in :data:`METHODS`, never in a
scenario; a run asks for it as the host's method (services/run_job.py RunOptions.host_method)."""

from __future__ import annotations

from typing import Any

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.task.machine import TaskOutputs

IDLE = "idle"


class IdleTask:
    """The task interface of host/app.py HostApp, holding still."""

    method = IDLE

    def __init__(self) -> None:
        self.steps = 0

    def detectors_needed(self) -> list[str]:
        """No detector: frames arrive and are counted idle."""
        return []

    def detector_fallbacks(self) -> dict[str, str]:
        """None (no detectors)."""
        return {}

    def step(self, now_us: int, inputs: Any) -> TaskOutputs:
        """INIT, no command, no event."""
        self.steps += 1
        return TaskOutputs(None, None, None, [], "INIT", {}, OpCounts())


# the host program's own tasks by name, beside the paper methods of METHODS
PROGRAM_TASKS = {IDLE: IdleTask}
