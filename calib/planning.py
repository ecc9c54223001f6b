"""The Bezier candidate evaluation of a recorded planner call, as the C kernels take it.

:func:`setup` turns one call of the planning corpus (calib/plan_corpus.py) into the inputs of
hostc/bezier000.c or hostc/bezier001.c (the candidates' control points, the limits, the grasp
circle and the infeasible regions' constants, the modelled-cycle budgets of the anytime cut
and of the fine check) and the Python's own answer for it: each candidate's reason and first
violated sample (host/planning/candidates.py evaluate_batch) and the modelled cycles of the
evaluation (batch_ops). The budgets follow host/planning/bezier001.py plan_001 line for line
(its set-up, region, end-point and clearance counts before the coarse and the fine pass).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mobigrasp.calib import plan_corpus
from mobigrasp.host.fixedpoint import isqrt
from mobigrasp.host.planning import bezier001 as b001
from mobigrasp.host.planning import bezier_q
from mobigrasp.host.planning.bezier_q import POS_PER_M, Q16, evaluate_q, quantize_ctrl, sample_ops
from mobigrasp.host.planning.candidates import Geometry, Limits, batch_ops, evaluate_batch
from mobigrasp.host.planning.clearance_q import clearance_ops
from mobigrasp.host.planning.sonar_regions import infeasible_regions

INFEASIBLE = np.iinfo(np.int64).max  # the C's cost of an infeasible candidate


def q16(k: float) -> int:
    """A cost weight in Q16, as the planners round it."""
    return round(k * Q16)

def geometry(obj, l_e: float, regions) -> Geometry:
    """001's geometric tests as plan_001 builds them (the grasp circle less its margin)."""
    return Geometry((float(obj[0]), float(obj[1])), l_e - b001.CIRCLE_MARGIN_M, tuple(regions))


@dataclass
class Pass:
    """One pass of candidates: the C's inputs and the Python's answer."""

    ctrl: np.ndarray  # (N, 4, 3) int32: 1/16 mm and 1/16 ms (bezier_q.quantize_ctrl)
    n: int
    lim: np.ndarray  # bezier_q.limits_q
    geo: np.ndarray | None  # bezier_q.geo_q
    n_reg: int
    reasons: list[str]  # Python's
    first: np.ndarray  # Python's first violated sample per candidate
    cycles: int  # modelled cycles of the candidates the pass evaluates


@dataclass
class Setup000:
    """000: one pass; the best index of the Python's plan (-1: none)."""

    coarse: Pass
    k1: int  # Q16
    k2: int
    best: int


@dataclass
class Setup001:
    """001: the coarse pass with its cut and the fine pass's budget."""

    coarse: Pass
    k1: int  # Q16
    k2: int
    per_sample_cycles: int
    setup_cycles: int
    cut_cycles: int
    fine_lim: np.ndarray
    fine_geo: np.ndarray
    n_fine: int
    max_fine: int
    t_d_m: float
    worst_us: int
    fine_budget_us: int
    clearance: np.ndarray  # D_m of each candidate as the Python found it (inf: no regions)
    best: tuple[int, int] | None  # (u, k_e) of the Python's plan
    us: np.ndarray
    endpoints: np.ndarray
    fine_limits: Limits
    fine_geometry: Geometry  # the fine pass's tests (true regions)
    # the plan's modelled cycles before the coarse pass (set-up, regions, end points) and
    # before the fine check (those, the coarse pass and the clearances D_m): where each pass
    # starts in the plan's slices (host/planning/anytime.py)
    pre_coarse_cycles: int = 0
    pre_fine_cycles: int = 0
    coarse_kw: dict | None = None  # sample_ops' arguments of the coarse pass


