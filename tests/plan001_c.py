"""001's planner parameters in the C's integers (hostc/plan001.h mg_params001_t), for the
tests of hostc/plan001.c and of the board's replanner."""

from __future__ import annotations

import math

from mobigrasp import hostc
from mobigrasp.host.fixedpoint import cos_q12
from mobigrasp.host.planning.bezier001 import CIRCLE_MARGIN_M, Params001
from mobigrasp.host.planning.bezier_q import POS_PER_M, Q16
from mobigrasp.host.planning.candidates import Limits
from mobigrasp.host.planning.grasp_circle import grasp_radius
from mobigrasp.host.planning.sonar_regions import sonar_q

FFI, C = hostc.lib()


def params_c(p: Params001):
    """Params001 in the C's integers."""
    q, m = sonar_q(p.sonar), POS_PER_M
    l_e = grasp_radius(p.arm).l_e_m
    r = max(l_e - CIRCLE_MARGIN_M, 0.0) * m
    lim = Limits(p.v_max, p.a_max, None, accel_is_normal=True).words()
    coarse = Limits(p.v_max * p.coarse_margin, p.a_max * p.coarse_margin, None,
                    accel_is_normal=True).words()
    return FFI.new("mg_params001_t *", {
        "v0_mm_s": round(p.v0 * 1000), "t_s_ms": round(p.t_s * 1000),
        "k1_q16": round(p.k1 * Q16), "k2_q16": round(p.k2 * Q16), "t_d_q4": round(p.t_d_m * m),
        "coarse_inflate_q4": round(p.coarse_inflate_m * m),
        "moving_q4": round(p.moving_speed_mps * m), "echo_tol_q4": round(p.object_echo_tol_m * m),
        "l_e_q4": round(l_e * m), "circle_r2": math.floor(r * r),
        "facing_cos_q12": cos_q12(round(p.endpoint_max_angle_rad * 1000)), "n_e": p.n_e,
        "n_coarse_min": p.n_coarse_min, "n_coarse_max": p.n_coarse_max, "n_fine": p.n_fine,
        "max_fine": p.max_fine, "budget_us": p.budget_us, "total_budget_us": p.total_budget_us,
        "expected_q16": round(p.expected_cost_fraction * Q16),
        "lim": [int(v) for v in lim], "lim_coarse": [int(v) for v in coarse],
        "sonar": [q.k_s, q.a_g_urad, q.d_e_q4, q.r_r_q4, q.tol_q4, q.offset_q4,
                  int(q.arc_bound), q.cot_half_q12]})
