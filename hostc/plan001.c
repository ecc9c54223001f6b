/* 001's planning among obstacles whole (host/planning/bezier001.py plan_001, whose docstring
 * gives the choices): the regions, the end points facing the start, the candidates of
 * eqs. (7)-(11), the coarse pass with its anytime cut (bezier001.c), D_m of eq. (18) of the
 * cheapest, eq. (18)'s pool and the fine check; the modelled cost as plan_001 charges it. */
#include "plan001.h"

#include "bezier.h"
#include "blocked_q.h"
#include "candidates.h"
#include "grasp_circle.h"
#include "isqrt.h"
#include "kernels.h"
#include "trig.h"

#if MG_GEO_HEAD != 3 || MG_REGION_WORDS != 12 || MG_CLEAR_WORDS != 11
#error "mg_plan001_work_t's geo and words follow bezier.h's and clearance.c's layouts"
#endif

/* bezier001.py SETUP_OPS, REGION_OPS (a region's words, the object-echo test, the grown
 * copy's words), END_POINT_OPS_EACH + FACING_OPS; control_points.py CANDIDATE_OPS;
 * clearance_q.py CLEARANCE_OPS */
static const mg_ops_t SETUP001 = {0, 0, 2450, 220, 1, 21, 0, 2, 0, 0, 0};
static const mg_ops_t REGION = {0, 0, 2458, 256, 16, 100, 0, 32, 0, 0, 0};
static const mg_ops_t END_POINT = {0, 0, 48, 6, 2, 13, 1, 4, 0, 0, 0};
static const mg_ops_t CANDIDATE = {0, 0, 40, 1, 0, 16, 0, 0, 0, 0, 0};
static const mg_ops_t CLEARANCE = {0, 0, 462, 58, 0, 24, 0, 0, 0, 0, 0};
#define DIVS_001 3 /* 64-bit quotients per sample of 001's checks */
#define ON_CIRCLE_Q4 16 /* POS_PER_M // 1000: within 1 mm of the circle */

static const char *const REASON_NAMES[MG_PLAN001_REASONS] = {
    "ok", "time_not_increasing", "speed", "accel", "radius", "grasp_circle", "obstacle",
    "budget", "range"};

static mg_ops_t setup_ops(int32_t n_regions, int32_t n_e, int32_t n_cand, int ends)
{
    mg_ops_t ops = mg_ops_add(SETUP001, mg_ops_scaled(REGION, n_regions));
    ops = mg_ops_add(ops, mg_ops_scaled(CANDIDATE, n_cand));
    return ends ? mg_ops_add(ops, mg_ops_scaled(END_POINT, n_e)) : ops;
}

/* order[0..n) stably sorted by key[order[i]] ascending (bottom-up merge) */
static void stable_sort(int32_t *order, int32_t *scratch, int32_t n, const int64_t *key)
{
    for (int32_t width = 1; width < n; width *= 2) {
        for (int32_t lo = 0; lo < n; lo += 2 * width) {
            const int32_t mid = lo + width < n ? lo + width : n;
            const int32_t hi = lo + 2 * width < n ? lo + 2 * width : n;
            int32_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi)
                scratch[k++] = key[order[j]] < key[order[i]] ? order[j++] : order[i++];
            while (i < mid)
                scratch[k++] = order[i++];
            while (j < hi)
                scratch[k++] = order[j++];
        }
        for (int32_t i = 0; i < n; i++)
            order[i] = scratch[i];
    }
}

static void geo_words(const int64_t target_q4[2], int64_t circle_r2, const mg_region_t *regions,
                      int32_t n, int64_t grow_q4, int64_t *geo)
{
    geo[0] = target_q4[0];
    geo[1] = target_q4[1];
    geo[2] = circle_r2;
    for (int32_t r = 0; r < n; r++) {
        mg_region_t g = regions[r];
        g.r_r_q4 += grow_q4;
        mg_region_geo(&g, geo + MG_GEO_HEAD + MG_REGION_WORDS * r);
    }
}

static int object_echo(const mg_region_t *reg, const int64_t target_q4[2], int64_t tol_q4)
{
    int64_t words[MG_CLEAR_WORDS];
    mg_region_clear(reg, words);
    return mg_path_clearance(words, 1, &target_q4[0], &target_q4[1], 1) + reg->r_r_q4 <= tol_q4;
}

/* the regions tested: the remembered ones, then the reading's, less the object's echoes;
 * returns their number, *n_all all of them (the set-up charged) */
