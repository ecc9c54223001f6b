/* Radial symbol of paper 000 (section III.A): the dual outer rings seen as an ellipse; centre,
 * outer diameter d_p + d_rp and Y_oc = L f / (d_p + d_rp), X_oc = (u0 - u_r) Y_oc / f,
 * Z_oc = (v0 - v_r) Y_oc / f. The steps and their reasons are those of
 * host/vision/radial_symbol.py, which this follows line by line (same integers). */
#include "kernels.h"

#define L_MM 109
#define MIN_WIDTH_PX 12
/* a cut symbol (radial_symbol.py detect_radial_cut): the visible part's width at least, and
 * the box's dark share at most */
#define CUT_MIN_PX 64
#define CUT_SOLID_PCT 45
#define MAX_CANDIDATES 12
#define LOCAL_BUDGET_NUM 3 /* local re-thresholding: 3/2 of a frame's pixels */
#define LOCAL_BUDGET_DEN 2
#define MIN_CONTRAST 90
#define FILL_MIN_PCT 62
#define FILL_MAX_PCT 84
#define SPAN_MIN_PCT 55
#define SPAN_MAX_PCT 90
#define CLIPPED_SUM (3 * 252) /* the card clips: radial_symbol.py CLIPPED_SUM */
static const int32_t LOCAL_NUM[3] = {1, 1, 2}, LOCAL_DEN[3] = {2, 3, 3};

typedef struct {
    int16_t *sums;
    uint8_t *lmask, *sel, *inner;
    int32_t *llabels, *block_lab, *parent, *lstats, *stack;
} scratch_t;

static int32_t blocks_of(int32_t w, int32_t h) { return ((w + 1) / 2) * ((h + 1) / 2); }
static int32_t align4(int32_t n) { return (n + 3) & ~3; }

int32_t mg_radial_scratch_bytes(int32_t w, int32_t h)
{
    int32_t n = w * h, b = blocks_of(w, h);
    return align4(2 * n) + 3 * align4(n) + 4 * n + 4 * b + 4 * (b + 1) + 20 * (b + 1) + 4 * n;
}

static scratch_t carve(uint8_t *p, int32_t w, int32_t h)
{
    int32_t n = w * h, b = blocks_of(w, h);
    scratch_t s;
    s.sums = (int16_t *)p; p += align4(2 * n);
    s.lmask = p; p += align4(n);
    s.sel = p; p += align4(n);
    s.inner = p; p += align4(n);
    s.llabels = (int32_t *)p; p += 4 * n;
    s.block_lab = (int32_t *)p; p += 4 * b;
    s.parent = (int32_t *)p; p += 4 * (b + 1);
    s.lstats = (int32_t *)p; p += 20 * (b + 1);
    s.stack = (int32_t *)p;
    return s;
}

static int32_t imax(int32_t a, int32_t b) { return a > b ? a : b; }
static int32_t imin(int32_t a, int32_t b) { return a < b ? a : b; }
static int32_t iabs(int32_t a) { return a < 0 ? -a : a; }

/* 1x3 horizontal sums of grey over [xa, xe) x [y0, y1), the sub-image's edge columns repeated */
static void box_sums(const uint8_t *grey, int32_t W, int32_t xa, int32_t xe, int32_t y0,
                     int32_t y1, int32_t x0, int32_t x1, int16_t *out)
{
    const int32_t lw = x1 - x0;
    for (int32_t y = y0; y < y1; y++) {
        const uint8_t *g = grey + y * W;
        int16_t *o = out + (y - y0) * lw;
        for (int32_t x = x0; x < x1; x++) {
            int32_t l = x - 1 < xa ? xa : x - 1, r = x + 1 >= xe ? xe - 1 : x + 1;
            o[x - x0] = (int16_t)(g[l] + g[x] + g[r]);
        }
    }
}

/* Flood the light pixels of m (bw x bh) 4-connected to pixel i (set to 0; to `mark` when
 * nonzero), i itself included when m[i] is 1 */
