/* Dual "+" symbol of paper 000 (section III.A): both "+" centres, D_is = D_act f / d_pixel and
 * the foreshortening-corrected distance from the pair's second moments. The steps and their
 * reasons are those of host/vision/dual_plus.py, which this follows line by line (same
 * integers). Input: the front end's grey image, labels and component stats. */
#include "isqrt.h"
#include "kernels.h"

#define D_ACT_DMM 473
#define MIN_AREA_PX 12
#define SOLIDITY_MIN_PCT 45
#define SOLIDITY_MAX_PCT 88
#define SEP_MIN_Q4 32
#define SEP_MAX_Q4 88

typedef mg_plus_t plus_t;

static int32_t imax(int32_t a, int32_t b) { return a > b ? a : b; }
static int32_t imin(int32_t a, int32_t b) { return a < b ? a : b; }

int32_t mg_dual_plus_scratch_bytes(int32_t w, int32_t h)
{
    (void)w;
    return (int32_t)sizeof(plus_t) * MG_MAX_PLUS + 6 * 4 * (h + 2);
}

/* ---- unsigned 256-bit integers for the moment algebra of d_eff (products reach ~2^150) ---- */
#define NL 8
typedef struct { uint32_t w[NL]; } big_t;

static void big_copy(big_t *r, const big_t *a) /* word by word: no struct copy (no libc) */
{
    for (int i = 0; i < NL; i++)
        r->w[i] = a->w[i];
}

static void big_u64(big_t *r, uint64_t v)
{
    for (int i = 0; i < NL; i++)
        r->w[i] = 0;
    r->w[0] = (uint32_t)v;
    r->w[1] = (uint32_t)(v >> 32);
}

static int big_cmp(const big_t *a, const big_t *b)
{
    for (int i = NL - 1; i >= 0; i--)
        if (a->w[i] != b->w[i])
            return a->w[i] < b->w[i] ? -1 : 1;
    return 0;
}

static void big_add(big_t *r, const big_t *a, const big_t *b)
{
    uint64_t c = 0;
    for (int i = 0; i < NL; i++) {
        c += (uint64_t)a->w[i] + b->w[i];
        r->w[i] = (uint32_t)c;
        c >>= 32;
    }
}

static void big_sub(big_t *r, const big_t *a, const big_t *b) /* a >= b */
{
    int64_t c = 0;
    for (int i = 0; i < NL; i++) {
        c += (int64_t)a->w[i] - b->w[i];
        r->w[i] = (uint32_t)c;
        c = c < 0 ? -1 : 0;
    }
}

static void big_mul_u64(big_t *r, const big_t *a, uint64_t v)
{
    const uint32_t v0 = (uint32_t)v, v1 = (uint32_t)(v >> 32);
    big_t out;
    big_u64(&out, 0);
    for (int i = 0; i < NL; i++) {
        uint64_t c = 0;
        for (int j = 0; j < 2 && i + j < NL; j++) {
            c += (uint64_t)a->w[i] * (j ? v1 : v0) + out.w[i + j];
            out.w[i + j] = (uint32_t)c;
            c >>= 32;
        }
        for (int k = i + 2; c && k < NL; k++) {
            c += out.w[k];
            out.w[k] = (uint32_t)c;
            c >>= 32;
        }
    }
    big_copy(r, &out);
}

static void big_mul64(big_t *r, uint64_t a, uint64_t b)
{
    big_t t;
    big_u64(&t, a);
    big_mul_u64(r, &t, b);
}

static void big_shr(big_t *r, const big_t *a, int s) /* 0 <= s < 32 */
{
    for (int i = 0; i < NL; i++)
        r->w[i] = s ? (a->w[i] >> s) | (i + 1 < NL ? a->w[i + 1] << (32 - s) : 0) : a->w[i];
}

static int big_bitlen(const big_t *a)
{
    for (int i = NL - 1; i >= 0; i--)
        if (a->w[i])
            for (int b = 31; b >= 0; b--)
                if (a->w[i] >> b & 1)
                    return 32 * i + b + 1;
    return 0;
}

