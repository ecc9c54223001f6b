"""Bezier planning among obstacles, paper 001 (§III, eqs. (5)-(18)).

From the start q_s to each of the n_e end points q_e^i of the grasp circle (eqs. (5)-(6),
:mod:`host.planning.grasp_circle`): t3 = |q_s P_i| / v0 (eq. (7)), N_i = t3 / T_s curves with

    P1 = (x_s + uΔd_s ẋ̂_s, y_s + uΔd_s ŷ̂_s, uΔd_s / v0)            (8)
    P2 = (x_e − uΔd_e ẋ̂_e, y_e − uΔd_e ŷ̂_e, t3 − uΔd_e / v3)       (9)
    Δd_e = |q_s P_i| / N_i (10),  Δd_s = Δd_e / 4 (11),  v3 = v0,

where (ẋ̂, ŷ̂) are unit directions (see 000's module for why): the start direction is the measured
velocity (or the heading when standing still) and the end direction points at the object P_i.
Constraints: v <= Vmax and a_t = v²κ <= Amax (eq. (14) as 001 writes it); no sample may enter an
infeasible region (eq. (16), :mod:`host.planning.sonar_regions`) or the grasp circle. Cost eq. (17)
k1·arc length + k2·∫κ dτ (arc length, not the printed ∫√(x²+y²)dτ); eq. (18): among the feasible
paths prefer those whose clearance D_m to the infeasible regions exceeds T_D. 001 gives T_D = 15
without a unit; we read it as centimetres (T_D = 0.15 m, ``t_d_m``), the only unit in which 15 is
a sensible distance for a 0.2 m safety radius and a 2.5 m sonar range.

ARM9 budget (one plan <= ~100 ms, run in slices of the control steps: host/planning/anytime.py):
all N_i·n_e candidates cannot be sampled finely on an ARM920T (1000+ curves at ~2000 cycles per
fixed-point sample, docs/budget.md). So, as engineering choices of ours:
(a) end points on the far side of the object (angle between q_e − P_i and q_s − P_i larger than
``endpoint_max_angle_rad``, default π/2) are skipped (set it to π to evaluate all 36);
(b) coarse-to-fine: the candidates are checked at a number of samples chosen so that the set
fits the budget at ``expected_cost_fraction`` of the worst-case cost (curves are rejected at
their first violation), at least ``n_coarse_min`` (below that, every stride-th u only); end
points facing the robot come first, and curves after the point where the budget is actually
spent are not evaluated (reason "budget": an anytime cut). The coarse check uses
``coarse_margin`` of the speed and acceleration limits and infeasible regions grown by
``coarse_inflate_m`` (peaks and intrusions between coarse samples); then the cheapest curves are
re-checked at ``n_fine`` samples against the true limits, in cost order, until one passes (at
most ``max_fine``, and only while the budget lasts).
(c) Echoes of the object itself are not obstacles (:func:`is_object_echo`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import cos_q12, isqrt, isqrt_ops, sin_ops
from mobigrasp.host.planning import control_points as cp
from mobigrasp.host.planning.bezier_q import POS_PER_M, Q16, sample_ops
from mobigrasp.host.planning.candidates import (
    REASON_OK,
    CandidateList,
    Geometry,
    Limits,
    Plan,
    batch_ops,
    candidates_from_batch,
    choose_sampling,
    evaluate_batch,
    summarize_rejections,
)
from mobigrasp.host.planning.clearance_q import (
    CLEARANCE_OPS,
    NO_REGION_Q4,
    clearance_ops,
    clearance_words,
    path_clearance_q4,
    point_clearance_q4,
)
from mobigrasp.host.planning.grasp_circle import (
    END_POINT_OPS_EACH,
    ArmGeometry001,
    end_points_q,
    grasp_radius,
)
from mobigrasp.host.planning.observe import observed
from mobigrasp.host.planning.sonar_regions import (
    REGION_SETUP_OPS,
    InfeasibleRegion,
    SonarConfig,
    infeasible_regions,
)


@dataclass(frozen=True)
class Params001:
    """Defaults of 001 §IV; the sampling/budget fields are ours (module docstring)."""

    v_max: float = 0.4
    a_max: float = 0.1
    v0: float = 0.2
    t_s: float = 0.5
    k1: float = 0.8
    k2: float = 0.2
    t_d_m: float = 0.15  # T_D = 15, read as cm
    n_e: int = 36
    sonar: SonarConfig = SonarConfig()
    arm: ArmGeometry001 = ArmGeometry001()
    endpoint_max_angle_rad: float = math.pi / 2
    n_coarse_min: int = 8
    n_coarse_max: int = 32
    n_fine: int = 48
    max_fine: int = 24
    coarse_margin: float = 0.9  # coarse samples check v, a_t against 90 % of the limits
    coarse_inflate_m: float = 0.1  # coarse test: regions grown by max(this, spacing / 4)
    budget_us: int = 75_000  # coarse pass: curves beyond it are not evaluated ("budget")
    expected_cost_fraction: float = 0.5  # sample count chosen for this share of the worst case
    total_budget_us: int = 98_000  # fine checks stop before the whole plan exceeds this
    moving_speed_mps: float = 0.02
    object_echo_tol_m: float = 0.15  # a region whose echo arc passes this close to the object

    def __post_init__(self) -> None:
        for name in ("v_max", "a_max", "v0", "t_s"):
            if not getattr(self, name) > 0:
                raise ValueError(f"Params001.{name} must be > 0, got {getattr(self, name)}")
        if self.n_e < 1 or self.n_coarse_min < 2 or self.n_fine < 2 or self.max_fine < 1:
            raise ValueError("Params001: n_e >= 1, n_coarse_min >= 2, n_fine >= 2, max_fine >= 1")


# the inputs in counts, |q_s P_i| (a root), the fallback direction (a unit vector), the
# per-plan numbers of eqs. (7), (10), (11), the facing threshold
SETUP_OPS = OpCounts(alu=40, muls32=8, branches=6) + isqrt_ops(1 << 44) + cp.UNIT_OPS \
    + cp.PLAN_NUMBERS_OPS + sin_ops()
FACING_OPS = OpCounts(alu=6, muls32=2 * 3, branches=1)  # one end point's 64-bit dot product
CIRCLE_MARGIN_M = 1e-3  # samples closer than l_e less this are inside the grasp circle
# per sonar region: its words (sonar_regions.py, in integers), the object-echo test (one
# point's clearance), and, in the coarse pass, the grown copy's words
REGION_OPS = REGION_SETUP_OPS.scaled(2) + CLEARANCE_OPS


def setup_ops(n_regions: int, n_e: int, n_candidates: int, ends: bool = True) -> OpCounts:
    """ARM9 cost of a plan's set-up before the coarse pass: the inputs and per-plan numbers,
    ``n_regions`` sonar regions, the n_e end points with their facing test (``ends``) and the
    control points of ``n_candidates`` curves."""
    ops = SETUP_OPS + REGION_OPS.scaled(n_regions) + cp.CANDIDATE_OPS.scaled(n_candidates)
    if ends:
        ops = ops + (END_POINT_OPS_EACH + FACING_OPS).scaled(n_e)
    return ops


def control_points_001(p0, d0, ends: np.ndarray, obj, t3: float, n_i: int, dist: float,
                       v0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Control points (eqs. (8)-(11)) for every (end point, u) in floats: (M, 4, 3), u and end
    index; the reference of the planner's integers (control_points.control_points_q)."""
    dd_e = dist / n_i  # eq. (10)
    dd_s = dd_e / 4.0  # eq. (11)
    n_end = ends.shape[0]
    u = np.tile(np.arange(1, n_i + 1, dtype=np.float64), n_end)
    k = np.repeat(np.arange(n_end), n_i)
    d3 = np.asarray(obj, dtype=np.float64)[None, :] - ends
    d3 /= np.hypot(d3[:, 0], d3[:, 1])[:, None]
    ctrl = np.zeros((u.size, 4, 3))
    ctrl[:, 0, :2] = p0
    ctrl[:, 1, :2] = p0 + (u * dd_s)[:, None] * d0
    ctrl[:, 1, 2] = u * dd_s / v0
    ctrl[:, 2, :2] = ends[k] - (u * dd_e)[:, None] * d3[k]
    ctrl[:, 2, 2] = t3 - u * dd_e / v0  # v3 = v0
    ctrl[:, 3, :2] = ends[k]
    ctrl[:, 3, 2] = t3
    return ctrl, u.astype(np.int64), k


