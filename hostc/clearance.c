/* D_m of eq. (18) of 001 (host/planning/clearance_q.py path_clearance_q4): the least distance
 * from a path's samples to the regions' echo arcs, less R_r, in 1/16 mm. A sample within the
 * arc's angles (a = OP.(cos, sin) > 0 and |OP x (cos, sin)| 2^14 <= a tan, Q14) is |OP| - eta
 * away, else the distance to the nearer end of the arc; one 64-bit root per sample and region.
 * Bounds in the Python's docstring. */
#include "isqrt.h"
#include "kernels.h"

int64_t mg_path_clearance(const int64_t *words, int32_t n_reg, const int64_t *x,
                          const int64_t *y, int32_t n)
{
    int64_t best = MG_NO_REGION_Q4;
    for (int32_t r = 0; r < n_reg; r++) {
        const int64_t *w = words + MG_CLEAR_WORDS * r;
        const int64_t ox = w[0], oy = w[1], c = w[2], s = w[3], tn = w[4], eta = w[5];
        const int64_t r_r = w[6];
        for (int32_t j = 0; j < n; j++) {
            const int64_t rx = x[j] - ox, ry = y[j] - oy;
            const int64_t along = rx * c + ry * s;
            int64_t across = ry * c - rx * s;
            if (across < 0)
                across = -across;
            int64_t d;
            if (along > 0 && across * (1 << 14) <= along * tn) {
                d = mg_isqrt64((uint64_t)(rx * rx + ry * ry)) - eta;
                if (d < 0)
                    d = -d;
            } else {
                const int64_t ax = x[j] - w[7], ay = y[j] - w[8];
                const int64_t bx = x[j] - w[9], by = y[j] - w[10];
                const int64_t e1 = ax * ax + ay * ay, e2 = bx * bx + by * by;
                d = mg_isqrt64((uint64_t)(e1 < e2 ? e1 : e2));
            }
            d -= r_r;
            if (d < best)
                best = d;
        }
    }
    return best;
}