static int32_t regions_of(const mg_params001_t *p, const int64_t start_q4[2],
                          int32_t heading_mrad, const int64_t target_q4[2],
                          const int32_t *sonar_mm, const mg_region_t *known, int32_t n_known,
                          mg_region_t *out, int32_t *n_all)
{
    mg_region_t scan[MG_SONAR_MAX_REGIONS];
    int32_t dropped = 0, n = 0;
    if (n_known > MG_PLAN001_MAX_KNOWN)
        n_known = MG_PLAN001_MAX_KNOWN;
    const int32_t n_scan = mg_sonar_regions(&p->sonar, start_q4[0], start_q4[1],
                                            (int64_t)heading_mrad * 1000, sonar_mm, scan,
                                            &dropped);
    for (int32_t i = 0; i < n_known + n_scan; i++) {
        const mg_region_t *r = i < n_known ? &known[i] : &scan[i - n_known];
        if (!object_echo(r, target_q4, p->echo_tol_q4))
            out[n++] = *r;
    }
    *n_all = n_known + n_scan;
    return n;
}

/* eq. (18)'s D_m of the cheapest coarse-feasible curves as far as the budget leaves room */
static void clearances(const mg_params001_t *p, const mg_region_t *regions, int32_t n_reg,
                       mg_plan001_work_t *w, mg_plan001_t *out)
{
    int64_t *words = w->words;
    int64_t x[MG_PLAN001_MAX_SAMPLES], y[MG_PLAN001_MAX_SAMPLES];
    const int32_t n = out->n_samples;
    int32_t n_ok = 0;
    for (int32_t i = 0; i < out->n_cand; i++) {
        w->clear_q4[i] = MG_NO_REGION_Q4;
        if (w->reason[i] == MG_OK && n_reg > 0) {
            w->clear_q4[i] = 0; /* D_m unknown: eq. (18) does not prefer it */
            w->order[n_ok++] = i;
        }
    }
    if (n_ok == 0)
        return;
    const mg_ops_t each = mg_ops_scaled(CLEARANCE, (int64_t)(n - 1) * n_reg);
    const int64_t each_us = mg_ops_time_us(&each) > 1 ? mg_ops_time_us(&each) : 1;
    const int64_t room = p->budget_us + 10000 - mg_ops_time_us(&out->ops);
    const int64_t fit = room <= 0 ? 0 : (room / each_us < n_ok ? room / each_us : n_ok);
    if (fit == 0)
        return;
    stable_sort(w->order, w->scratch, n_ok, w->cost);
    for (int32_t r = 0; r < n_reg; r++)
        mg_region_clear(&regions[r], words + MG_CLEAR_WORDS * r);
    for (int32_t k = 0; k < fit; k++) {
        const int32_t i = w->order[k];
        mg_curve_positions_q(w->ctrl + 12 * i, n, x, y);
        w->clear_q4[i] = mg_path_clearance(words, n_reg, x + 1, y + 1, n - 1);
    }
    out->ops = mg_ops_add(out->ops, mg_ops_scaled(each, fit));
}

/* the pool of eq. (18) re-checked at n_fine samples in cost order until one passes */
static void fine_check(const mg_params001_t *p, const int64_t *geo, int32_t n_reg,
                       mg_plan001_work_t *w, mg_plan001_t *out)
{
    int32_t n_pool = 0, n_wide = 0;
    for (int32_t i = 0; i < out->n_cand; i++)
        if (w->reason[i] == MG_OK && w->clear_q4[i] > p->t_d_q4)
            n_wide++;
    for (int32_t i = 0; i < out->n_cand; i++)
        if (w->reason[i] == MG_OK && (n_wide == 0 || w->clear_q4[i] > p->t_d_q4))
            w->order[n_pool++] = i;
    stable_sort(w->order, w->scratch, n_pool, w->cost);
    if (n_pool > p->max_fine)
        n_pool = p->max_fine;
    const mg_ops_t worst = mg_sample_ops(p->n_fine, 0, 1, n_reg, DIVS_001);
    const int64_t budget_us = p->total_budget_us - mg_ops_time_us(&out->ops);
    mg_ops_t ops = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    out->fine_last = -1;
    for (int32_t k = 0; k < n_pool; k++) {
        if (mg_ops_time_us(&ops) + mg_ops_time_us(&worst) > budget_us) {
            out->fine_budget = 1;
            break;
        }
        const int32_t i = w->order[k];
        int32_t first = 0;
        int64_t len = 0, kint = 0;
        const int32_t why = mg_bezier_curve(w->ctrl + 12 * i, p->n_fine, p->lim, geo, n_reg,
                                            &first, &len, &kint);
        ops = mg_ops_add(ops, mg_curve_ops(first, p->n_fine, 0, 1, n_reg, DIVS_001));
        if (why == MG_OK) {
            out->best = i;
            for (int c = 0; c < 12; c++)
                out->best_ctrl[c] = w->ctrl[12 * i + c];
            break;
        }
        out->fine_last = why;
    }
    out->ops = mg_ops_add(out->ops, ops);
}