static void flood(uint8_t *m, int32_t bw, int32_t bh, int32_t i, uint8_t mark, int32_t *stack)
{
    int32_t top = 0;
    m[i] = mark;
    stack[top++] = ((i / bw) << 16) | (i % bw);
    /* the stack holds (y << 16) | x: no division per pixel (boxes are under 65536 px wide) */
    while (top > 0) {
        int32_t p = stack[--top], x = p & 0xFFFF, y = p >> 16, j = y * bw + x;
        if (x > 0 && m[j - 1] == 1) { m[j - 1] = mark; stack[top++] = p - 1; }
        if (x + 1 < bw && m[j + 1] == 1) { m[j + 1] = mark; stack[top++] = p + 1; }
        if (y > 0 && m[j - bw] == 1) { m[j - bw] = mark; stack[top++] = p - (1 << 16); }
        if (y + 1 < bh && m[j + bw] == 1) { m[j + bw] = mark; stack[top++] = p + (1 << 16); }
    }
}

/* The enclosed interior of component k in its box (bx, by, bw, bh) of the local labels
 * (stride lw): light pixels (not k) 4-connected to no pixel of the box's border. Writes sel
 * (pixels of k) and inner, bw x bh each; returns the interior's area, and in *regions the
 * box's 4-connected light regions plus one (the labels radial_symbol.py's ring test charges
 * for) */
static int32_t enclosed(const int32_t *lab, int32_t lw, int32_t k, int32_t bx, int32_t by,
                        int32_t bw, int32_t bh, uint8_t *sel, uint8_t *inner, int32_t *stack,
                        int32_t *regions)
{
    const int32_t n = bw * bh;
    for (int32_t y = 0; y < bh; y++) {
        const int32_t *lr = lab + (by + y) * lw + bx;
        for (int32_t x = 0; x < bw; x++) {
            sel[y * bw + x] = lr[x] == k;
            inner[y * bw + x] = lr[x] != k; /* light: interior until reached from the border */
        }
    }
    int32_t count = 1;
    for (int32_t y = 0; y < bh; y++) {
        for (int32_t x = 0; x < bw; x++) {
            if (y != 0 && y != bh - 1 && x != 0 && x != bw - 1)
                continue;
            int32_t i = y * bw + x;
            if (inner[i] == 1) {
                flood(inner, bw, bh, i, 0, stack);
                count++;
            }
        }
    }
    int32_t total = 0;
    for (int32_t i = 0; i < n; i++) {
        if (inner[i] == 1) { /* an enclosed region: counted, marked 2, then back to 1 */
            flood(inner, bw, bh, i, 2, stack);
            count++;
        }
        total += inner[i] != 0;
    }
    for (int32_t i = 0; i < n; i++)
        inner[i] = inner[i] != 0;
    *regions = count;
    return total;
}

static int interior_v_q4(const uint8_t *grey, int32_t W, int32_t H, const uint8_t *inner,
                         int32_t xi, int32_t yi, int32_t wi, int32_t hi, int32_t u_px,
                         int32_t *v_q4)
{
    int32_t c = imin(wi - 1, imax(0, u_px - xi)), top = -1, bot = -1;
    for (int32_t r = 0; r < hi; r++) {
        if (inner[r * wi + c]) {
            if (top < 0)
                top = r;
            bot = r;
        }
    }
    int32_t tq, bq;
    if (top < 0)
        return 0;
    if (!mg_edge_q4(grey + u_px, W, H, yi + top - 1, +1, &tq)
            || !mg_edge_q4(grey + u_px, W, H, yi + bot + 1, -1, &bq))
        return 0;
    *v_q4 = mg_floordiv(tq + bq, 2);
    return 1;
}

static int row_span(const uint8_t *row, int32_t n, int32_t *first, int32_t *last)
{
    *first = -1;
    for (int32_t i = 0; i < n; i++) {
        if (row[i]) {
            if (*first < 0)
                *first = i;
            *last = i;
        }
    }
    return *first >= 0;
}

static int32_t line_max(const uint8_t *line, int32_t a, int32_t b)
{
    int32_t m = 0;
    for (int32_t i = a; i < b; i++)
        if (line[i] > m)
            m = line[i];
    return m;
}

/* the operation counts of n sub-pixel edges (host/vision/dark_blobs.py EDGE_OPS) */
static void edge_ops(mg_ops_t *o, int32_t n)
{
    mg_ops_charge(o, 14 * n, 0, 30 * n, 10 * n, 0, 0, n, 0, 0);
}

/* the ring's centre, diameter and position (out), or 0 when it is not an ellipse; adds to *o
 * what radial_symbol.py's _measure charges */
