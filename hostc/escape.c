/* A straight way out through free sonar space (host/planning/escape.py): a segment's samples
 * tested against eq. (16) as the planner tests them (bezier.c), and where the start already
 * lies in a region, its distance to the echo arc as D_m of eq. (18) (clearance.c) not
 * shrinking by more than LEAVE_TOL; the headings tried nearest the object's bearing first. */
#include "escape.h"

#include "bezier.h"
#include "candidates.h"
#include "fixedpoint.h"
#include "kernels.h"

#define LEAVE_TOL_Q4 320 /* escape.py LEAVE_TOL_M, 0.02 m */
#define TURN_URAD 6283185
#define GEO_EACH (MG_GEO_HEAD + MG_REGION_WORDS)

/* clearance_q.py CLEARANCE_OPS: one sample and region of D_m */
static const mg_ops_t CLEARANCE = {0, 0, 462, 58, 0, 24, 0, 0, 0, 0, 0};

static int64_t wrap_urad(int64_t a)
{
    return mg_floor_mod(a + TURN_URAD / 2, TURN_URAD) - TURN_URAD / 2;
}

static int64_t point_clearance(const int64_t *words, int64_t x, int64_t y)
{
    return mg_path_clearance(words, 1, &x, &y, 1);
}

int mg_segment_clear_q(const int64_t *geo_each, const int64_t *clear_each, int32_t n_reg,
                       int64_t px_q4, int64_t py_q4, int32_t heading_mrad, int64_t length_q4,
                       int32_t samples, int leave_ok, mg_ops_t *ops)
{
    const mg_ops_t per = mg_ops_add(mg_position_ops(),
                                    mg_ops_scaled(mg_region_sample_ops(), n_reg));
    const mg_ops_t luts = {0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0}, none = {0, 0, 0, 0, 0, 0, 0, 0, 0,
                                                                     0, 0};
    *ops = none;
    if (length_q4 <= 0)
        return 1;
    *ops = mg_ops_add(mg_ops_scaled(per, samples), luts);
    if (leave_ok)
        *ops = mg_ops_add(*ops, mg_ops_scaled(CLEARANCE, (int64_t)(samples + 1) * n_reg));
    const int64_t s = mg_sin_q12(heading_mrad), c = mg_cos_q12(heading_mrad);
    for (int32_t r = 0; r < n_reg; r++) {
        const int64_t *geo = geo_each + GEO_EACH * r;
        const int64_t *words = clear_each + MG_CLEAR_WORDS * r;
        int started = 0; /* the start's own test, made once the segment enters the region */
        int64_t d_start = 0;
        for (int32_t j = 1; j <= samples; j++) {
            const int64_t dist = length_q4 * j / samples;
            const int64_t x = px_q4 + ((dist * c) >> 12), y = py_q4 + ((dist * s) >> 12);
            if (!mg_bezier_in_regions(geo, 1, x, y))
                continue;
            if (!leave_ok)
                return 0;
            if (!started) {
                if (!mg_bezier_in_regions(geo, 1, px_q4, py_q4))
                    return 0;
                d_start = point_clearance(words, px_q4, py_q4);
                started = 1;
            }
            if (point_clearance(words, x, y) < d_start - LEAVE_TOL_Q4)
                return 0;
        }
    }
    return 1;
}

/* escape.py's order: the side's headings (and the goal's) first, then nearer the goal, then
 * the smaller heading */
static int before(int64_t a, int64_t b, int64_t goal, int32_t side)
{
    const int64_t da = wrap_urad(a - goal), db = wrap_urad(b - goal);
    const int oa = side * da < 0, ob = side * db < 0;
    if (oa != ob)
        return oa < ob;
    const int64_t ma = da < 0 ? -da : da, mb = db < 0 ? -db : db;
    if (ma != mb)
        return ma < mb;
    return a < b;
}

int mg_escape_heading_q(const int64_t *geo_each, const int64_t *clear_each, int32_t n_reg,
                        int64_t px_q4, int64_t py_q4, int64_t h_urad, int64_t goal_urad,
                        int64_t step_urad, int32_t n_side, int64_t length_q4, int32_t samples,
                        int32_t side, int64_t *out_urad, mg_ops_t *ops)
{
    const mg_ops_t none = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    *ops = none;
    if (n_side < 0 || 2 * n_side + 1 > MG_ESCAPE_MAX_HEADINGS || samples < 1 || length_q4 <= 0)
        return 0;
    int64_t heads[MG_ESCAPE_MAX_HEADINGS];
    int32_t n = 0;
    for (int32_t j = -n_side; j <= n_side; j++) { /* insertion in escape.py's order */
        const int64_t h = h_urad + j * step_urad;
        int32_t i = n++;
        while (i > 0 && before(h, heads[i - 1], goal_urad, side)) {
            heads[i] = heads[i - 1];
            i--;
        }
        heads[i] = h;
    }
    for (int32_t i = 0; i < n; i++) {
        mg_ops_t more;
        const int clear = mg_segment_clear_q(geo_each, clear_each, n_reg, px_q4, py_q4,
                                             (int32_t)mg_floor_div(heads[i], 1000), length_q4,
                                             samples, 1, &more);
        *ops = mg_ops_add(*ops, more);
        if (clear) {
            *out_urad = wrap_urad(heads[i]);
            return 1;
        }
    }
    return 0;
}