/* floor(sqrt(n)) digit by digit, host/fixedpoint.py isqrt_digits */
static void big_isqrt(big_t *res, const big_t *n_in)
{
    big_t n, bit, t;
    big_copy(&n, n_in);
    big_u64(res, 0);
    const int len = big_bitlen(&n);
    if (!len)
        return;
    const int e = (len - 1) & ~1;
    big_u64(&bit, 0);
    bit.w[e / 32] = 1u << (e % 32);
    for (int k = e; k >= 0; k -= 2) {
        big_add(&t, res, &bit);
        if (big_cmp(&n, &t) >= 0) {
            big_sub(&n, &n, &t);
            big_shr(res, res, 1);
            big_add(res, res, &bit);
        } else {
            big_shr(res, res, 1);
        }
        big_shr(&bit, &bit, 2);
    }
}

/* floor(num / den), den > 0: binary long division */
static void big_div(big_t *q, const big_t *num, const big_t *den)
{
    big_t r;
    big_u64(&r, 0);
    big_u64(q, 0);
    for (int i = big_bitlen(num) - 1; i >= 0; i--) {
        for (int k = NL - 1; k > 0; k--)
            r.w[k] = (r.w[k] << 1) | (r.w[k - 1] >> 31);
        r.w[0] = (r.w[0] << 1) | (num->w[i / 32] >> (i % 32) & 1);
        if (big_cmp(&r, den) >= 0) {
            big_sub(&r, &r, den);
            q->w[i / 32] |= 1u << (i % 32);
        }
    }
}

static uint64_t uabs64(int64_t v) { return v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v; }

static int64_t floordiv64(int64_t a, int64_t b) /* b > 0 */
{
    int64_t q = a / b;
    return (a % b != 0 && a < 0) ? q - 1 : q;
}

/* central second moments (sums of squared deviations, floored) */
static void central(const plus_t *p, int64_t c[3])
{
    const int64_t *m = p->m;
    c[0] = floordiv64(m[0] * m[3] - m[1] * m[1], m[0]);
    c[1] = floordiv64(m[0] * m[4] - m[1] * m[2], m[0]);
    c[2] = floordiv64(m[0] * m[5] - m[2] * m[2], m[0]);
}

/* d_eff^2 = lambda_max(C) p^T C^-1 p (host/vision/dual_plus.py _d_eff_q4); 0 when det <= 0.
 * The result is clamped to 2^40 (never reached by a pair that passed the separation test). */
static int64_t d_eff_q4(const plus_t *a, const plus_t *b, int32_t du, int32_t dv)
{
    int64_t ca[3], cb[3];
    central(a, ca);
    central(b, cb);
    const int64_t sa = a->m[0] * a->m[0], sb = b->m[0] * b->m[0];
    const int64_t xx = ca[0] * sb + cb[0] * sa, xy = ca[1] * sb + cb[1] * sa;
    const int64_t yy = ca[2] * sb + cb[2] * sa;
    big_t p, q, det, t, s, lam2, quad, num, den, res;
    big_mul64(&p, (uint64_t)xx, (uint64_t)yy);
    big_mul64(&q, uabs64(xy), uabs64(xy));
    if (big_cmp(&p, &q) <= 0)
        return 0;
    big_sub(&det, &p, &q);
    /* 2 lambda_max = xx + yy + isqrt((xx - yy)^2 + 4 xy^2) */
    big_mul64(&t, uabs64(xx - yy), uabs64(xx - yy));
    big_mul_u64(&s, &q, 4);
    big_add(&t, &t, &s);
    big_isqrt(&s, &t);
    big_u64(&lam2, (uint64_t)xx + (uint64_t)yy);
    big_add(&lam2, &lam2, &s);
    /* p^T adj(C) p = yy du^2 - 2 xy du dv + xx dv^2 (>= 0: adj(C) is positive definite) */
    big_mul64(&quad, (uint64_t)yy, (uint64_t)((int64_t)du * du));
    big_mul64(&t, (uint64_t)xx, (uint64_t)((int64_t)dv * dv));
    big_add(&quad, &quad, &t);
    const int64_t duv = (int64_t)du * dv;
    big_mul64(&t, uabs64(xy), 2 * uabs64(duv));
    if ((xy < 0) == (duv < 0) && xy && duv)
        big_sub(&quad, &quad, &t);
    else
        big_add(&quad, &quad, &t);
    /* lam2 < 2^64 here (xx, yy < 2^60) */
    big_mul_u64(&num, &quad, (uint64_t)lam2.w[0] | (uint64_t)lam2.w[1] << 32);
    big_add(&den, &det, &det);
    big_div(&t, &num, &den);
    big_isqrt(&res, &t);
    for (int i = 2; i < NL; i++)
        if (res.w[i])
            return (int64_t)1 << 40;
    const uint64_t r = (uint64_t)res.w[0] | (uint64_t)res.w[1] << 32;
    return r > ((uint64_t)1 << 40) ? (int64_t)1 << 40 : (int64_t)r;
}

