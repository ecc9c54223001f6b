"""Bezier approach planning of paper 000 (§III.B.1, eqs. (4)-(9)).

P0 = (x_s, y_s, 0) is the current position; P3 = (x_e, y_e, t3) is the grasp standoff point on the
line from P0 to the object. N_i = t3 / T_s candidates u = 1..N_i with

    P1 = (x_s + uΔd_s v̂_0x, y_s + uΔd_s v̂_0y, uΔd_s / v0)
    P2 = (x_e − uΔd_e v̂_3x, y_e − uΔd_e v̂_3y, t3 − uΔd_e / v3),   v3 = v0,
    Δd_e = |P0P3| / N_i,  Δd_s = Δd_e / 4,

constraints v <= Vmax, a_t <= Amax, R = 1/κ >= R_min at every sample, and the best feasible
candidate minimises eq. (9): k1·length + k2·∫κ dτ.

Where the paper is ambiguous we chose, and say so:
- "length" in eq. (9) is printed as ∫√(x(τ)² + y(τ)²)dτ (which depends on where the origin is);
  we use the arc length ∫√(x_τ² + y_τ²)dτ, which does not;
- v_0x, v_0y in P1, P2 are taken as the direction cosines of the velocity (a unit vector): the
  time coordinate uΔd_s/v0 is the time to cover uΔd_s at v0, which only fits if the spatial offset
  is uΔd_s; taken literally (m·m/s) the units would not match. The speed at both ends is then v0;
- 000 does not give t3; we use t3 = |P0P3| / v0 (eq. (7) of 001, same authors);
- "tangential acceleration" a_t is the component of 000's acceleration vector (a_tx, a_ty) along
  the velocity, |dv/dt|; the normal part is bounded by Vmax and R_min already;
- the velocity direction at P3 points at the object (001 §III.B.1); the start direction is the
  measured velocity, or ``heading_rad`` when standing still, or the object direction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import div_round, isqrt, isqrt_ops
from mobigrasp.host.planning.bezier_q import POS_PER_M, sample_ops
from mobigrasp.host.planning.candidates import (
    REASON_OK,
    CandidateList,
    Limits,
    Plan,
    batch_ops,
    candidates_from_batch,
    choose_sampling,
    evaluate_batch,
    summarize_rejections,
)
from mobigrasp.host.planning.control_points import (
    CANDIDATE_OPS,
    ONE_DIR,
    PLAN_NUMBERS_OPS,
    UNIT_OPS,
    control_points_q,
    plan_numbers,
    start_direction_q,
    unit_q14,
)
from mobigrasp.host.planning.observe import observed


@dataclass(frozen=True)
class Params000:
    """Defaults of 000 §IV; standoff and sampling are ours (see module docstring)."""

    t_s: float = 0.3  # T_s, s
    k1: float = 0.5
    k2: float = 0.5
    v0: float = 0.12  # m/s
    v_max: float = 0.25  # m/s
    a_max: float = 0.04  # m/s²
    r_min: float = 0.1  # m
    standoff_m: float = 0.15  # |P3 − object|: where the vision-based adjustment takes over
    n_samples_min: int = 16
    n_samples_max: int = 64
    budget_us: int = 90_000  # modelled ARM9 time allowed for one candidate set
    moving_speed_mps: float = 0.02  # below this the velocity gives no direction

    def __post_init__(self) -> None:
        for name in ("t_s", "v0", "v_max", "a_max", "r_min"):
            if not getattr(self, name) > 0:
                raise ValueError(f"Params000.{name} must be > 0, got {getattr(self, name)}")
        if self.standoff_m < 0 or self.n_samples_min < 2 or self.n_samples_max < self.n_samples_min:
            raise ValueError("Params000: standoff_m >= 0 and 2 <= n_samples_min <= n_samples_max")


# the inputs in counts, |P0 P_obj| (a root), the object direction (a unit vector), P3, and the
# per-plan numbers of eqs. (7), (10), (11)
SETUP_OPS = OpCounts(alu=30, muls32=6, branches=4) + isqrt_ops(1 << 44) + UNIT_OPS \
    + PLAN_NUMBERS_OPS


def control_points_000(p0: np.ndarray, d0: np.ndarray, p3: np.ndarray, d3: np.ndarray,
                       t3: float, n_i: int, v0: float) -> np.ndarray:
    """The (N_i, 4, 3) control points of all u = 1..N_i in floats (000 §III.B.1 as quoted
    above): the reference of the planner's integers (control_points.control_points_q)."""
    dist = float(np.hypot(*(p3 - p0)))
    dd_e = dist / n_i
    dd_s = dd_e / 4.0
    u = np.arange(1, n_i + 1, dtype=np.float64)[:, None]
    ctrl = np.zeros((n_i, 4, 3))
    ctrl[:, 0, :2] = p0
    ctrl[:, 1, :2] = p0 + u * dd_s * d0
    ctrl[:, 1, 2] = u[:, 0] * dd_s / v0
    ctrl[:, 2, :2] = p3 - u * dd_e * d3
    ctrl[:, 2, 2] = t3 - u[:, 0] * dd_e / v0  # v3 = v0
    ctrl[:, 3, :2] = p3
    ctrl[:, 3, 2] = t3
    return ctrl


