"""The planner as an anytime computation in slices of the 20 ms control step.

A Bezier plan costs tens of milliseconds of ARM920T time (docs/budget.md), more than the control
step's 20 ms. On the board it runs in the spare time of the control steps: each step gives it
at most ``PLAN_SLICE_US`` and the evaluation resumes where it stopped (the candidate loop of
hostc/bezier001.c keeps its index, the best feasible candidate so far and the cycles spent);
once the plan's budget is spent (the planners' ``budget_us``) it ends with the best candidate
found, the planners' "budget" cut. The host computes the same plan at once (its result does
not depend on where the slices fall) and :class:`PlanJob` holds it back until its slices have
been charged: the task keeps doing what it did (follows the old path, or stands) and takes
the new path in the step of the last slice, its time starting then.

``PLAN_SLICE_US`` leaves room in a 20 ms step for the step's own work and the protocol
(< 1 ms), and in a 66.7 ms frame period for a 17 ms vision front end preempted by four steps
of planning (docs/budget.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mobigrasp.host.budget import FCLK_HZ, OpCounts

PLAN_SLICE_US = 8_000
CYCLES_PER_US = FCLK_HZ // 1_000_000


@dataclass
class PlanJob:
    """A finished plan whose modelled time is still being charged slice by slice."""

    follower: Any  # what the plan gives the task (a PathFollower or None)
    detail: dict | None  # the plan's trace detail (None: its outcome needs no handling)
    remaining_us: int
    slice_us: int = PLAN_SLICE_US

    @classmethod
    def start(cls, follower: Any, detail: dict | None, ops: OpCounts,
              slice_us: int = PLAN_SLICE_US) -> PlanJob:
        """A job for a plan of modelled cost ``ops`` (its first slice is taken by :meth:`step`)."""
        if slice_us <= 0:
            raise ValueError(f"slice_us must be > 0, got {slice_us}")
        return cls(follower, detail, ops.time_us(), int(slice_us))

    @property
    def done(self) -> bool:
        """All slices charged: the plan's result may be used."""
        return self.remaining_us <= 0

    def step(self) -> OpCounts:
        """The slice of this control step (at most ``slice_us``), as ARM9 cycles."""
        take = min(self.remaining_us, self.slice_us)
        self.remaining_us -= take
        return OpCounts(alu=take * CYCLES_PER_US)

    def slices(self) -> int:
        """Control steps still needed."""
        return -(-self.remaining_us // self.slice_us)