/* twice the area of the convex hull of the component's pixel squares: the hull of each box
 * row's leftmost and rightmost pixel corners (every row of a component's box has a pixel),
 * as left and right chains over the corner levels 0..h (Andrew's monotone chain, by y) */
static int32_t hull_area2(const int32_t *lab, int32_t W, int32_t k, int32_t xi, int32_t yi,
                          int32_t wi, int32_t hi, int32_t *minx, int32_t *maxx, int32_t *lc,
                          int32_t *rc)
{
    for (int32_t y = 0; y < hi; y++) {
        const int32_t *row = lab + (yi + y) * W + xi;
        int32_t l = 0, r = wi - 1;
        while (row[l] != k)
            l++;
        while (row[r] != k)
            r--;
        minx[y] = y ? imin(minx[y], l) : l;
        maxx[y] = y ? imax(maxx[y], r + 1) : r + 1;
        minx[y + 1] = l;
        maxx[y + 1] = r + 1;
    }
    int32_t nl = 0, nr = 0;
    for (int32_t y = 0; y <= hi; y++) {
        while (nl >= 2) { /* left chain: drop a point that is not left of its neighbours */
            const int32_t ox = lc[2 * nl - 4], oy = lc[2 * nl - 3];
            const int32_t ax = lc[2 * nl - 2], ay = lc[2 * nl - 1];
            if ((ax - ox) * (y - oy) - (ay - oy) * (minx[y] - ox) < 0)
                break;
            nl--;
        }
        lc[2 * nl] = minx[y];
        lc[2 * nl + 1] = y;
        nl++;
        while (nr >= 2) {
            const int32_t ox = rc[2 * nr - 4], oy = rc[2 * nr - 3];
            const int32_t ax = rc[2 * nr - 2], ay = rc[2 * nr - 1];
            if ((ax - ox) * (y - oy) - (ay - oy) * (maxx[y] - ox) > 0)
                break;
            nr--;
        }
        rc[2 * nr] = maxx[y];
        rc[2 * nr + 1] = y;
        nr++;
    }
    /* shoelace over the right chain downwards, then the left chain upwards */
    int32_t s = 0, px = lc[0], py = lc[1];
    for (int32_t i = 0; i < nr; i++) {
        s += px * rc[2 * i + 1] - py * rc[2 * i];
        px = rc[2 * i];
        py = rc[2 * i + 1];
    }
    for (int32_t i = nl - 1; i >= 0; i--) {
        s += px * lc[2 * i + 1] - py * lc[2 * i];
        px = lc[2 * i];
        py = lc[2 * i + 1];
    }
    return s < 0 ? -s : s;
}

/* step 2: the dark components that look like a "+" on white, the counts of
 * host/vision/dual_plus.py plus_candidates added to *o */