void mg_plan001(const mg_params001_t *p, const int64_t start_q4[2], const int64_t vel_q4[2],
                int32_t heading_mrad, const int64_t target_q4[2], const int32_t *sonar_mm,
                const mg_region_t *known, int32_t n_known, mg_plan001_work_t *w,
                mg_plan001_t *out)
{
    mg_region_t *regions = w->regions;
    int64_t *geo = w->geo;
    int64_t ends[2 * MG_PLAN001_MAX_ENDS], facing[MG_PLAN001_MAX_ENDS];
    int32_t dirs[2 * MG_PLAN001_MAX_ENDS], keep[MG_PLAN001_MAX_ENDS];
    int32_t keep_scratch[MG_PLAN001_MAX_ENDS], n_all = 0;
    static const mg_plan001_t zero;
    *out = zero;
    out->best = -1;
    out->fine_last = -1;
    const int32_t n_reg = regions_of(p, start_q4, heading_mrad, target_q4, sonar_mm, known,
                                     n_known, regions, &n_all);
    out->n_regions = n_reg;
    out->ops = setup_ops(n_all, p->n_e, 0, 0);
    const int64_t to_start[2] = {start_q4[0] - target_q4[0], start_q4[1] - target_q4[1]};
    const int64_t dist = mg_isqrt64((uint64_t)(to_start[0] * to_start[0]
                                               + to_start[1] * to_start[1]));
    if (dist <= p->l_e_q4 + ON_CIRCLE_Q4) {
        out->status = MG_PLAN001_ON_CIRCLE;
        return;
    }
    if (p->n_e > MG_PLAN001_MAX_ENDS || p->n_coarse_max > MG_PLAN001_MAX_SAMPLES
        || p->n_fine > MG_PLAN001_MAX_SAMPLES
        || mg_end_points_q(target_q4, p->l_e_q4, p->n_e, ends, dirs) != 0) {
        out->status = MG_PLAN001_TOO_MANY;
        return;
    }
    /* an end point faces the start when (q_e - P_i).(q_s - P_i) >= cos(angle) l_e |q_s P_i| */
    const int64_t floor_q = ((int64_t)p->facing_cos_q12 * p->l_e_q4 * dist) >> 12;
    for (int32_t k = 0; k < p->n_e; k++) {
        facing[k] = -((ends[2 * k] - target_q4[0]) * to_start[0]
                      + (ends[2 * k + 1] - target_q4[1]) * to_start[1]);
        if (-facing[k] >= floor_q)
            keep[out->n_ends++] = k;
    }
    stable_sort(keep, keep_scratch, out->n_ends, facing); /* most promising end points first */
    out->ops = setup_ops(n_all, p->n_e, 0, 1);
    int32_t fallback[2], d0[2];
    mg_unit_q14(-to_start[0], -to_start[1], fallback);
    mg_start_direction_q(vel_q4, 1, heading_mrad, fallback, p->moving_q4, d0);
    mg_plan_numbers_t num;
    mg_plan_numbers(dist, p->v0_mm_s, p->t_s_ms, &num);
    out->n_i = (int32_t)num.n_i;
    const int64_t n_rows = (int64_t)out->n_ends * num.n_i;
    const mg_ops_t one = mg_sample_ops(1, 0, 1, n_reg, DIVS_001);
    const mg_ops_t none = mg_sample_ops(0, 0, 1, n_reg, DIVS_001);
    const int64_t per_sample = mg_ops_cycles(&one) - mg_ops_cycles(&none);
    const int64_t expected_q = (per_sample * p->expected_q16) >> 16;
    mg_choose_sampling(n_rows, expected_q > 1 ? expected_q : 1,
                       p->budget_us - mg_ops_time_us(&out->ops), p->n_coarse_min,
                       p->n_coarse_max, &out->n_samples, &out->stride);
    const int64_t n_cand = n_rows == 0 ? 0 : (n_rows + out->stride - 1) / out->stride;
    if (n_cand > MG_PLAN001_MAX_CAND) {
        out->status = MG_PLAN001_TOO_MANY;
        return;
    }
    out->n_cand = (int32_t)n_cand;
    for (int32_t i = 0; i < out->n_cand; i++) {
        const int64_t row = (int64_t)i * out->stride;
        const int32_t k = keep[row / num.n_i];
        mg_control_point_row(start_q4, d0, ends + 2 * k, dirs + 2 * k, &num,
                             1 + row % num.n_i, w->ctrl + 12 * i);
    }
    out->ops = setup_ops(n_all, p->n_e, out->n_cand, 1);
    /* the coarse pass: regions grown by a quarter of the samples' straight-line spacing */
    const int32_t n = out->n_samples;
    int64_t grow = dist / (4 * (int64_t)(n - 1));
    if (grow < p->coarse_inflate_q4)
        grow = p->coarse_inflate_q4;
    geo_words(target_q4, p->circle_r2, regions, n_reg, grow, geo);
    const int32_t taken = mg_bezier001_coarse(
        w->ctrl, out->n_cand, n, p->lim_coarse, geo, n_reg, (int32_t)per_sample,
        (int32_t)mg_ops_cycles(&none),
        (int32_t)((p->budget_us - mg_ops_time_us(&out->ops)) * 400), p->k1_q16, p->k2_q16,
        w->reason, w->first, w->cost);
    for (int32_t i = 0; i < taken; i++)
        out->ops = mg_ops_add(out->ops, mg_curve_ops(w->first[i], n, 0, 1, n_reg, DIVS_001));
    for (int32_t i = 0; i < out->n_cand; i++) {
        out->reasons[w->reason[i]]++;
        if (w->reason[i] == MG_OK)
            out->n_feasible++;
    }
    clearances(p, regions, n_reg, w, out);
    if (out->n_feasible == 0) {
        out->status = MG_PLAN001_NONE_FEASIBLE;
        return;
    }
    geo_words(target_q4, p->circle_r2, regions, n_reg, 0, geo);
    fine_check(p, geo, n_reg, w, out);
    out->status = out->best < 0 ? MG_PLAN001_FINE_FAILED : MG_PLAN001_OK;
}