def is_object_echo(region: InfeasibleRegion, obj, tol_m: float) -> bool:
    """True when the echo arc of ``region`` passes within ``tol_m`` of the object.

    The sonars also see the object to be grasped; 001 handles the object through the grasp
    circle, so such an echo must not make the grasp circle itself infeasible (our reading).
    """
    words = clearance_words([region])
    d_q4 = point_clearance_q4(words, round(obj[0] * POS_PER_M), round(obj[1] * POS_PER_M))
    return bool(int(d_q4[0]) + int(words[0, 6]) <= round(tol_m * POS_PER_M))


def _geometry(obj, l_e: float, regions: list[InfeasibleRegion]) -> Geometry:
    """The grasp circle (less a 1 mm margin) and the regions of eq. (16)."""
    return Geometry((float(obj[0]), float(obj[1])), l_e - CIRCLE_MARGIN_M, tuple(regions))


@observed("001")
def plan_001(start_xy_m, start_vel_xy_mps, heading_rad: float, target_xy_m, sonar_mm,
             params: Params001 = Params001(),
             known_regions: list[InfeasibleRegion] | None = None) -> Plan:
    """Plan from the present pose/velocity to the grasp circle of the object at ``target_xy_m``.

    ``sonar_mm`` are the present ranges of S_1..S_k_s (mm); ``known_regions`` are infeasible
    regions remembered from earlier readings (see :mod:`mobigrasp.host.planning.replan`).
    """
    p0 = np.asarray(start_xy_m, dtype=np.float64).reshape(2)
    vel = np.asarray(start_vel_xy_mps, dtype=np.float64).reshape(2)
    obj = np.asarray(target_xy_m, dtype=np.float64).reshape(2)
    if not (np.all(np.isfinite(p0)) and np.all(np.isfinite(vel)) and np.all(np.isfinite(obj))
            and math.isfinite(heading_rad)):
        raise ValueError(f"plan_001: non-finite input {p0}, {vel}, {heading_rad}, {obj}")
    scan = infeasible_regions(params.sonar, p0, heading_rad, sonar_mm)
    regions = [r for r in list(known_regions or []) + scan.regions
               if not is_object_echo(r, obj, params.object_echo_tol_m)]
    n_reg = len(scan.regions) + len(known_regions or [])
    ops = setup_ops(n_reg, params.n_e, 0, ends=False)
    l_e = grasp_radius(params.arm).l_e_m
    # the set-up in integers (control_points.py): positions in 1/16 mm, velocity in 1/16 mm/s
    p0_q = (round(p0[0] * POS_PER_M), round(p0[1] * POS_PER_M))
    ob_q = (round(obj[0] * POS_PER_M), round(obj[1] * POS_PER_M))
    l_e_q = round(l_e * POS_PER_M)
    to_start = (p0_q[0] - ob_q[0], p0_q[1] - ob_q[1])
    dist = isqrt(to_start[0] ** 2 + to_start[1] ** 2)  # |q_s P_i|
    if dist <= l_e_q + POS_PER_M // 1000:
        return Plan(None, CandidateList.empty(), ops, "already on the grasp circle")
    ends, d3 = end_points_q(ob_q, l_e_q, params.n_e)
    # an end point faces the start when the angle at the object between them is at most
    # endpoint_max_angle_rad: (q_e − P_i)·(q_s − P_i) >= cos(angle) l_e |q_s P_i|
    facing = (ends[:, 0] - ob_q[0]) * to_start[0] + (ends[:, 1] - ob_q[1]) * to_start[1]
    floor = (cos_q12(round(params.endpoint_max_angle_rad * 1000)) * l_e_q * dist) >> 12
    keep = np.nonzero(facing >= floor)[0]
    keep = keep[np.argsort(-facing[keep], kind="stable")]  # most promising end points first
    ops = setup_ops(n_reg, params.n_e, 0)
    d0 = cp.start_direction_q((round(vel[0] * POS_PER_M), round(vel[1] * POS_PER_M)),
                              round(heading_rad * 1000),
                              cp.unit_q14(-to_start[0], -to_start[1]),
                              round(params.moving_speed_mps * POS_PER_M))
    numbers = cp.plan_numbers(dist, round(params.v0 * 1000), round(params.t_s * 1000))
    t3, n_i = numbers[0], numbers[1]
    ctrl = cp.control_points_q(p0_q, d0, ends[keep], d3[keep], numbers)
    us = np.tile(np.arange(1, n_i + 1, dtype=np.int64), keep.size)
    ks = np.repeat(np.arange(keep.size), n_i)
    ks = keep[ks] + 1  # k_e = 1..n_e as in eq. (6)
    kw = {"grasp_circle": True, "regions": len(regions), "divs_per_sample": 3}
    per_sample = sample_ops(1, **kw).cycles() - sample_ops(0, **kw).cycles()
    expected = max(1, per_sample * round(params.expected_cost_fraction * Q16) >> 16)
    n, stride = choose_sampling(len(us), expected, params.budget_us - ops.time_us(),
                                params.n_coarse_min, params.n_coarse_max)
    sel = np.arange(0, len(us), stride)
    ctrl, us, ks = ctrl[sel], us[sel], ks[sel]
    ops = setup_ops(n_reg, params.n_e, len(us))
    lim = Limits(params.v_max, params.a_max, None, accel_is_normal=True)
    coarse = Limits(params.v_max * params.coarse_margin, params.a_max * params.coarse_margin,
                    None, accel_is_normal=True)
    checks = _geometry(obj, l_e, regions)
    # grow by a quarter of the straight-line spacing of coarse samples (>= coarse_inflate_m)
    inflate_q4 = max(round(params.coarse_inflate_m * POS_PER_M), dist // (4 * (n - 1)))
    grown = [r.grown(inflate_q4) for r in regions]
    s, reasons, first = evaluate_batch(ctrl, n, coarse, _geometry(obj, l_e, grown))
    # anytime cut: the C loop stops taking curves once the coarse budget is spent; curves after
    # that point were never evaluated (reason "budget")
    row_cycles = np.minimum(first + 1, n) * per_sample + sample_ops(0, **kw).cycles()
    spent = np.cumsum(row_cycles)
    cut = spent > (params.budget_us - ops.time_us()) * 400
    for i in np.nonzero(cut)[0]:
        reasons[i] = "budget"
    ops = ops + batch_ops(first[~cut], n, **kw)
    ok_rows = np.array([i for i, r in enumerate(reasons) if r == REASON_OK], dtype=np.int64)
    clear_q4 = np.full(len(us), NO_REGION_Q4, dtype=np.int64)
    if regions and ok_rows.size:
        # D_m of the coarse-feasible curves, as many as the budget leaves room for (the others
        # keep D_m unknown = 0, so eq. (18) does not prefer them)
        each = clearance_ops(n - 1, len(regions))
        room = params.budget_us + 10_000 - ops.time_us()
        fit = max(0, min(ok_rows.size, room // max(1, each.time_us())))
        clear_q4[ok_rows] = 0
        if fit:
            rows = ok_rows[np.argsort(_coarse_cost(s, ok_rows, params), kind="stable")][:fit]
            clear_q4[rows] = path_clearance_q4(clearance_words(regions), s.x_q4[rows, 1:],
                                               s.y_q4[rows, 1:])
            ops = ops + each.scaled(int(fit))
    clear_m = np.where(clear_q4 == NO_REGION_Q4, np.inf, clear_q4 / POS_PER_M)
    cands = candidates_from_batch(ctrl / POS_PER_M, s, reasons, us, ks, params.k1, params.k2,
                                  clear_m)
    feasible = cands.feasible_indices()
    extra = {"t3_s": t3 / POS_PER_M, "n_i": n_i, "l_e_m": l_e, "regions": regions,
             "sonar_dropped": scan.dropped, "endpoints_kept": int(keep.size)}
    if feasible.size == 0:
        return Plan(None, cands, ops, summarize_rejections(cands), n, stride, extra=extra)
    wide = feasible[clear_q4[feasible] > round(params.t_d_m * POS_PER_M)]  # eq. (18)
    pool = wide if wide.size else feasible
    order = pool[np.argsort(cands.cost[pool], kind="stable")][:params.max_fine]
    best, fine_reason = _fine_check((cands[int(i)] for i in order), params, lim, checks, kw,
                                    params.total_budget_us - ops.time_us())
    ops = ops + fine_reason[1]
    if best is None:
        return Plan(None, cands, ops, f"coarse-feasible candidates failed the fine check "
                    f"({fine_reason[0]})", n, stride, extra=extra)
    return Plan(best.curve, cands, ops, REASON_OK, n, stride, best, extra=extra)


def _coarse_cost(s, rows: np.ndarray, params: Params001) -> np.ndarray:
    """Cost eq. (17) (Q16) of the given rows of an evaluated batch (to rank them before D_m is
    known)."""
    return s.cost_q16(round(params.k1 * Q16), round(params.k2 * Q16))[rows]


def _fine_check(pool, params: Params001, lim: Limits, checks, kw,
                budget_us: int):
    """Re-check candidates at n_fine samples in cost order; the first that passes wins."""
    ops = OpCounts()
    last = "none tried"
    worst = sample_ops(params.n_fine, **kw).time_us()
    for cand in pool:
        if ops.time_us() + worst > budget_us:
            last = f"ARM9 budget spent, last: {last}"
            break
        s, reasons, first = evaluate_batch(cand.curve.array[None], params.n_fine, lim, checks)
        ops = ops + batch_ops(first, params.n_fine, **kw)
        if reasons[0] == REASON_OK:
            return cand, (REASON_OK, ops)
        last = reasons[0]
    return None, (last, ops)