def setup(call: dict, arrays: dict[str, np.ndarray]) -> Setup000 | Setup001:
    """The C inputs and the Python's answer for one recorded planner call."""
    params = plan_corpus.params_of(call)
    res = call["result"]
    ctrl = np.asarray(arrays["ctrl"], np.float64)
    n = int(res["n_samples"])
    if call["planner"] == "000":
        lim = Limits(params.v_max, params.a_max, params.r_min, accel_is_normal=False)
        _, reasons, first = evaluate_batch(ctrl, n, lim) if len(ctrl) else (None, [], [])
        first = np.asarray(first, np.int64)
        cycles = batch_ops(first, n).cycles() if len(ctrl) else 0
        best = -1
        if res["best"] is not None:
            best = int(np.nonzero(arrays["us"] == res["best"]["u"])[0][0])
        return Setup000(Pass(quantize_ctrl(ctrl), n, lim.words(), None, 0, reasons, first,
                             cycles), q16(params.k1), q16(params.k2), best)
    inp = call["inputs"]
    p0 = np.asarray(inp["start_xy_m"], np.float64)
    obj = np.asarray(inp["target_xy_m"], np.float64)
    l_e = float(res["extra"]["l_e_m"])
    regions = plan_corpus.rows_to_regions(arrays["regions"])
    known = len(inp.get("known_regions") or [])
    scan = infeasible_regions(params.sonar, p0, inp["heading_rad"], inp["sonar_mm"])
    ops = b001.setup_ops(len(scan.regions) + known, params.n_e, len(arrays["us"]))
    pre_coarse = ops.cycles()
    kw = {"grasp_circle": True, "regions": len(regions), "divs_per_sample": 3}
    per_sample = sample_ops(1, **kw).cycles() - sample_ops(0, **kw).cycles()
    setup_cycles = sample_ops(0, **kw).cycles()
    cut_cycles = (params.budget_us - ops.time_us()) * 400
    dist_q4 = isqrt(sum((round(a * POS_PER_M) - round(b * POS_PER_M)) ** 2
                        for a, b in zip(obj, p0, strict=True)))
    inflate_q4 = max(round(params.coarse_inflate_m * POS_PER_M), dist_q4 // (4 * (n - 1)))
    grown = [r.grown(inflate_q4) for r in regions]
    coarse = Limits(params.v_max * params.coarse_margin, params.a_max * params.coarse_margin,
                    None, accel_is_normal=True)
    _, reasons, first = evaluate_batch(ctrl, n, coarse, geometry(obj, l_e, grown))
    row_cycles = np.minimum(first + 1, n) * per_sample + setup_cycles
    cut = np.cumsum(row_cycles) > cut_cycles
    reasons = ["budget" if c else r for r, c in zip(reasons, cut, strict=True)]
    ops = ops + batch_ops(first[~cut], n, **kw)
    n_ok = sum(1 for r in reasons if r == "ok")
    if regions and n_ok:
        each = clearance_ops(n - 1, len(regions))
        room = params.budget_us + 10_000 - ops.time_us()
        fit = max(0, min(n_ok, room // max(1, each.time_us())))
        ops = ops + each.scaled(int(fit))
    lim = Limits(params.v_max, params.a_max, None, accel_is_normal=True)
    best = None if res["best"] is None else (res["best"]["u"], res["best"]["endpoint"])
    return Setup001(
        Pass(quantize_ctrl(ctrl), n, coarse.words(), geometry(obj, l_e, grown).words(),
             len(grown), reasons, first, int(batch_ops(first[~cut], n, **kw).cycles())),
        q16(params.k1), q16(params.k2), per_sample, setup_cycles, cut_cycles, lim.words(),
        geometry(obj, l_e, regions).words(), params.n_fine, params.max_fine, params.t_d_m,
        sample_ops(params.n_fine, **kw).time_us(), params.total_budget_us - ops.time_us(),
        np.asarray(arrays["clearance"], np.float64), best, arrays["us"], arrays["endpoints"],
        lim, geometry(obj, l_e, regions), pre_coarse, ops.cycles(), kw)


def fine_order(cost: np.ndarray, clearance: np.ndarray, t_d_m: float, max_fine: int
               ) -> np.ndarray:
    """Eq. (18)'s pool in cost order, as plan_001 takes it to the fine check."""
    feasible = np.nonzero(cost < INFEASIBLE)[0]
    wide = feasible[clearance[feasible] > t_d_m]
    pool = wide if wide.size else feasible
    return pool[np.argsort(cost[pool], kind="stable")][:max_fine]



def fine_cycles(st: Setup001, ctrl_q: np.ndarray) -> int:
    """Modelled cycles of the fine checks of these quantized curves, as plan_001 charges them:
    each rejected at its first violated sample (batch_ops at n_fine samples)."""
    rows = np.asarray(ctrl_q).reshape(-1, 4, 3)
    if not len(rows):
        return 0
    first = evaluate_q(rows, st.n_fine, st.fine_lim, st.fine_geo,
                       len(st.fine_geo) // bezier_q.REGION_WORDS).first
    return int(np.minimum(first + 1, st.n_fine).sum()) * st.per_sample_cycles \
        + st.setup_cycles * len(rows) + bezier_q.PASS_OPS.cycles() * int((first >= st.n_fine).sum())


def coarse_cycles(st: Setup001, start: int, stop: int) -> int:
    """Modelled cycles of the coarse pass's candidates ``start:stop``, as plan_001 charges them
    (those past the anytime cut not at all)."""
    cp = st.coarse
    taken = np.array([r != "budget" for r in cp.reasons[start:stop]], bool)
    return int(batch_ops(cp.first[start:stop][taken], cp.n, **(st.coarse_kw or {})).cycles())