/* append s to buf at *at (cap bytes, always 0-terminated) */
static void put(char *buf, int32_t cap, int32_t *at, const char *s)
{
    while (*s && *at < cap - 1)
        buf[(*at)++] = *s++;
    buf[*at] = 0;
}

static void put_int(char *buf, int32_t cap, int32_t *at, int32_t v)
{
    char digits[12];
    int32_t n = 0;
    do {
        digits[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v > 0);
    char out[12];
    for (int32_t i = 0; i < n; i++)
        out[i] = digits[n - 1 - i];
    out[n] = 0;
    put(buf, cap, at, out);
}

void mg_plan001_reason(const mg_plan001_t *plan, char *buf, int32_t cap)
{
    /* candidates.py summarize_rejections: the reasons by name, sorted */
    static const int32_t BY_NAME[MG_PLAN001_REASONS - 1] = {
        MG_ACCEL, MG_BUDGET, MG_CIRCLE, MG_OBSTACLE, MG_RADIUS, MG_RANGE, MG_SPEED, MG_TIME};
    int32_t at = 0;
    if (cap <= 0)
        return;
    buf[0] = 0;
    switch (plan->status) {
    case MG_PLAN001_OK:
        put(buf, cap, &at, "ok");
        return;
    case MG_PLAN001_ON_CIRCLE:
        put(buf, cap, &at, "already on the grasp circle");
        return;
    case MG_PLAN001_TOO_MANY:
        put(buf, cap, &at, "too many candidates for the C planner");
        return;
    case MG_PLAN001_FINE_FAILED:
        put(buf, cap, &at, "coarse-feasible candidates failed the fine check (");
        if (plan->fine_budget)
            put(buf, cap, &at, "ARM9 budget spent, last: ");
        put(buf, cap, &at, plan->fine_last < 0 ? "none tried" : REASON_NAMES[plan->fine_last]);
        put(buf, cap, &at, ")");
        return;
    default:
        break;
    }
    put(buf, cap, &at, "no feasible candidate (");
    int first = 1;
    for (int32_t k = 0; k < MG_PLAN001_REASONS - 1; k++) {
        const int32_t code = BY_NAME[k];
        if (plan->reasons[code] == 0)
            continue;
        put(buf, cap, &at, first ? "" : ", ");
        put(buf, cap, &at, REASON_NAMES[code]);
        put(buf, cap, &at, ": ");
        put_int(buf, cap, &at, plan->reasons[code]);
        first = 0;
    }
    put(buf, cap, &at, ")");
}
