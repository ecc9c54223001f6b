"""Bezier path update of paper 001 (§III.E): replan from the present position and velocity
whenever the sonars show the rest of the present path passing through an infeasible region.

At every sonar reading the remaining part of the curve (from the τ of the present time to the
end) is sampled and tested against the infeasible regions of the fresh reading (eq. (16)) and the
regions remembered from earlier (re)plans; if any sample is inside, the path is blocked and
:func:`host.planning.bezier001.plan_001` is called from the present position and velocity, with
the remembered regions (001 Fig. 5: path 2 must still avoid region 1, which the sonars may no
longer see). The regions present at each (re)plan are remembered (at most ``memory`` of them, the
oldest forgotten first), so that memory stays small and the plan stays within its ARM9 budget.
When no feasible path exists the decision says so and the caller stops the platform; the next
update plans again (``curve`` None counts as blocked) with v0 scaled by the next of
``slow_factors`` (ours, not 001: with a_t = v²κ <= Amax a slower curve may bend where a fast one
cannot); each call makes at most one plan, so it stays within one plan's ARM9 budget.

Memory (ours; 001 Fig. 5 only says path 2 must still avoid region 1 that the sonars no longer
see): a remembered region is kept only while its place is out of the sonars' present view. Once
the middle of its echo arc is again within D_e and inside the ring's angular span (S_1's right
edge to S_k_s's left edge), the fresh reading describes that place and the old region is
forgotten (:meth:`Replanner.forget_seen`). Without this the memory fills with the wide sectors of
far-off first echoes (a sector A_g/2 wide about its bisector is ±0.8 m across at 2.3 m) taken
from poses along the way, and they box in every replan long after better readings exist.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import mrad_from_rad, sincos_q12
from mobigrasp.host.planning.bezier import Curve
from mobigrasp.host.planning.bezier001 import Params001, is_object_echo, plan_001
from mobigrasp.host.planning.bezier_q import (
    POS_PER_M,
    TIME_PER_S,
    geo_q,
    isqrt_array,
    quantize_ctrl,
)
from mobigrasp.host.planning.blocked_q import first_blocked_q, tau_at_time_q15
from mobigrasp.host.planning.candidates import Plan
from mobigrasp.host.planning.observe import observed
from mobigrasp.host.planning.sonar_regions import (
    REGION_SETUP_OPS,
    InfeasibleRegion,
    infeasible_regions,
    sonar_q,
)


@dataclass(frozen=True)
class ReplanDecision:
    """Outcome of one sonar update."""

    blocked: bool  # the remaining path crosses an infeasible region
    replanned: bool  # a new curve was planned (it starts at the present time)
    curve: Curve | None  # the curve to follow from now on (None: stop, nothing feasible)
    plan: Plan | None  # the new plan when one was made
    reason: str
    ops: OpCounts  # ARM9 cost of the check (and of the plan when one was made)


# per remembered region: offset, along, across, distance², two compares
FORGET_OPS = OpCounts(alu=10, muls32=6, branches=3)
# per region tested: its fixed-point words (sonar_regions.region_words, in integers)
REGION_WORDS_OPS = REGION_SETUP_OPS


class Replanner:
    """Keeps the present 001 curve, checks it against fresh sonar readings, replans."""

    def __init__(self, target_xy_m, params: Params001 | None = None, memory: int = 16,
                 check_samples: int = 32, slow_factors: tuple[float, ...] = (1.0, 0.5),
                 keep_going_m: float = 1.2) -> None:
        self.target = np.asarray(target_xy_m, dtype=np.float64).reshape(2)
        self.params = params if params is not None else Params001()
        self.memory: deque[InfeasibleRegion] = deque(maxlen=int(memory))
        self.check_samples = int(check_samples)
        if not slow_factors or any(not 0 < f <= 1 for f in slow_factors):
            raise ValueError(f"slow_factors must be in (0, 1], got {slow_factors}")
        self.slow_factors = tuple(slow_factors)
        self.level = 0
        self.curve: Curve | None = None
        self.start_us = 0
        self.replans = 0
        self.keep_going_m = float(keep_going_m)
        self._old_start_us = 0

    @property
    def v0_mps(self) -> float:
        """The v0 the next plan uses (001's v0 times the present slow-down factor)."""
        return self.params.v0 * self.slow_factors[self.level]

    def _plan(self, t_us: int, position_xy_m, heading_rad: float, vel_xy_mps,
              sonar_mm) -> Plan:
        params = replace(self.params, v0=self.v0_mps)
        plan = plan_001(position_xy_m, vel_xy_mps, heading_rad, self.target, sonar_mm,
                        params, known_regions=list(self.memory))
        fresh = infeasible_regions(self.params.sonar, position_xy_m, heading_rad, sonar_mm)
        for reg in fresh.regions:
            if (not is_object_echo(reg, self.target, self.params.object_echo_tol_m)
                    and reg not in self.memory):
                self.memory.append(reg)
        # ours, not 001: no feasible curve -> the next attempt plans slower (a_t = v²κ shrinks
        # with v²); a success lets the following replan try one step faster again
        if plan.best is None:
            self.level = min(self.level + 1, len(self.slow_factors) - 1)
        else:
            self.level = max(self.level - 1, 0)
        self._old_start_us = self.start_us
        self.curve = plan.best
        self.start_us = int(t_us)
        return plan

    @observed("start", topic="replan")
    def start(self, t_us: int, position_xy_m, heading_rad: float, vel_xy_mps, sonar_mm) -> Plan:
        """First plan from the present pose; its curve starts at ``t_us``."""
        self.level = 0
        return self._plan(t_us, position_xy_m, heading_rad, vel_xy_mps, sonar_mm)

    @observed("start_path", topic="replan")
    def start_path(self, t_us: int) -> None:
        """The present curve starts at ``t_us`` (the plan was charged in slices of the control
        steps: the path is followed from the last one)."""
        self.start_us = int(t_us)

    def forget_seen(self, position_xy_m, heading_rad: float) -> int:
        """Forget remembered regions whose place the sonars see again now; how many.

        In integers: the middle of each remembered echo arc (1/16 mm, the region's set-up) is
        seen again when it is nearer than D_e and its bearing off the heading is within the
        ring's span π/2 + A_g/2: with a, b its offset along and across the heading (Q12
        trigonometry), not (a < 0 and |b| < −a·cot(A_g/2)) (the span is wider than π/2)."""
        cfg = sonar_q(self.params.sonar)
        px = round(float(position_xy_m[0]) * POS_PER_M)
        py = round(float(position_xy_m[1]) * POS_PER_M)
        s, c = sincos_q12(mrad_from_rad(heading_rad))
        d_e2 = cfg.d_e_q4 ** 2
        cot_q12 = cfg.cot_half_q12
        keep = []
        for reg in self.memory:
            words = reg.words
            ax, ay = words.mx - px, words.my - py
            along = ax * c + ay * s
            across = abs(ay * c - ax * s)
            within_span = not (along < 0 and (across << 12) < -along * cot_q12)
            if not (ax * ax + ay * ay < d_e2 and within_span):
                keep.append(reg)
        dropped = len(self.memory) - len(keep)
        if dropped:
            self.memory = deque(keep, maxlen=self.memory.maxlen)
        return dropped

    def remaining_blocked(self, t_us: int,
                          regions: list[InfeasibleRegion]) -> tuple[bool, OpCounts]:
        """Does the rest of the present curve (after now) enter any of ``regions``?"""
        where, ops = self.first_blocked_q4(t_us, regions)
        return where is not None, ops

    def first_blocked_q4(self, t_us: int, regions: list[InfeasibleRegion]
                         ) -> tuple[tuple[int, int] | None, OpCounts]:
        """The first point (1/16 mm) of the rest of the present curve inside any of
        ``regions`` (None: clear) and the ARM9 cost of the test (host/planning/blocked_q.py)."""
        if self.curve is None or not regions:
            return None, OpCounts()
        ctrl_q = quantize_ctrl(self.curve.array)
        t_q4 = int(ctrl_q[0, 2]) + (t_us - self.start_us) * TIME_PER_S // 1_000_000
        tau0 = tau_at_time_q15(ctrl_q, t_q4)
        where, ops = first_blocked_q(ctrl_q, tau0, self.check_samples,
                                     geo_q((0.0, 0.0), 0.0, regions), len(regions))
        return where, ops + REGION_WORDS_OPS.scaled(len(regions))

    @observed("update", topic="replan")
    def update(self, t_us: int, position_xy_m, heading_rad: float, vel_xy_mps,
               sonar_mm, force: bool = False) -> ReplanDecision:
        """Check the present path against a fresh reading; replan when it is blocked.

        ``force``: replan even when the path is clear (the caller stopped following it, e.g.
        the sonar guard stopped the base: its rest starts from a pose the base has left)."""
        n_mem = len(self.memory)
        self.forget_seen(position_xy_m, heading_rad)
        scan = infeasible_regions(self.params.sonar, position_xy_m, heading_rad, sonar_mm)
        fresh = [r for r in scan.regions
                 if not is_object_echo(r, self.target, self.params.object_echo_tol_m)]
        where, ops = self.first_blocked_q4(t_us, fresh + list(self.memory))
        blocked = where is not None
        ops = ops + FORGET_OPS.scaled(n_mem) + OpCounts(luts=2 if n_mem else 0)
        if self.curve is not None and not blocked and not force:
            return ReplanDecision(False, False, self.curve, None, "path clear", ops)
        old = self.curve
        plan = self._plan(t_us, position_xy_m, heading_rad, vel_xy_mps, sonar_mm)
        self.replans += 1
        ops = ops + plan.ops
        ahead_q4 = None
        if where is not None:
            dx = where[0] - round(float(position_xy_m[0]) * POS_PER_M)
            dy = where[1] - round(float(position_xy_m[1]) * POS_PER_M)
            ahead_q4 = int(isqrt_array(np.array([dx * dx + dy * dy]))[0])
        if plan.best is None and old is not None and ahead_q4 is not None and (
                ahead_q4 > round(self.keep_going_m * POS_PER_M)):
            # ours: no update exists yet, but the block is far: keep the path and look again at
            # the next reading (closer echoes give narrower sectors, a far one often leaves the
            # centre cone); stop only when the block comes within keep_going_m
            self.curve = old
            self.start_us = self._old_start_us
            return ReplanDecision(True, False, old, plan, f"blocked {ahead_q4 / POS_PER_M:.2f} m "
                                  f"ahead, no update yet ({plan.reason}): path kept", ops)
        why = "blocked" if blocked else "no path" if old is None else "path dropped"
        if plan.best is None:
            return ReplanDecision(blocked, False, None, plan, f"{why}: {plan.reason}", ops)
        return ReplanDecision(blocked, True, plan.best, plan, f"{why}: replanned", ops)
