"""Candidate sets of Bezier paths: constraint checks, cost, ARM9 cost, and the Plan result.

Shared by the planners of 000 (:mod:`mobigrasp.host.planning.bezier000`) and 001
(:mod:`host.planning.bezier001`). A batch of curves is sampled at the same τ in fixed point
(:mod:`mobigrasp.host.planning.bezier_q`); each curve is checked sample by sample in the order
the C loop does (the planner's geometric tests, time increasing, speed, acceleration, turning
radius) and the index of its first violation is kept, so that the modelled ARM9 cost charges
an early exit only for the samples the C loop evaluates.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.planning.bezier import Curve
from mobigrasp.host.planning.bezier_q import (
    PASS_OPS,
    Q16,
    REASONS,
    QBatch,
    evaluate_q,
    geo_q,
    limits_q,
    quantize_ctrl,
    sample_ops,
)

REASON_OK = "ok"


@dataclass(frozen=True)
class Candidate:
    """One planned curve of the candidate set, kept with its evaluation (for plots and tests)."""

    u: int  # index u = 1..N_i of the P1/P2 spacing
    endpoint: int  # index k_e of the grasp-circle end point (001), -1 for 000
    curve: Curve
    feasible: bool
    reason: str  # "ok" or the first constraint violated
    cost: float  # k1·length + k2·∫|κ|dτ (inf when infeasible before the end)
    length_m: float
    kappa_integral: float
    clearance_m: float = float("inf")  # D_m of 001 (distance to the nearest infeasible region)


@dataclass
class Plan:
    """Result of one planning call: the best curve (or None), every candidate, and the ARM9 ops."""

    best: Curve | None
    candidates: Sequence[Candidate]  # a CandidateList from the planners
    ops: OpCounts
    reason: str
    n_samples: int = 0
    stride: int = 1
    best_candidate: Candidate | None = None
    extra: dict = field(default_factory=dict)


def choose_sampling(n_candidates: int, cycles_per_sample: int, budget_us: int,
                    n_min: int, n_max: int) -> tuple[int, int]:
    """Samples per curve and the stride over candidates so the set fits ``budget_us`` of ARM9.

    Worst case (no early exit) is budgeted. When even ``n_min`` samples per curve do not fit, only
    every ``stride``-th candidate is evaluated.
    """
    budget_samples = max(1, budget_us * 400 // max(1, cycles_per_sample))  # 400 cycles per us
    n = int(min(n_max, max(n_min, budget_samples // max(1, n_candidates))))
    stride = 1
    while (n_candidates + stride - 1) // stride * n > budget_samples and stride < n_candidates:
        stride += 1
    return n, stride


@dataclass(frozen=True)
class Limits:
    """Kinematic constraints of a plan (SI)."""

    v_max: float
    a_max: float
    r_min: float | None  # None: no turning-radius constraint (001 has none)
    accel_is_normal: bool  # True: a_t = v²κ as eq. (14) of 001 writes it; False: dv/dt (000)

    def words(self) -> np.ndarray:
        """The fixed-point limits (bezier_q.limits_q, hostc/bezier.h ``lim``)."""
        return limits_q(self.v_max, self.a_max, self.r_min, self.accel_is_normal)


@dataclass(frozen=True)
class Geometry:
    """001's geometric tests: the grasp circle (samples inside ``radius_m`` of the object are
    rejected) and the infeasible regions of eq. (16)."""

    obj_xy_m: tuple[float, float]
    radius_m: float
    regions: tuple = ()

    def words(self) -> np.ndarray:
        """hostc/bezier.h ``geo`` (bezier_q.geo_q)."""
        return geo_q(self.obj_xy_m, self.radius_m, self.regions)


def evaluate_batch(ctrl: np.ndarray, n_samples: int, lim: Limits,
                   geometry: Geometry | None = None) -> tuple[QBatch, list[str], np.ndarray]:
    """Check a batch (N, 4, 3) in fixed point (bezier_q.evaluate_q); return the evaluation, a
    reason per curve and its first bad sample index (n_samples when none). Integer control
    points are counts already (1/16 mm, 1/16 ms), float ones metres and seconds."""
    geo = None if geometry is None else geometry.words()
    n_reg = 0 if geometry is None else len(geometry.regions)
    ctrl = np.asarray(ctrl)
    ctrl_q = ctrl if np.issubdtype(ctrl.dtype, np.integer) else quantize_ctrl(ctrl)
    q = evaluate_q(ctrl_q, n_samples, lim.words(), geo, n_reg)
    return q, [REASONS[c] for c in q.reason.tolist()], q.first


def batch_ops(first_bad: np.ndarray, n_samples: int, **kw) -> OpCounts:
    """ARM9 cost of a batch with early exit: a curve rejected at sample j costs j + 1 samples,
    a curve that passes its integrals and cost too."""
    first_bad = np.asarray(first_bad)
    if first_bad.size == 0:
        return OpCounts()
    samples = int(np.minimum(first_bad + 1, n_samples).sum())
    setup = sample_ops(0, **kw)
    one = sample_ops(1, **kw)
    per_sample = OpCounts(**{f.name: getattr(one, f.name) - getattr(setup, f.name)
                             for f in fields(OpCounts)})  # fields(): OpCounts may use slots
    passed = int((first_bad >= n_samples).sum())
    return per_sample.scaled(samples) + setup.scaled(first_bad.size) + PASS_OPS.scaled(passed)


class CandidateList(Sequence):
    """Read-only list of Candidate records built on access from the batch arrays.

    Planning keeps hundreds of candidates for plots and tests; building a Python object for each
    only when asked keeps one plan within a few milliseconds of wall time.
    """

    def __init__(self, ctrl: np.ndarray, reasons: list[str], us, endpoints, cost: np.ndarray,
                 length: np.ndarray, kint: np.ndarray, clearance: np.ndarray) -> None:
        self.ctrl = ctrl
        self.reasons = reasons
        self.us = np.asarray(us)
        self.endpoints = np.asarray(endpoints)
        self.cost = cost
        self.length = length
        self.kint = kint
        self.clearance = clearance

    def __len__(self) -> int:
        return len(self.reasons)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError(i)
        ok = self.reasons[i] == REASON_OK
        return Candidate(u=int(self.us[i]), endpoint=int(self.endpoints[i]),
                         curve=Curve.from_array(self.ctrl[i]), feasible=ok,
                         reason=self.reasons[i], cost=float(self.cost[i]),
                         length_m=float(self.length[i]), kappa_integral=float(self.kint[i]),
                         clearance_m=float(self.clearance[i]))

    @classmethod
    def empty(cls) -> CandidateList:
        """No candidates (nothing was planned)."""
        z = np.zeros(0)
        return cls(np.zeros((0, 4, 3)), [], z, z, z, z, z, z)

    def feasible_indices(self) -> np.ndarray:
        """Indices of the candidates that passed every check."""
        return np.nonzero(np.isfinite(self.cost))[0]


def candidates_from_batch(ctrl: np.ndarray, s: QBatch, reasons: list[str], us, endpoints,
                          k1: float, k2: float, clearance=None) -> CandidateList:
    """Wrap an evaluated batch into Candidate records with cost eq. (9) of 000 / (17) of 001
    (the fixed-point cost, Q16, as a float: the ranking is the integers')."""
    length = s.arc_length()
    kint = s.kappa_integral()
    # the reasons given, not the batch's: a curve past 001's anytime cut ("budget") was never
    # evaluated by the C loop and is not feasible, whatever the batch found
    ok = np.array([r == REASON_OK for r in reasons], dtype=bool).reshape(s.reason.shape)
    cost = np.where(ok, s.cost_q16(round(k1 * Q16), round(k2 * Q16)) / Q16, np.inf)
    if clearance is None:
        clearance = np.full(len(reasons), np.inf)
    return CandidateList(ctrl, reasons, us, endpoints, cost, length, kint,
                         np.asarray(clearance, dtype=np.float64))


def summarize_rejections(cands: CandidateList) -> str:
    """"no feasible candidate (speed: 3, accel: 10)" style summary."""
    counts: dict[str, int] = {}
    for r in cands.reasons:
        if r != REASON_OK:
            counts[r] = counts.get(r, 0) + 1
    parts = ", ".join(f"{k}: {v}" for k, v in sorted(counts.items()))
    return f"no feasible candidate ({parts})"


def unit(v: np.ndarray) -> np.ndarray | None:
    """v/|v|, or None for a (near) zero vector."""
    n = float(np.hypot(v[0], v[1]))
    if not np.isfinite(n) or n < 1e-9:
        return None
    return np.asarray(v, dtype=np.float64) / n