static int measure(const uint8_t *grey, int32_t W, int32_t H, const uint8_t *roi,
                   const uint8_t *inner, int32_t xi, int32_t yi, int32_t wi, int32_t hi,
                   int32_t f_px, int32_t u0_px, int32_t v0_px, int32_t *out, mg_ops_t *o)
{
    int32_t v_q4, l, r = 0, b0 = 0, b1 = 0, have = 0;
    mg_ops_charge(o, (int64_t)wi * hi, 0, (int64_t)wi * hi, hi, 0, 0, 0, 0, 0);
    edge_ops(o, 4);
    if (!interior_v_q4(grey, W, H, inner, xi, yi, wi, hi, xi + wi / 2, &v_q4))
        return 0;
    int32_t r0 = mg_floordiv(v_q4 + 8, 16) - yi;
    for (int32_t row = r0 - 1; row <= r0 + 1; row++) {
        if (row < 0 || row >= hi || !row_span(roi + row * wi, wi, &l, &r))
            continue;
        edge_ops(o, 2);
        int32_t lq, rq;
        const uint8_t *line = grey + (yi + row) * W;
        if (!mg_edge_q4(line, 1, W, xi + l, -1, &lq) || !mg_edge_q4(line, 1, W, xi + r, +1, &rq))
            continue;
        if (!have || rq - lq > b1 - b0) {
            b0 = lq;
            b1 = rq;
            have = 1;
        }
    }
    if (!have)
        return 0;
    int32_t d_q4 = b1 - b0, u_q4 = mg_floordiv(b0 + b1, 2);
    if (!interior_v_q4(grey, W, H, inner, xi, yi, wi, hi, mg_floordiv(u_q4 + 8, 16), &v_q4)
            || d_q4 < 16 * MIN_WIDTH_PX)
        return 0;
    int32_t il, ir = 0;
    int32_t irow = imin(hi - 1, imax(0, mg_floordiv(v_q4 + 8, 16) - yi));
    if (!row_span(inner + irow * wi, wi, &il, &ir))
        return 0;
    if (iabs(8 * (2 * xi + il + ir) - u_q4) > 16 * imax(2, wi / 12))
        return 0;
    int32_t tl = 16 * (xi + il) - b0, tr = b1 - 16 * (xi + ir);
    if (iabs(tl - tr) > imax(32, mg_floordiv(tl + tr, 4)))
        return 0;
    const uint8_t *line = grey + imin(H - 1, mg_floordiv(v_q4 + 8, 16)) * W;
    int32_t light = line_max(line, xi + il, xi + ir + 1);
    int32_t lo_x = mg_floordiv(b0, 16), hi_x = mg_floordiv(b1 + 15, 16);
    int32_t out_l = line_max(line, imax(0, lo_x - 3), lo_x + 1);
    int32_t out_r = line_max(line, hi_x, imin(W, hi_x + 4));
    if (10 * imin(out_l, out_r) < 7 * light)
        return 0;
    int64_t ring_sum = 0, in_sum = 0;
    int32_t n_ring = 0, n_in = 0;
    for (int32_t y = 0; y < hi; y++) {
        const uint8_t *g = grey + (yi + y) * W + xi;
        for (int32_t x = 0; x < wi; x++) {
            int32_t i = y * wi + x;
            if (roi[i]) { ring_sum += g[x]; n_ring++; }
            if (inner[i]) { in_sum += g[x]; n_in++; }
        }
    }
    if (2 * ring_sum * n_in >= in_sum * n_ring)
        return 0;
    mg_ops_charge(o, (int64_t)wi * hi, 0, 2 * (int64_t)wi * hi, 0, 0, 2, 0, 0, 0);
    int32_t hr = imin(hi, imax(1, mg_floordiv(2 * v_q4 - 32 * yi + 16, 16) + 1));
    int32_t filled = 0;
    for (int32_t i = 0; i < hr * wi; i++)
        filled += roi[i] + inner[i];
    int32_t span = ir - il + 1;
    if (!(FILL_MIN_PCT * wi * hr <= 100 * filled && 100 * filled <= FILL_MAX_PCT * wi * hr
          && SPAN_MIN_PCT * wi <= 100 * span && 100 * span <= SPAN_MAX_PCT * wi))
        return 0;
    int32_t y_mm = mg_div_round((int64_t)L_MM * f_px * 16, d_q4);
    mg_ops_charge(o, 2 * wi, 0, 30, 0, 0, 4, 3, 0, 0);
    out[0] = u_q4;
    out[1] = v_q4;
    out[2] = d_q4;
    out[3] = y_mm;
    out[4] = mg_div_round((int64_t)(u0_px * 16 - u_q4) * y_mm, f_px * 16);
    out[5] = mg_div_round((int64_t)(v0_px * 16 - v_q4) * y_mm, f_px * 16);
    return 1;
}

