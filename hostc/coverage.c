/* Stations of the wandering search (host/coverage.py). */
#include "coverage.h"

#include "fixedpoint.h"
#include "path_follow.h"

#define TWO_PI_MRAD 6283

/* the polygon whose sides (at most about chord_mm) touch the circle of radius a at their
 * midpoints: its vertex radius and its sides */
static void ring(int64_t a, int32_t chord_mm, int64_t *a_v, int32_t *m)
{
    const int64_t sides = -mg_floor_div(-(int64_t)TWO_PI_MRAD * a, 1000 * (int64_t)chord_mm);
    *m = (int32_t)(sides > 6 ? sides : 6);
    *a_v = mg_floor_div(a * 4096, mg_cos_q12(TWO_PI_MRAD / (2 * *m)));
}

int32_t mg_ring_stations(int32_t radius_mm, int32_t view_mm, int32_t chord_mm, int32_t edge_mm,
                         int32_t out[][2], int32_t max, int32_t *overflow)
{
    if (view_mm <= 0 || chord_mm <= 0 || radius_mm < 0 || edge_mm < 0)
        return -1;
    if (radius_mm <= view_mm)
        return 0;
    const int64_t span = (int64_t)radius_mm - (edge_mm ? edge_mm : view_mm);
    int64_t a_v[MG_COVER_MAX_RINGS];
    int32_t m[MG_COVER_MAX_RINGS];
    int32_t n = 0;
    /* each ring as far out as the strip allows, the last at span; inner: the ring inside's
     * radius (its sides' midpoints, its reach outward), the start's 0 for the first */
    for (int64_t inner = 0; inner < span; n++) {
        if (n >= MG_COVER_MAX_RINGS) {
            *overflow = 1;
            return 0;
        }
        int64_t a = span < inner + 2 * (int64_t)view_mm ? span : inner + 2 * (int64_t)view_mm;
        ring(a, chord_mm, &a_v[n], &m[n]);
        /* vertices outside the circle by the sagitta: a ring's reach inward is from them */
        while (a_v[n] - inner > 2 * (int64_t)view_mm) {
            a -= a_v[n] - inner - 2 * (int64_t)view_mm;
            ring(a, chord_mm, &a_v[n], &m[n]);
        }
        if (a <= inner)
            return -1; /* sides too long for the strip: no ring gets farther out */
        inner = a;
    }
    int32_t count = 0;
    for (int32_t k = 0; k < n; k++)
        for (int32_t j = 0; j <= m[k]; j++) {
            if (count >= max) {
                *overflow = 1;
                return count;
            }
            const int32_t phi = (int32_t)((int64_t)TWO_PI_MRAD * j / m[k]);
            out[count][0] = (int32_t)((a_v[k] * mg_cos_q12(phi)) >> 12);
            out[count++][1] = (int32_t)((a_v[k] * mg_sin_q12(phi)) >> 12);
        }
    return count;
}

void mg_leg_to(const int32_t pose[3], const int32_t station[2], int32_t *turn_mrad,
               int32_t *drive_mm)
{
    const int64_t dx = (int64_t)station[0] - pose[0], dy = (int64_t)station[1] - pose[1];
    *turn_mrad = mg_wrap_mrad((int64_t)mg_atan2_mrad(dy, dx) - pose[2]);
    *drive_mm = (int32_t)mg_isqrt(dx * dx + dy * dy);
}

void mg_to_odometry(const int32_t origin[3], const int32_t xy[2], int32_t out[2])
{
    const int64_t c = mg_cos_q12(origin[2]), s = mg_sin_q12(origin[2]);
    out[0] = (int32_t)(origin[0] + ((xy[0] * c - xy[1] * s) >> 12));
    out[1] = (int32_t)(origin[1] + ((xy[0] * s + xy[1] * c) >> 12));
}
