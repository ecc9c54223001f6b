/* Single "+" spoke of paper 000 (section III.A, Fig. 3): slope k_l and width w_l of the "+"
 * nearest the image centre. The steps and their reasons are those of host/vision/spoke.py,
 * which this follows line by line (same integers). The local dark mask (grey below the mid
 * level of the "+" box and 4 px around) is tested in place, not written. */
#include "isqrt.h"
#include "kernels.h"

#define K_S 5
#define SECOND_PASS_Q12 722
#define MAX_ANGLE_MRAD 524

typedef struct {
    const uint8_t *grey;
    int32_t W, H, t, rx0, ry0, rx1, ry1; /* the local mask's threshold and window */
} local_t;

typedef struct {
    int ok; /* 1 when the arm's direction exists */
    int32_t du, dv, reach;
} arm_t;

static int64_t floordiv64(int64_t a, int64_t b) /* b > 0 */
{
    int64_t q = a / b;
    return (a % b != 0 && a < 0) ? q - 1 : q;
}

static int dark_at(const local_t *L, int32_t x, int32_t y)
{
    return x >= L->rx0 && x < L->rx1 && y >= L->ry0 && y < L->ry1
        && L->grey[y * L->W + x] < L->t;
}

/* one side arm's centroid direction (Q4 px) beyond half the reach in its 45-degree cone */
static void arm_direction(const local_t *L, const mg_plus_t *p, int32_t side, arm_t *a)
{
    const int32_t x = p->box[0], y = p->box[1], w = p->box[2], h = p->box[3];
    int32_t dmax = -1;
    a->ok = 0;
    for (int32_t yy = y; yy < y + h; yy++)
        for (int32_t xx = x; xx < x + w; xx++) {
            if (!dark_at(L, xx, yy))
                continue;
            const int32_t du = (16 * xx - p->u_q4) * side, dv = 16 * yy - p->v_q4;
            if (du > (dv < 0 ? -dv : dv) && du > dmax)
                dmax = du;
        }
    if (dmax < 0)
        return;
    const int32_t reach = dmax / 16;
    int64_t su = 0, sv = 0;
    int32_t n = 0;
    for (int32_t yy = y; yy < y + h; yy++)
        for (int32_t xx = x; xx < x + w; xx++) {
            if (!dark_at(L, xx, yy))
                continue;
            const int32_t du = (16 * xx - p->u_q4) * side, dv = 16 * yy - p->v_q4;
            if (du > (dv < 0 ? -dv : dv) && 2 * du > 16 * reach) {
                su += du;
                sv += dv;
                n++;
            }
        }
    if (!n)
        return;
    a->ok = 1;
    a->du = (int32_t)floordiv64(su, n);
    a->dv = (int32_t)floordiv64(sv, n);
    a->reach = reach;
}

/* centre and length (Q4) of the dark run in column u nearest the predicted row */
static int run_centre(const local_t *L, int32_t u, int32_t v_pred, int32_t *c_q4,
                      int32_t *len_q4)
{
    const int32_t n = L->H;
    const int32_t v = v_pred < 0 ? 0 : (v_pred > n - 1 ? n - 1 : v_pred);
    int32_t best = -1;
    for (int32_t d = 0; d < n; d++) {
        if (v - d >= 0 && v - d < n && dark_at(L, u, v - d))
            best = v - d;
        else if (v + d >= 0 && v + d < n && dark_at(L, u, v + d))
            best = v + d;
        if (best >= 0 || d > 8)
            break;
    }
    if (best < 0)
        return 0;
    int32_t top = best, bot = best, tq, bq;
    while (top > 0 && dark_at(L, u, top - 1))
        top--;
    while (bot < n - 1 && dark_at(L, u, bot + 1))
        bot++;
    if (!mg_edge_q4(L->grey + u, L->W, n, top, -1, &tq)
        || !mg_edge_q4(L->grey + u, L->W, n, bot, +1, &bq))
        return 0;
    *c_q4 = (int32_t)floordiv64((int64_t)tq + bq, 2);
    *len_q4 = bq - tq;
    return 1;
}

