"""Fuzzy approaching of paper 002 (§3): two inputs, one output, 35 rules, integer (Q12).

Inputs: e, the angle between the direction of motion and the line from the platform to the
centre of the double-cross marker, and its rate e_c. Output u, the deviation angle the platform
should turn by; as 002 §3.1 says, relative to the present direction of motion and *turning left is
negative*, so e and u are positive when the marker is to the right (clockwise).
Units (002 gives none for the thresholds): e in mrad, e_c in mrad/s, u in mrad.

Quantisation (§3.1): k_e = 1/e_th (e_th = 1.43 rad), k_ec = 1/e_cth (e_cth = 5 rad/s),
k_u = 1/u_th (u_th = 1 rad); quantised values saturate at ±1. Fuzzy sets: E has 7 (NB NM NS Z
PS PM PB), E_c 5 (NB NS Z PS PB), U 7, triangular on [−1, 1] with peaks evenly spaced and feet on
the neighbouring peaks, so the memberships of every input sum to 1 and at least one rule always
fires. Inference: AND = min; defuzzification by the centroid of eq. (1) of 002,
u = Σ b_h μ_i / Σ μ_i over the fired rules (b_h: centre of the rule's output set). If no rule
fired (impossible with these covering triangles) the output is defined as u = 0 (keep the
direction) and counted in ``no_rule_fired``.

Wheel speeds, eq. (2) of 002: v_r = 2V_avg / (2 + k_uc·u), v_l = 2V_avg − v_r, V_avg = 15 cm/s,
k_uc = 1 (u in rad); u > 0 slows the right wheel and the platform turns right. Stop when the two
rings of the red cylinder are more than T_d = 45 px apart (§4).

Integer implementation: the quantised inputs are scaled so that set peaks are exact multiples of
4096 (E: x = 3·e_q12, peaks at (j−3)·4096; E_c: x = 2·e_c,q12, peaks at (k−2)·4096), so each
membership is max(0, 4096 − |x − peak|) exactly in Q12; the centroid is one integer division.
Against a float64 reference over the whole input grid (e every 2 mrad in ±1.6 rad, e_c every
20 mrad/s in ±5.6 rad/s, beyond saturation) the largest difference of u is 0.75 mrad
(tests/test_fuzzy_approach.py checks <= 1.5 mrad on a coarser grid).
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import div_round

E_SETS = ("NB", "NM", "NS", "Z", "PS", "PM", "PB")
EC_SETS = ("NB", "NS", "Z", "PS", "PB")
U_SETS = E_SETS

# Table 1 of 002: rows E_c = NB, NS, Z, PS, PB; columns E = NB .. PB; entries are U sets.
RULE_TABLE: tuple[tuple[str, ...], ...] = (
    ("NB", "NB", "NM", "NM", "Z", "PS", "PM"),
    ("NB", "NM", "NS", "NS", "Z", "PS", "PM"),
    ("NB", "NM", "NS", "Z", "PS", "PM", "PB"),
    ("NM", "NS", "Z", "Z", "PS", "PM", "PB"),
    ("NS", "NS", "Z", "PS", "PS", "PM", "PB"),
)
_RULE_IDX = tuple(tuple(U_SETS.index(u) for u in row) for row in RULE_TABLE)

Q12 = 4096
E_RANGE = 3 * Q12  # x_e in [−12288, 12288]
EC_RANGE = 2 * Q12  # x_ec in [−8192, 8192]
EVAL_OPS = OpCounts(alu=60, muls=6, divs=3, branches=20)


@dataclass(frozen=True)
class FuzzyParams:
    """Parameters of 002 §5 (angles in mrad, speeds in mm/s)."""

    e_th_mrad: int = 1430
    e_cth_mrad_s: int = 5000
    u_th_mrad: int = 1000
    v_avg_mm_s: int = 150
    k_uc_q12: int = 4096  # k_uc = 1 per rad of u
    t_d_px: int = 45

    def __post_init__(self) -> None:
        if min(self.e_th_mrad, self.e_cth_mrad_s, self.u_th_mrad) <= 0:
            raise ValueError(f"FuzzyParams: thresholds must be > 0, got {self}")


def _clamp(v: int, lim: int) -> int:
    return -lim if v < -lim else lim if v > lim else v


def memberships(x: int, n_sets: int) -> list[tuple[int, int]]:
    """(set index, μ in Q12) of the sets with μ > 0 for a scaled input x (peaks at multiples
    of 4096 centred on the middle set)."""
    half = n_sets // 2
    out = []
    for j in range(n_sets):
        mu = Q12 - abs(x - (j - half) * Q12)
        if mu > 0:
            out.append((j, mu))
    return out


class FuzzyController:
    """The controller of 002 §3.1 with integer inference; ``no_rule_fired`` counts the
    impossible empty case."""

    def __init__(self, params: FuzzyParams = FuzzyParams()) -> None:
        self.p = params
        self.no_rule_fired = 0

    def quantise(self, e_mrad: int, ec_mrad_s: int) -> tuple[int, int]:
        """Scaled inputs x_e = 3·k_e·e (Q12) and x_ec = 2·k_ec·e_c (Q12), saturated."""
        x_e = _clamp(div_round(int(e_mrad) * E_RANGE, self.p.e_th_mrad), E_RANGE)
        x_ec = _clamp(div_round(int(ec_mrad_s) * EC_RANGE, self.p.e_cth_mrad_s), EC_RANGE)
        return x_e, x_ec

    def infer_q12(self, x_e: int, x_ec: int) -> int:
        """Quantised output u·k_u in Q12 ([−4096, 4096]) by min-inference and eq. (1)."""
        num = 0
        den = 0
        for k, mu_ec in memberships(x_ec, 5):
            for j, mu_e in memberships(x_e, 7):
                w = mu_e if mu_e < mu_ec else mu_ec  # AND = min
                num += (_RULE_IDX[k][j] - 3) * w  # b_h = (h − 3)/3
                den += w
        if den == 0:
            self.no_rule_fired += 1
            return 0
        return div_round(num * Q12, 3 * den)

    def u_mrad(self, e_mrad: int, ec_mrad_s: int) -> int:
        """Deviation angle u in mrad (positive: turn right) for e (mrad) and e_c (mrad/s)."""
        u_q12 = self.infer_q12(*self.quantise(e_mrad, ec_mrad_s))
        return div_round(u_q12 * self.p.u_th_mrad, Q12)  # u = u_q / k_u

    def wheels_mm_s(self, u_mrad: int) -> tuple[int, int]:
        """Eq. (2) of 002: (v_l, v_r) in mm/s."""
        v = self.p.v_avg_mm_s
        k_u = div_round(self.p.k_uc_q12 * int(u_mrad), 1000)  # k_uc·u in Q12
        v_r = div_round(2 * v * Q12, 2 * Q12 + k_u)
        return 2 * v - v_r, v_r


@dataclass(frozen=True)
class FuzzyCommand:
    """One step of the fuzzy approach: wheel speeds and whether the platform must stop."""

    left_mm_s: int
    right_mm_s: int
    u_mrad: int
    stop: bool


class FuzzyApproach:
    """The approach loop of 002: e_c from successive e, stop when d_pixel > T_d."""

    def __init__(self, params: FuzzyParams = FuzzyParams()) -> None:
        self.ctl = FuzzyController(params)
        self._prev: tuple[int, int] | None = None

    def step(self, t_us: int, e_mrad: int | None, d_pixel: int | None = None) -> FuzzyCommand:
        """One control step; ``e_mrad`` None means the marker is not seen (stop and wait)."""
        if d_pixel is not None and d_pixel > self.ctl.p.t_d_px:
            return FuzzyCommand(0, 0, 0, True)
        if e_mrad is None:
            self._prev = None
            return FuzzyCommand(0, 0, 0, False)
        ec = 0
        if self._prev is not None and t_us > self._prev[0]:
            ec = div_round((int(e_mrad) - self._prev[1]) * 1_000_000, int(t_us) - self._prev[0])
        self._prev = (int(t_us), int(e_mrad))
        u = self.ctl.u_mrad(e_mrad, ec)
        v_l, v_r = self.ctl.wheels_mm_s(u)
        return FuzzyCommand(v_l, v_r, u, False)
