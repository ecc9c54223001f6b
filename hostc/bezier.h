/* One cubic Bezier curve with time (000 eqs. (4)-(9), 001 (3)-(4), (12)-(17)) checked sample by
 * sample in fixed point, as host/planning/bezier_q.py evaluate_q does for a batch (the formats
 * are its docstring's): the reason codes and the layouts shared by bezier.c, bezier000.c and
 * bezier001.c. */
#ifndef MG_BEZIER_H
#define MG_BEZIER_H

#include <stdint.h>

/* reasons (bezier_q.py REASONS) */
enum { MG_OK = 0, MG_TIME = 1, MG_SPEED = 2, MG_ACCEL = 3, MG_RADIUS = 4, MG_CIRCLE = 5,
       MG_OBSTACLE = 6, MG_BUDGET = 7, MG_RANGE = 8 };

/* lim: v_max (m/s Q16), a_max (m/s^2 Q16), kappa_max = 1 / R_min (1/m Q16; < 0: no radius
 * test), accel_is_normal (0: 000's |dv/dt|, 1: 001's v^2 |kappa| of eq. (14)) */
#define MG_LIM_WORDS 4
/* geo (int64): grasp circle x, y (1/16 mm), radius^2; then per infeasible region of eq. (16)
 * (bezier_q.py geo_q): apex qx, qy; cos, sin of the bisector and tan of the half-angle (Q14);
 * sensing position ox, oy; the band's radii squared lo^2, hi^2; the arc bound: 1 when
 * applied, 1 when cos(bound) >= 0, cos(bound)^2 (Q16) */
#define MG_GEO_HEAD 3
#define MG_REGION_WORDS 12

/* ctrl: 4 rows (x, y, t) in 1/16 mm and 1/16 ms; n samples at tau_j = (j << 15) / (n - 1);
 * geo NULL: no geometric tests. Returns the reason, *first the sample of the first violation
 * (n when none); for a curve that passes, *len_q4 and *kint_q16 the trapezoid integrals of
 * |P_tau| (1/16 mm) and |kappa| (Q16) over tau. */
int32_t mg_bezier_curve(const int32_t *ctrl, int32_t n, const int32_t *lim, const int64_t *geo,
                        int32_t n_reg, int32_t *first, int64_t *len_q4, int64_t *kint_q16);

/* eq. (16): 1 when (x, y) (1/16 mm) lies in any of the n_reg regions of geo (bezier_q.py
 * in_regions_q) */
int mg_bezier_in_regions(const int64_t *geo, int32_t n_reg, int64_t x, int64_t y);

/* cost of eq. (9) / (17) in Q16 from the integrals (k1, k2 Q16) */
int64_t mg_bezier_cost(int32_t k1_q16, int32_t k2_q16, int64_t len_q4, int64_t kint_q16);

#endif