@observed("000")
def plan_000(start_xy_m, start_vel_xy_mps, target_xy_m, params: Params000 = Params000(),
             heading_rad: float | None = None) -> Plan:
    """Plan the approach of 000 from the current position/velocity to the object at target.

    Returns every candidate with its rejection reason and the best feasible one (or None with
    the reason). ``plan.ops`` is the modelled ARM9 cost.
    """
    p0f = np.asarray(start_xy_m, dtype=np.float64).reshape(2)
    vel = np.asarray(start_vel_xy_mps, dtype=np.float64).reshape(2)
    obj = np.asarray(target_xy_m, dtype=np.float64).reshape(2)
    if not (np.all(np.isfinite(p0f)) and np.all(np.isfinite(vel)) and np.all(np.isfinite(obj))
            or heading_rad is not None and not math.isfinite(heading_rad)):
        raise ValueError(f"plan_000: non-finite input start={p0f}, vel={vel}, target={obj}")
    # the set-up in integers (control_points.py): positions in 1/16 mm, velocity in 1/16 mm/s
    p0 = (round(p0f[0] * POS_PER_M), round(p0f[1] * POS_PER_M))
    ob = (round(obj[0] * POS_PER_M), round(obj[1] * POS_PER_M))
    standoff = round(params.standoff_m * POS_PER_M)
    ops = SETUP_OPS
    dist_obj = isqrt((ob[0] - p0[0]) ** 2 + (ob[1] - p0[1]) ** 2)
    if dist_obj <= standoff:
        return Plan(None, CandidateList.empty(), ops, "already within standoff of the object")
    d3 = unit_q14(ob[0] - p0[0], ob[1] - p0[1])
    p3 = (ob[0] - div_round(standoff * d3[0], ONE_DIR), ob[1] - div_round(standoff * d3[1],
                                                                        ONE_DIR))
    d0 = start_direction_q((round(vel[0] * POS_PER_M), round(vel[1] * POS_PER_M)),
                           None if heading_rad is None else round(heading_rad * 1000), d3,
                           round(params.moving_speed_mps * POS_PER_M))
    numbers = plan_numbers(dist_obj - standoff, round(params.v0 * 1000),
                           round(params.t_s * 1000))
    t3, n_i = numbers[0], numbers[1]
    per_sample = sample_ops(1).cycles() - sample_ops(0).cycles()
    n, stride = choose_sampling(n_i, per_sample, params.budget_us - ops.time_us(),
                                params.n_samples_min, params.n_samples_max)
    ctrl = control_points_q(p0, d0, np.array([p3]), np.array([d3]), numbers)[::stride]
    ops = ops + CANDIDATE_OPS.scaled(len(ctrl))
    us = np.arange(1, n_i + 1)[::stride]
    lim = Limits(params.v_max, params.a_max, params.r_min, accel_is_normal=False)
    s, reasons, first = evaluate_batch(ctrl, n, lim)
    ops = ops + batch_ops(first, n)
    cands = candidates_from_batch(ctrl / POS_PER_M, s, reasons, us, np.full(len(us), -1),
                                  params.k1, params.k2)
    feasible = cands.feasible_indices()
    if feasible.size == 0:
        return Plan(None, cands, ops, summarize_rejections(cands), n, stride)
    best = cands[int(feasible[np.argmin(cands.cost[feasible])])]  # first minimum: smallest u
    return Plan(best.curve, cands, ops, REASON_OK, n, stride, best,
                extra={"t3_s": t3 / POS_PER_M, "n_i": n_i,
                       "p3_xy_m": (p3[0] / POS_PER_M, p3[1] / POS_PER_M)})