int32_t mg_radial_symbol(const uint8_t *grey, int32_t W, int32_t H, const int32_t *stats,
                         int32_t n_lab, int32_t f_px, int32_t u0_px, int32_t v0_px,
                         uint8_t *scratch, int32_t *out, mg_ops_t *ops)
{
    static mg_ops_t unread; /* the counts when the caller wants none: never read */
    mg_ops_t *o = ops != 0 ? ops : &unread;
    if (ops != 0) {
        mg_ops_clear(o);
        /* the candidate scan: a call's set-up, the filter per component and, with any
         * component, the first line fills of the stats table and candidate list */
        const int32_t n_st = n_lab > 1 ? n_lab - 1 : 0;
        o->alu = 100 + 12 * n_st + (n_st > 0 ? 150 : 0);
        o->branches = 2 * n_st;
    }
    scratch_t s = carve(scratch, W, H);
    int32_t cand[MAX_CANDIDATES], n_cand = 0;
    /* candidates: wide, not solid, not too near; widest first (stable), at most 12 */
    for (int32_t i = 1; i < n_lab; i++) {
        const int32_t *st = stats + 5 * i;
        int32_t w = st[2], h = st[3], area = st[4];
        if (!(w >= MIN_WIDTH_PX && h >= 3 && 10 * w >= 8 * h && area * 100 <= 70 * w * h
              && 4 * w <= 3 * W))
            continue;
        int32_t pos = n_cand;
        while (pos > 0 && stats[5 * cand[pos - 1] + 2] < w)
            pos--;
        if (pos >= MAX_CANDIDATES)
            continue;
        int32_t last = n_cand < MAX_CANDIDATES ? n_cand : MAX_CANDIDATES - 1;
        for (int32_t j = last; j > pos; j--)
            cand[j] = cand[j - 1];
        cand[pos] = i;
        if (n_cand < MAX_CANDIDATES)
            n_cand++;
    }
    int64_t budget = (int64_t)LOCAL_BUDGET_NUM * W * H / LOCAL_BUDGET_DEN;
    for (int32_t c = 0; c < n_cand; c++) {
        const int32_t *st = stats + 5 * cand[c];
        int32_t x = st[0], y = st[1], w = st[2], h = st[3];
        int32_t m = imax(3, w / 8), mx = w + 3;
        int32_t x0 = imax(0, x - mx), y0 = imax(0, y - m);
        int32_t x1 = imin(W, x + w + mx), y1 = imin(H, y + h + m);
        int32_t xa = imax(0, x0 - 1), xe = imin(W, x1 + 1);
        int32_t lw = x1 - x0, lh = y1 - y0, ln = lw * lh;
        box_sums(grey, W, xa, xe, y0, y1, x0, x1, s.sums);
        /* the 1x3 sums with the clamped edge columns and the min/max pass */
        mg_ops_charge(o, 4 * (int64_t)ln, ln, 22 * (int64_t)ln, 2 * (int64_t)ln, 0, 0, 0, 0, ln);
        int32_t lo = 32767, hi = -1;
        for (int32_t i = 0; i < ln; i++) {
            if (s.sums[i] < lo) lo = s.sums[i];
            if (s.sums[i] > hi) hi = s.sums[i];
        }
        /* thresholds at 1/2, then 1/3, of the range; where the card clips (the lightest sum
         * at least CLIPPED_SUM) around a candidate narrower than CUT_MIN_PX, then 2/3
         * (radial_symbol.py LOCAL_FRACTIONS_CLIPPED) */
        const int32_t n_try = hi >= CLIPPED_SUM && w < CUT_MIN_PX ? 3 : 2;
        for (int32_t try_i = 0; try_i < n_try; try_i++) {
            const int32_t num = LOCAL_NUM[try_i], den = LOCAL_DEN[try_i];
            /* the pixels this try touches, as charged in radial_symbol.py (4 per pixel) */
            int32_t touched = 4 * ln;
            int found = 0;
            int32_t bx = 0, by = 0, bw = 0, bh = 0;
            mg_ops_charge(o, 4 * (int64_t)ln, 0, 6 * (int64_t)ln, 0, 0, 0, 0, 0, 0);
            if (hi - lo >= 3 * MIN_CONTRAST) {
                mg_components_ops(o, ln);
                mg_ops_charge(o, 0, ln, 0, 0, 0, 0, 1, 0, 0);
                int32_t t = lo + (hi - lo) * num / den;
                for (int32_t i = 0; i < ln; i++)
                    s.lmask[i] = s.sums[i] < t;
                int32_t nl = mg_label(s.lmask, lw, lh, s.llabels, s.block_lab, s.parent,
                                      s.lstats);
                touched += 2 * ln;
                int32_t cx = x + w / 2 - x0, cy = y + h / 2 - y0, k = -1;
                for (int32_t j = 1; j < nl; j++) {
                    const int32_t *ls = s.lstats + 5 * j;
                    if (ls[0] <= cx && cx < ls[0] + ls[2] && ls[1] <= cy && cy < ls[1] + ls[3]
                            && 10 * ls[2] >= 8 * w && (k < 0 || ls[2] > s.lstats[5 * k + 2]))
                        k = j;
                }
                if (nl >= 2) {
                    mg_ops_charge(o, 0, 0, 10 * (int64_t)nl, nl, 0, 0, 0, 0, 0);
                }
                if (nl >= 2 && k > 0) {
                    const int32_t *ls = s.lstats + 5 * k;
                    bx = ls[0];
                    by = ls[1];
                    bw = ls[2];
                    bh = ls[3];
                    int32_t regions;
                    int32_t total = enclosed(s.llabels, lw, k, bx, by, bw, bh, s.sel, s.inner,
                                             s.stack, &regions);
                    /* the ring test: the box's copy, the flood from its border, the count */
                    const int64_t nb = (int64_t)bw * bh;
                    mg_ops_charge(o, 8 * nb, 3 * nb, 38 * nb + 8 * (int64_t)regions,
                                  8 * nb + 2 * (int64_t)regions, 0, 0, 0, 4 * nb, 8 * nb);
                    touched += 4 * bw * bh;
                    found = total >= 4 && 25 * total >= bw * bh;
                    if (found) {
                        int any = 0;
                        for (int32_t r = 0; r < bh; r++)
                            any |= s.inner[r * bw + bw / 2];
                        found = any;
                    }
                }
            }
            budget -= touched / 4;
            if (budget < 0)
                return 0;
            if (found && measure(grey, W, H, s.sel, s.inner, x0 + bx, y0 + by, bw, bh, f_px,
                                 u0_px, v0_px, out, o))
                return 1;
        }
    }
    return 0;
}