int32_t mg_plus_candidates(const uint8_t *grey, const int32_t *lab, int32_t W, int32_t H,
                           const int32_t *stats, int32_t n_lab, mg_plus_t *out, int32_t *lvl,
                           mg_ops_t *o)
{
    int32_t n_out = 0, n_ok = 0;
    /* the call and the stats scan, per component; then the pixels of the boxes and frames
     * summed and the dark ones among them (the lightness test and the moments' pass) */
    const int64_t n_st = n_lab > 1 ? n_lab - 1 : 0;
    int64_t frame_px = 0, dark_px = 0;
    mg_ops_charge(o, 0, 0, 100 + 25 * n_st, 4 * n_st, 0, 0, 0, 0, 20 * n_st);
    int32_t *minx = lvl, *maxx = lvl + (H + 2), *lc = lvl + 2 * (H + 2);
    int32_t *rc = lvl + 4 * (H + 2);
    for (int32_t k = 1; k < n_lab && n_ok < MG_MAX_PLUS; k++) {
        const int32_t *st = stats + 5 * k;
        const int32_t xi = st[0], yi = st[1], wi = st[2], hi = st[3], area = st[4];
        if (!(area >= MIN_AREA_PX && wi >= 4 && hi >= 4 && wi <= W / 2 && hi <= H / 2
              && 100 * area >= 25 * wi * hi && 100 * area <= 80 * wi * hi && wi <= 4 * hi
              && hi <= 4 * wi && xi > 0 && yi > 0 && xi + wi < W && yi + hi < H))
            continue;
        n_ok++;
        if (lab[(yi + hi / 2) * W + xi + wi / 2] != k)
            continue;
        const int32_t area2 = hull_area2(lab, W, k, xi, yi, wi, hi, minx, maxx, lc, rc);
        mg_ops_charge(o, 0, 0, 28 * (int64_t)hi + 60, 4 * (int64_t)hi, 0, 0, 0, 0, 0);
        const int32_t sol = area2 ? 200 * area / area2 : 0;
        if (sol < SOLIDITY_MIN_PCT || sol > SOLIDITY_MAX_PCT)
            continue;
        /* lighter around: the 2 px frame around the box at least 2.2x the print's mean */
        const int32_t x0 = imax(0, xi - 2), y0 = imax(0, yi - 2);
        const int32_t x1 = imin(W, xi + wi + 2), y1 = imin(H, yi + hi + 2);
        int64_t ring_sum = 0, dark_sum = 0;
        int64_t m00 = 0, m10 = 0, m01 = 0, m20 = 0, m11 = 0, m02 = 0;
        for (int32_t y = y0; y < y1; y++) {
            const uint8_t *g = grey + y * W;
            const int32_t *l = lab + y * W;
            const int in_rows = y >= yi && y < yi + hi;
            for (int32_t x = x0; x < x1; x++) {
                if (in_rows && x >= xi && x < xi + wi) {
                    if (l[x] == k) {
                        dark_sum += g[x];
                        m00++;
                        m10 += x;
                        m01 += y;
                        m20 += x * x;
                        m11 += x * y;
                        m02 += y * y;
                    }
                } else {
                    ring_sum += g[x];
                }
            }
        }
        const int64_t ring_n = (int64_t)(x1 - x0) * (y1 - y0) - (int64_t)wi * hi;
        frame_px += (int64_t)(x1 - x0) * (y1 - y0);
        dark_px += m00;
        if (10 * ring_sum * m00 < 22 * dark_sum * ring_n)
            continue;
        plus_t *p = out + n_out++;
        p->m[0] = m00;
        p->m[1] = m10;
        p->m[2] = m01;
        p->m[3] = m20;
        p->m[4] = m11;
        p->m[5] = m02;
        p->u_q4 = (int32_t)((16 * m10 + m00 / 2) / m00);
        p->v_q4 = (int32_t)((16 * m01 + m00 / 2) / m00);
        p->box[0] = xi;
        p->box[1] = yi;
        p->box[2] = wi;
        p->box[3] = hi;
    }
    mg_ops_charge(o, 2 * frame_px, 0, 16 * frame_px + 36 * dark_px + 1300 * (int64_t)n_out,
                  frame_px, 0, 6 * dark_px, 2 * (int64_t)n_out, 0, 5 * frame_px);
    return n_out;
}

