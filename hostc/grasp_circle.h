/* The grasp circle's end points of 001 (host/planning/grasp_circle.py end_points_q, eq. (6)).
 * The radius l_e (eq. (5)'s scan) is configuration-time work: the caller gives it in 1/16 mm. */
#ifndef MG_GRASP_CIRCLE_H
#define MG_GRASP_CIRCLE_H

#include <stdint.h>

/* the n_e end points (2 words each, 1/16 mm) at phi_k = 2 pi k / n_e (k = 1..n_e, k / n_e
 * of a turn, mg_sincos_turn_q12) and the unit directions from each to the object, -(cos, sin) phi_k in Q14;
 * returns -1 (nothing written) when n_e < 1 or l_e <= 0 */
int mg_end_points_q(const int64_t object_q4[2], int64_t l_e_q4, int32_t n_e, int64_t *ends_q4,
                    int32_t *dirs_q14);

#endif