/* central points (u, v pairs) and run lengths of one side arm; 0 when a column fails. *cols:
 * the columns host/vision/spoke.py _scan_arm charges (all when they are found, up to the one
 * without a run, none when a column leaves the frame) */
static int scan_arm(const local_t *L, const mg_plus_t *p, int32_t side, int has_slope,
                    int32_t slope_q12, const arm_t *a, int32_t *pts, int32_t *runs,
                    int32_t *cols)
{
    *cols = 0;
    if (!a->ok)
        return 0;
    int32_t adu = a->du, adv = a->dv;
    if (has_slope) {
        adu = 4096;
        adv = side * slope_q12;
    }
    for (int32_t j = 0; j < K_S; j++) {
        const int32_t off = a->reach * (50 + 3 * j) / 100;
        const int32_t u = (p->u_q4 + 8) / 16 + side * off;
        if (u < 0 || u >= L->W) {
            *cols = 0;
            return 0;
        }
        *cols = j + 1;
        const int32_t v_pred = (int32_t)floordiv64(
            p->v_q4 + mg_div_round((int64_t)16 * off * adv, adu), 16);
        int32_t c, len;
        if (!run_centre(L, u, v_pred, &c, &len))
            return 0;
        pts[2 * j] = 16 * u;
        pts[2 * j + 1] = c;
        runs[j] = len;
    }
    return 1;
}

typedef struct {
    int32_t pts[4 * K_S]; /* left arm left to right, then right arm */
    int32_t n_pts, run_sum, n_runs, k_l, reach;
} template_t;

/* one pass of the Fig. 3 template on both side arms, its counts added to *o (both arms are
 * scanned, as spoke.py charges them) */
static int template_pass(const local_t *L, const mg_plus_t *p, int has_slope, int32_t slope,
                         const arm_t *arms, template_t *out, mg_ops_t *o)
{
    int32_t pl[2 * K_S], pr[2 * K_S], rl[K_S], rr[K_S], all[2 * K_S], cols_l, cols_r;
    const int ok_l = scan_arm(L, p, -1, has_slope, slope, &arms[0], pl, rl, &cols_l);
    const int ok_r = scan_arm(L, p, +1, has_slope, slope, &arms[1], pr, rr, &cols_r);
    /* a column: two sub-pixel edges (dark_blobs.py EDGE_OPS) and the run's search
     * (spoke.py _COLUMN_OPS) */
    const int64_t cols = cols_l + cols_r;
    mg_ops_charge(o, (2 * 14 + 20) * cols, 0, (2 * 30 + 30) * cols, (2 * 10 + 20) * cols, 0, 0,
                  (2 * 1 + 1) * cols, 0, 0);
    if (!ok_l || !ok_r)
        return 0;
    const int32_t reach = (arms[0].reach + arms[1].reach) / 2;
    for (int32_t i = 0; i < K_S; i++) {
        all[i] = rl[i];
        all[K_S + i] = rr[i];
    }
    for (int32_t i = 1; i < 2 * K_S; i++) /* insertion sort: the median of ten */
        for (int32_t j = i; j > 0 && all[j - 1] > all[j]; j--) {
            const int32_t t = all[j];
            all[j] = all[j - 1];
            all[j - 1] = t;
        }
    const int32_t med = all[K_S];
    int32_t kl = 0, kr = 0, n = 0, run_sum = 0;
    for (int32_t i = 0; i < K_S; i++) {
        kl += 17 * med <= 20 * rl[i] && 20 * rl[i] <= 26 * med;
        kr += 17 * med <= 20 * rr[i] && 20 * rr[i] <= 26 * med;
    }
    if (kl < 3 || kr < 3)
        return 0;
    for (int32_t i = K_S - 1; i >= 0; i--) /* left arm: left to right */
        if (17 * med <= 20 * rl[i] && 20 * rl[i] <= 26 * med) {
            out->pts[2 * n] = pl[2 * i];
            out->pts[2 * n + 1] = pl[2 * i + 1];
            run_sum += rl[i];
            n++;
        }
    for (int32_t i = 0; i < K_S; i++)
        if (17 * med <= 20 * rr[i] && 20 * rr[i] <= 26 * med) {
            out->pts[2 * n] = pr[2 * i];
            out->pts[2 * n + 1] = pr[2 * i + 1];
            run_sum += rr[i];
            n++;
        }
    /* k_l: least-squares slope through the central points of both arms */
    int64_t su = 0, sv = 0, suu = 0, suv = 0;
    for (int32_t i = 0; i < n; i++) {
        su += out->pts[2 * i];
        sv += out->pts[2 * i + 1];
    }
    for (int32_t i = 0; i < n; i++) {
        const int64_t du = n * (int64_t)out->pts[2 * i] - su;
        const int64_t dv = n * (int64_t)out->pts[2 * i + 1] - sv;
        suu += du * du;
        suv += du * dv;
    }
    if (suu == 0)
        return 0;
    const int32_t k_l = mg_div_round(suv * 4096, suu);
    mg_ops_charge(o, 0, 0, 12 * (int64_t)n + 8 * K_S, 4 * K_S, 0, 6 * (int64_t)n, n + 1, 0, 0);
    int64_t worst = 0;
    for (int32_t i = 0; i < n; i++) {
        const int64_t du = n * (int64_t)out->pts[2 * i] - su;
        int64_t e = n * (int64_t)out->pts[2 * i + 1] - sv - mg_div_round(k_l * du, 4096);
        e = e < 0 ? -e : e;
        if (e > worst)
            worst = e;
    }
    if (worst > n * 24)
        return 0;
    out->n_pts = n;
    out->run_sum = run_sum;
    out->n_runs = n;
    out->k_l = k_l;
    out->reach = reach;
    return 1;
}