int32_t mg_radial_cut(const int32_t *stats, int32_t n_lab, int32_t W, int32_t H, int32_t *out,
                      mg_ops_t *ops)
{
    const int32_t n_st = n_lab > 1 ? n_lab - 1 : 0;
    if (ops != 0) {
        mg_ops_clear(ops);
        ops->alu = 20 + 14 * n_st; /* the scan over the component table */
        ops->branches = 2 * n_st;
    }
    int32_t best = -1, best_side = 0;
    for (int32_t i = 1; i < n_lab; i++) {
        const int32_t *st = stats + 5 * i;
        const int32_t x = st[0], y = st[1], w = st[2], h = st[3], area = st[4];
        const int left = x <= 0, right = x + w >= W;
        if (w < CUT_MIN_PX || 100 * (int64_t)area > (int64_t)CUT_SOLID_PCT * w * h
            || !(left || right || y <= 0 || y + h >= H) || (left && right))
            continue;
        if (best < 0 || w > stats[5 * best + 2]) { /* the widest; the first of equals */
            best = i;
            best_side = left ? -1 : right ? 1 : 0;
        }
    }
    if (best < 0)
        return 0;
    for (int32_t k = 0; k < 4; k++)
        out[k] = stats[5 * best + k];
    out[4] = best_side;
    return 1;
}
