/* The end points of 001's grasp circle (host/planning/grasp_circle.py end_points_q), eq. (6):
 * x_e = x_i + l_e cos phi_k, y_e = y_i + l_e sin phi_k, phi_k = 2 pi k / n_e, k = 1..n_e. */
#include "grasp_circle.h"

#include "div_round.h"
#include "trig.h"

int mg_end_points_q(const int64_t object_q4[2], int64_t l_e_q4, int32_t n_e, int64_t *ends_q4,
                    int32_t *dirs_q14)
{
    if (n_e < 1 || l_e_q4 <= 0)
        return -1;
    for (int32_t i = 0; i < n_e; i++) {
        int32_t s, c; /* phi_k: (i + 1) / n_e of a turn, exact at the quarter turns */
        mg_sincos_turn_q12(i + 1, n_e, &s, &c);
        ends_q4[2 * i] = object_q4[0] + mg_div_round_i64(l_e_q4 * c, 4096);
        ends_q4[2 * i + 1] = object_q4[1] + mg_div_round_i64(l_e_q4 * s, 4096);
        dirs_q14[2 * i] = -c * 4;
        dirs_q14[2 * i + 1] = -s * 4;
    }
    return 0;
}