int32_t mg_dual_plus(const uint8_t *grey, const int32_t *lab, int32_t W, int32_t H,
                     const int32_t *stats, int32_t n_lab, int32_t alpha_mrad, int32_t f_px,
                     int32_t u0_px, uint8_t *scratch, int32_t *out, mg_ops_t *ops)
{
    mg_ops_t none, *o = ops != 0 ? ops : &none;
    mg_ops_clear(o);
    plus_t *plus = (plus_t *)scratch;
    int32_t *lvl = (int32_t *)(scratch + sizeof(plus_t) * MG_MAX_PLUS);
    const int32_t n = mg_plus_candidates(grey, lab, W, H, stats, n_lab, plus, lvl, o);
    int32_t bi = -1, bj = -1, best = -1, bdu = 0, bdv = 0, bd = 0;
    for (int32_t i = 0; i < n; i++) {
        for (int32_t j = i + 1; j < n; j++) {
            const plus_t *a = plus + i, *b = plus + j;
            const int32_t a0 = (int32_t)a->m[0], b0 = (int32_t)b->m[0];
            if (2 * imin(a0, b0) < imax(a0, b0))
                continue; /* the same size within 2:1 (seen obliquely) */
            const int32_t du = a->u_q4 - b->u_q4, dv = a->v_q4 - b->v_q4;
            const int32_t d_q4 = mg_isqrt32((uint32_t)(du * du + dv * dv));
            const int32_t r_q4 = mg_isqrt32((uint32_t)(256 * (a0 + b0) / 2));
            if (16 * d_q4 < SEP_MIN_Q4 * r_q4 || 16 * d_q4 > SEP_MAX_Q4 * r_q4)
                continue;
            const int32_t mu = (a->u_q4 + b->u_q4) / 32, mv = (a->v_q4 + b->v_q4) / 32;
            if (lab[mv * W + mu])
                continue; /* the card is white between the "+" */
            if (best < 0 || a0 + b0 > best) {
                best = a0 + b0;
                bi = i;
                bj = j;
                bdu = du;
                bdv = dv;
                bd = d_q4;
            }
        }
    }
    /* the pairs' tests (host/vision/dual_plus.py detect_dual_plus) */
    const int64_t n2 = (int64_t)n * n;
    mg_ops_charge(o, 0, 0, 30 * n2, n2, 0, 4 * n2, 0, 0, 0);
    if (best < 0)
        return 0;
    const plus_t *a = plus + bi, *b = plus + bj;
    if (a->u_q4 > b->u_q4) { /* "+" 1 is the left one in the image */
        const plus_t *t = a;
        a = b;
        b = t;
    }
    const int64_t d_eff = d_eff_q4(a, b, bdu, bdv);
    /* the moment algebra in 256-bit integers (_D_EFF_OPS, as emulated: docs/budget.md) */
    mg_ops_charge(o, 0, 0, 36000, 1700, 0, 24, 3, 0, 0);
    if (d_eff == 0 || d_eff < bd || bd == 0)
        return 0;
    /* a sine, a cosine, two Q12 products (host/fixedpoint.py sin_ops, mul_q12_ops), the
     * three divisions and their products */
    mg_ops_charge(o, 0, 0, 2 * 10 + 2 * 2, 2 * 2, 2 * 1, 2 * 1 + 2 + 3, 3, 2 * 2, 0);
    const int64_t num = (int64_t)D_ACT_DMM * f_px * 16;
    const int32_t dist = mg_div_round(num, 10 * d_eff);
    const int32_t raw = mg_div_round(num, 10 * (int64_t)bd);
    const int32_t c = mg_cos_q12(alpha_mrad), s = mg_sin_q12(alpha_mrad);
    out[0] = a->u_q4;
    out[1] = a->v_q4;
    out[2] = b->u_q4;
    out[3] = b->v_q4;
    out[4] = bd;
    out[5] = (int32_t)d_eff;
    out[6] = dist;
    out[7] = raw;
    out[8] = (int32_t)(((int64_t)dist * c + 2048) >> 12);
    out[9] = (int32_t)(((int64_t)dist * s + 2048) >> 12);
    out[10] = mg_div_round((int64_t)dist * (u0_px * 32 - a->u_q4 - b->u_q4),
                           (int64_t)32 * f_px);
    return 1;
}
