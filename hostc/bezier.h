/* One cubic Bezier curve with time (000 eqs. (4)-(9), 001 (3)-(4), (12)-(17)) checked sample by
 * sample in double precision, as host/planning/candidates.py evaluate_batch does for a batch:
 * the reason codes and the layouts shared by bezier.c, bezier000.c and bezier001.c. */
#ifndef MG_BEZIER_H
#define MG_BEZIER_H

#include <stdint.h>

/* reasons (calib/plan_corpus.py REASONS) */
enum { MG_OK = 0, MG_TIME = 1, MG_SPEED = 2, MG_ACCEL = 3, MG_RADIUS = 4, MG_CIRCLE = 5,
       MG_OBSTACLE = 6, MG_BUDGET = 7 };

/* lim: v_max, a_max, kappa_max (1 / R_min; < 0: no radius test), accel_is_normal (0: 000's
 * |dv/dt|, 1: 001's v^2 |kappa| of eq. (14)) */
#define MG_LIM_WORDS 4
/* geo: grasp circle (x, y, (l_e - margin)^2), then per infeasible region of eq. (16) the
 * constants of host/planning/sonar_regions.py any_region_contains: apex qx, qy; cos, sin of the
 * bisector; tan of the half-angle; sensing position ox, oy; max(eta - R_r, 0)^2; (eta + R_r)^2;
 * the arc bound: 1 when applied, 1 when cos(bound) >= 0, cos(bound)^2 */
#define MG_GEO_HEAD 3
#define MG_REGION_WORDS 12

/* ctrl: 4 rows (x, y, t); n samples at tau_j = j / (n - 1); geo NULL: no geometric tests.
 * Returns the reason, *first the sample of the first violation (n when none); for a curve
 * that passes, *len and *kint the trapezoid integrals of |P_tau| and |kappa| over tau. */
int32_t mg_bezier_curve(const double *ctrl, int32_t n, const double *lim, const double *geo,
                        int32_t n_reg, int32_t *first, double *len, double *kint);

#endif
