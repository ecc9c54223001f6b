/* The grasp circle's end points of 001 (host/planning/grasp_circle.py end_points_q, eq. (6)).
 * The radius l_e = (l_m + l_n) / 2 comes from eq. (5)'s scan (configuration-time work,
 * mg_grasp_radius_um); mg_end_points_q takes it in 1/16 mm. */
#ifndef MG_GRASP_CIRCLE_H
#define MG_GRASP_CIRCLE_H

#include <stdint.h>

/* the n_e end points (2 words each, 1/16 mm) at phi_k = 2 pi k / n_e (k = 1..n_e, k / n_e
 * of a turn, mg_sincos_turn_q12) and the unit directions from each to the object, -(cos, sin) phi_k in Q14;
 * returns -1 (nothing written) when n_e < 1 or l_e <= 0 */
int mg_end_points_q(const int64_t object_q4[2], int64_t l_e_q4, int32_t n_e, int64_t *ends_q4,
                    int32_t *dirs_q14);

#define MG_GRASP_GRID_STEPS 180 /* grasp_circle.py GRID_STEPS: 1 degree */

/* eq. (5) of 001 (host/planning/grasp_circle.py grasp_radius_um): l_m, l_n in um, the largest
 * and least reach l >= 0 at height h_e over (theta2, theta3) on a (steps + 1)^2 grid on
 * [-pi/2, pi/2], theta1 from h = h_e (its two roots) kept in [0, pi]; returns -1 (nothing
 * written) when no grid point reaches h_e or steps < 1 */
int mg_grasp_radius_um(int64_t l1_um, int64_t l2_um, int64_t l3_um, int64_t h_r_um,
                       int64_t h_e_um, int32_t steps, int64_t out_um[2]);

/* eq. (5) on 001's arm (grasp_circle.py ArmGeometry001: l1, l2, l3 160, 160, 200 mm, h_r
 * 108 mm) for the grasp height h_e_mm, as mg_grasp_radius_um */
int mg_grasp_radius001_um(int32_t h_e_mm, int64_t out_um[2]);

#endif
