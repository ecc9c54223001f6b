/* The candidates' control points in integers (host/planning/control_points.py): 000 §III.B.1
 * and eqs. (7)-(11) of 001. Positions in 1/16 mm, times in 1/16 ms, unit directions in Q14,
 * v0 in mm/s, T_s in ms. */
#ifndef MG_CONTROL_POINTS_H
#define MG_CONTROL_POINTS_H

#include <stdint.h>

#define MG_DIR_BITS 14

/* the per-plan numbers: t3 = |q_s P_i| / v0 (7), N_i = t3 / T_s (at least 1), the spacings
 * Delta d_e (10), Delta d_s (11) and their times Delta d / v0 */
typedef struct {
    int64_t t3, n_i, dd_e, dd_s, dt_e, dt_s;
} mg_plan_numbers_t;

/* (dx, dy) / |(dx, dy)| in Q14, rounded; 0 for the zero vector (out untouched) */
int mg_unit_q14(int64_t dx, int64_t dy, int32_t out[2]);
/* (cos, sin) of a heading in Q14 (the Q12 table's values, shifted) */
void mg_heading_q14(int32_t heading_mrad, int32_t out[2]);
/* the velocity's direction (1/16 mm per s) when its speed is at least moving_q4, else the
 * heading's (has_heading), else the fallback */
void mg_start_direction_q(const int64_t vel_q4[2], int has_heading, int32_t heading_mrad,
                          const int32_t fallback_q14[2], int64_t moving_q4, int32_t out[2]);
/* 0, or -1 when dist < 0, v0 <= 0 or T_s <= 0 */
int mg_plan_numbers(int64_t dist_q4, int32_t v0_mm_s, int32_t t_s_ms, mg_plan_numbers_t *out);
/* eqs. (8)-(9) for one end and one u: 12 words (P0..P3, each x, y, t) */
void mg_control_point_row(const int64_t p0_q4[2], const int32_t d0_q14[2],
                          const int64_t end_q4[2], const int32_t d3_q14[2],
                          const mg_plan_numbers_t *num, int64_t u, int32_t *row);
/* eqs. (8)-(9) for n_end ends (ends_q4 and d3_q14: 2 words each), u = 1..N_i within each:
 * n_end N_i rows of 12 int32 (P0..P3, each x, y, t) into ctrl, which holds cap rows; returns
 * the rows written, or -1 when they do not fit (nothing written) */
int32_t mg_control_points_q(const int64_t p0_q4[2], const int32_t d0_q14[2],
                            const int64_t *ends_q4, const int32_t *d3_q14, int32_t n_end,
                            const mg_plan_numbers_t *num, int32_t *ctrl, int32_t cap);

#endif