/* the "+" template: dark on all four spokes at 0.6 of the reach, light on the diagonals */
static int is_cross(const local_t *L, int32_t uc, int32_t vc, int32_t angle, int32_t reach)
{
    const int32_t c = mg_cos_q12(angle), s = mg_sin_q12(angle);
    const int32_t dir[8][2] = {{c, s}, {-s, c}, {-c, -s}, {s, -c},
                               {c - s, s + c}, {-c - s, -s + c}, {-c + s, -s - c}, {c + s, s - c}};
    for (int32_t k = 0; k < 8; k++) {
        const int32_t r = k < 4 ? 6 * reach : 75 * reach / 10 * 2896 / 4096;
        const int32_t u = (int32_t)floordiv64(
            uc + floordiv64((int64_t)16 * r * dir[k][0], 10 * 4096) + 8, 16);
        const int32_t v = (int32_t)floordiv64(
            vc + floordiv64((int64_t)16 * r * dir[k][1], 10 * 4096) + 8, 16);
        if (u < 0 || u >= L->W || v < 0 || v >= L->H)
            return 0;
        if ((L->grey[v * L->W + u] < L->t) != (k < 4))
            return 0;
    }
    return 1;
}

int32_t mg_spoke(const uint8_t *grey, const int32_t *lab, int32_t W, int32_t H,
                 const int32_t *stats, int32_t n_lab, uint8_t *scratch, int32_t *out,
                 mg_ops_t *ops)
{
    mg_ops_t none, *o = ops != 0 ? ops : &none;
    mg_ops_clear(o);
    mg_plus_t *plus = (mg_plus_t *)scratch;
    int32_t *lvl = (int32_t *)(scratch + sizeof(mg_plus_t) * MG_MAX_PLUS);
    const int32_t n = mg_plus_candidates(grey, lab, W, H, stats, n_lab, plus, lvl, o);
    mg_ops_charge(o, 0, 0, 200, 0, 0, 0, 0, 0, 0); /* the call and its scratch (_CALL_OPS) */
    if (!n)
        return 0;
    mg_ops_charge(o, 0, 0, 4 * (int64_t)n, 0, 0, 2 * (int64_t)n, 0, 0, 0); /* the nearest */
    const int32_t cu = 8 * W, cv = 8 * H;
    const mg_plus_t *p = plus;
    int64_t bd = -1;
    for (int32_t i = 0; i < n; i++) { /* the "+" nearest the image centre (first of equals) */
        const int64_t du = plus[i].u_q4 - cu, dv = plus[i].v_q4 - cv;
        if (bd < 0 || du * du + dv * dv < bd) {
            bd = du * du + dv * dv;
            p = plus + i;
        }
    }
    local_t L;
    L.grey = grey;
    L.W = W;
    L.H = H;
    L.rx0 = p->box[0] - 4 < 0 ? 0 : p->box[0] - 4;
    L.ry0 = p->box[1] - 4 < 0 ? 0 : p->box[1] - 4;
    L.rx1 = p->box[0] + p->box[2] + 4 > W ? W : p->box[0] + p->box[2] + 4;
    L.ry1 = p->box[1] + p->box[3] + 4 > H ? H : p->box[1] + p->box[3] + 4;
    int32_t lo = 255, hi = 0;
    for (int32_t y = L.ry0; y < L.ry1; y++)
        for (int32_t x = L.rx0; x < L.rx1; x++) {
            const int32_t g = grey[y * W + x];
            lo = g < lo ? g : lo;
            hi = g > hi ? g : hi;
        }
    L.t = (lo + hi) / 2;
    /* the local mask's window: its level and its mask */
    const int64_t roi = (int64_t)(L.rx1 - L.rx0) * (L.ry1 - L.ry0);
    mg_ops_charge(o, 3 * roi, roi, 3 * roi, 0, 0, 0, 0, 0, 0);
    arm_t arms[2];
    arm_direction(&L, p, -1, &arms[0]);
    arm_direction(&L, p, +1, &arms[1]);
    /* both arms' directions: two passes over the box each (spoke.py _scan_arm) */
    const int64_t box = 2 * (int64_t)p->box[2] * p->box[3];
    mg_ops_charge(o, 2 * box, 0, 54 * box, 4 * box, 3 * box, 0, 2 * 2, 0, 0);
    template_t tp;
    if (!template_pass(&L, p, 0, 0, arms, &tp, o))
        return 0;
    if (tp.k_l > SECOND_PASS_Q12 || tp.k_l < -SECOND_PASS_Q12) {
        const int32_t k1 = tp.k_l;
        if (!template_pass(&L, p, 1, k1, arms, &tp, o))
            return 0;
    }
    const int32_t angle = mg_atan2_mrad(tp.k_l, 4096);
    if (angle > MAX_ANGLE_MRAD || angle < -MAX_ANGLE_MRAD)
        return 0;
    if (!is_cross(&L, p->u_q4, p->v_q4, angle, tp.reach))
        return 0;
    /* the template's eight pixels, a sine and a cosine (host/fixedpoint.py sin_ops) */
    mg_ops_charge(o, 8, 0, 40 + 2 * 10, 2 * 2, 2 * 1, 16 + 2 * 1, 0, 2 * 2, 0);
    const int32_t run = (int32_t)floordiv64(tp.run_sum, tp.n_runs);
    if (!(40 * tp.reach <= 100 * run / 16 && 100 * run / 16 <= 90 * tp.reach))
        return 0;
    /* the width's divisions, three atan2 (atan2_ops) and the isqrt of a 27-bit number
     * (isqrt_ops(1 << 26): 14 rounds) */
    mg_ops_charge(o, 0, 0, 40 + 3 * 14 + 4 * 14, 3 * 4 + 14, 3 * 1, 4, 2 * K_S + 2 + 3 * 1,
                  3 * 2, 0);
    const int32_t width = mg_div_round((int64_t)run * 4096,
                                       mg_isqrt32((uint32_t)(4096 * 4096 + tp.k_l * tp.k_l)));
    out[0] = p->u_q4;
    out[1] = p->v_q4;
    out[2] = tp.k_l;
    out[3] = angle;
    out[4] = width;
    out[5] = tp.n_pts;
    for (int32_t i = 0; i < 2 * tp.n_pts; i++)
        out[6 + i] = tp.pts[i];
    return 1;
}
