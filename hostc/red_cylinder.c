/* Red cylinder with two black rings of paper 002 (section 2.2): the red region, its two rings
 * and their spacing d_pixel. The steps and their reasons are those of
 * host/vision/red_cylinder.py, which this follows line by line (same integers); so are the
 * operation counts, which it says the ARM920T code of. */
#include "kernels.h"

#define T_RED 40
#define MIN_AREA_HALF_PX 6
#define MIN_ROI_AREA_HALF_PX 12 /* the colour ROI alone: 48 px */
#define MIN_RING_GAP_PX 2
#define MAX_STRIPS 256

typedef struct {
    int32_t area, x0, y0, x1, y1, ix0, ix1;
} cand_t;

static int32_t imax(int32_t a, int32_t b) { return a > b ? a : b; }
static int32_t imin(int32_t a, int32_t b) { return a < b ? a : b; }
static int32_t iabs(int32_t a) { return a < 0 ? -a : a; }

static int32_t redness(const uint8_t *p)
{
    int32_t gb = p[1] > p[2] ? p[1] : p[2];
    return p[0] > gb ? p[0] - gb : 0;
}

/* int(np.median(v)) of n >= 1 non-negative values; tmp: n words */
static int32_t median_int(const int32_t *v, int32_t n, int32_t *tmp)
{
    for (int32_t i = 0; i < n; i++) {
        int32_t x = v[i], j = i;
        while (j > 0 && tmp[j - 1] > x) {
            tmp[j] = tmp[j - 1];
            j--;
        }
        tmp[j] = x;
    }
    return n & 1 ? tmp[n / 2] : (tmp[n / 2 - 1] + tmp[n / 2]) / 2;
}

static int32_t centroid_q4(const int32_t *profile, int32_t n, int32_t s, int32_t e,
                           int32_t level)
{
    int32_t a = imax(0, s - 1), b = imin(n, e + 1);
    int64_t tot = 0, mom = 0;
    for (int32_t r = a; r < b; r++) {
        int32_t w = level - profile[r];
        if (w > 0) {
            tot += w;
            mom += (int64_t)w * r;
        }
    }
    if (tot == 0)
        return ((s + e - 1) * 16) / 2;
    return mg_div_round(mom * 16, tot);
}

/* ring rows in columns [cx0, cx1) of rows [y0, y1): 1 and out (r1_q4, r2_q4, level, run1,
 * run2), or 0 without exactly two thin dark rings; prof/rprof/tmp: y1 - y0 words each */
static int measure(const uint8_t *rgb, int32_t W, int32_t y0, int32_t y1, int32_t cx0,
                   int32_t cx1, int32_t *prof, int32_t *rprof, int32_t *tmp, int32_t *out,
                   mg_ops_t *o)
{
    const int32_t n = y1 - y0, nc = cx1 - cx0;
    const int64_t px = (int64_t)n * nc;
    mg_ops_charge(o, 3 * px, 0, 9 * px, 2 * n, px, 0, 2 * n, 0, 3 * px);
    for (int32_t y = y0; y < y1; y++) {
        const uint8_t *p = rgb + 3 * (y * W + cx0);
        int32_t sr = 0, s = 0;
        for (int32_t x = 0; x < nc; x++, p += 3) {
            int32_t gb = p[1] > p[2] ? p[1] : p[2], r = p[0];
            if (2 * r >= 5 * gb)
                sr += r - gb;
            s += r;
        }
        prof[y - y0] = sr / nc;
        rprof[y - y0] = s / nc;
    }
    int32_t level = median_int(prof, n, tmp), thr = level / 2;
    if (level < T_RED)
        return 0;
    int32_t lo = -1, hi = -1;
    for (int32_t r = 0; r < n; r++) {
        if (!(prof[r] < thr)) {
            if (lo < 0)
                lo = r;
            hi = r;
        }
    }
    if (lo < 0 || lo == hi)
        return 0;
    int32_t runs = 0, s1 = 0, e1 = 0, s2 = 0, e2 = 0;
    for (int32_t r = lo; r <= hi;) {
        if (prof[r] < thr) {
            int32_t s = r;
            while (r <= hi && prof[r] < thr)
                r++;
            if (runs == 0) { s1 = s; e1 = r; }
            else if (runs == 1) { s2 = s; e2 = r; }
            runs++;
        } else {
            r++;
        }
    }
    if (runs != 2)
        return 0;
    int32_t r_level = median_int(rprof, n, tmp), m1 = 1 << 30, m2 = 1 << 30;
    for (int32_t r = s1; r < e1; r++)
        m1 = imin(m1, rprof[r]);
    for (int32_t r = s2; r < e2; r++)
        m2 = imin(m2, rprof[r]);
    if (3 * m1 > 2 * r_level || 3 * m2 > 2 * r_level)
        return 0;
    /* the centroids */
    mg_ops_charge(o, 0, 0, 8 * (e2 - s1 + 4) + 40, 0, 0, 2 * (e2 - s1 + 4), 2, 0, 0);
    int32_t r1 = y0 * 16 + centroid_q4(prof, n, s1, e1, level);
    int32_t r2 = y0 * 16 + centroid_q4(prof, n, s2, e2, level);
    if (r2 - r1 < MIN_RING_GAP_PX * 16 || 2 * imax(e1 - s1, e2 - s2) * 16 > r2 - r1)
        return 0;
    out[0] = r1; out[1] = r2; out[2] = level; out[3] = e1 - s1; out[4] = e2 - s2;
    return 1;
}

/* the longest run of columns where both rings are clearly less red than the band between
 * them (and the red outside them); ok: x1 - x0 bytes */
static int ring_columns(const uint8_t *rgb, int32_t W, int32_t H, int32_t x0, int32_t x1,
                        int32_t r1_q4, int32_t r2_q4, int32_t level, uint8_t *ok,
                        int32_t *left, int32_t *right, mg_ops_t *o)
{
    int32_t k = imax(1, (r2_q4 - r1_q4 + 16) >> 5), j = imax(1, k / 2);
    int32_t ra = (r1_q4 + 8) >> 4, rb = (r2_q4 + 8) >> 4, mid = (ra + rb) >> 1;
    int32_t lo = imax(0, ra - k - j), hi = imin(H, rb + k + j + 1);
    const int64_t px = (int64_t)imax(0, hi - lo) * (x1 - x0); /* the redness of the band */
    mg_ops_charge(o, 3 * px, 0, 6 * px, x1 - x0, 0, 0, 0, 0, 0);
    for (int32_t x = x0; x < x1; x++) {
        int good = 1;
        for (int side = 0; side < 2 && good; side++) {
            int32_t ring = side ? rb : ra, outer = side ? rb + k : ra - k;
            int32_t a = imax(lo, ring - j), b = imin(hi, ring + j + 1), dark = 1 << 30;
            for (int32_t y = a; y < b; y++)
                dark = imin(dark, redness(rgb + 3 * (y * W + x)));
            int32_t ref = redness(rgb + 3 * (mid * W + x));
            if (lo <= outer && outer < hi) {
                int32_t oa = imax(lo, outer - j), ob = imin(hi, outer + j + 1), mx = -1;
                for (int32_t y = oa; y < ob; y++)
                    mx = imax(mx, redness(rgb + 3 * (y * W + x)));
                ref = imin(ref, mx);
            }
            good = ref - dark >= level / 4;
        }
        ok[x - x0] = (uint8_t)good;
    }
    int32_t best = 0, bs = 0, n = x1 - x0;
    for (int32_t i = 0; i < n;) {
        if (!ok[i]) {
            i++;
            continue;
        }
        int32_t s = i;
        while (i < n && ok[i])
            i++;
        if (i - s > best) {
            best = i - s;
            bs = s;
        }
    }
    if (!best)
        return 0;
    *left = x0 + bs;
    *right = x0 + bs + best - 1;
    return 1;
}

static void red_run(const uint8_t *rgb, int32_t W, int32_t H, int32_t ya, int32_t yb,
                    int32_t x0, int32_t x1, int32_t centre, int32_t *left, int32_t *right,
                    mg_ops_t *o)
{
    int32_t ya2 = imax(0, ya), yb2 = imax(ya + 1, yb);
    int32_t rows = imax(0, imin(yb2, H) - ya2), c = centre - x0, n = x1 - x0;
    mg_ops_charge(o, 3 * (int64_t)rows * n, 0, 5 * (int64_t)rows * n, n, 0, 0, 0, 0, 0);
    int32_t l = 0, r = n - 1;
    for (int32_t x = 0; x < n; x++) {
        int32_t cnt = 0;
        for (int32_t y = ya2; y < ya2 + rows; y++)
            cnt += redness(rgb + 3 * (y * W + x0 + x)) >= T_RED;
        int colred = cnt * 2 >= rows;
        if (!colred && x < c)
            l = x + 1;
        if (!colred && x > c && r == n - 1)
            r = x - 1;
    }
    *left = x0 + l;
    *right = x0 + r;
}

int32_t mg_red_scratch_bytes(int32_t w, int32_t h)
{
    int32_t gw = (w + 1) / 2, gh = (h + 1) / 2, n = gw * gh, b = ((gw + 1) / 2) * ((gh + 1) / 2);
    return ((n + 3) & ~3) + 4 * n + 4 * b + 4 * (b + 1) + 20 * (b + 1)
           + (int32_t)sizeof(cand_t) * 2 * (b + 1) + 4 * (b + 1) + 4 * (3 * h + w) + 4 * w
           + 4 * MAX_STRIPS;
}

/* The scratch of both detectors, laid out in the caller's buffer (mg_red_scratch_bytes). */
typedef struct {
    uint8_t *mask;
    int32_t *labels, *block_lab, *parent, *stats;
    cand_t *comps, *cands;
    int32_t *used, *prof, *rprof, *tmp;
    uint8_t *ok;
    int32_t *strips;
} red_scratch_t;

static red_scratch_t red_layout(uint8_t *scratch, int32_t W, int32_t H)
{
    const int32_t gw = (W + 1) / 2, gh = (H + 1) / 2, n = gw * gh;
    const int32_t b = ((gw + 1) / 2) * ((gh + 1) / 2);
    red_scratch_t s;
    uint8_t *p = scratch + ((n + 3) & ~3);
    s.mask = scratch;
    s.labels = (int32_t *)p; p += 4 * n;
    s.block_lab = (int32_t *)p; p += 4 * b;
    s.parent = (int32_t *)p; p += 4 * (b + 1);
    s.stats = (int32_t *)p; p += 20 * (b + 1);
    s.comps = (cand_t *)p; p += sizeof(cand_t) * (b + 1);
    s.cands = (cand_t *)p; p += sizeof(cand_t) * (b + 1);
    s.used = (int32_t *)p; p += 4 * (b + 1);
    s.prof = (int32_t *)p; p += 4 * H;
    s.rprof = (int32_t *)p; p += 4 * H;
    s.tmp = (int32_t *)p; p += 4 * (H + W); /* a median's sort, or column counts */
    s.ok = p; p += 4 * W;
    s.strips = (int32_t *)p;
    return s;
}

/* Steps 1-2 of 002 section 2.2 (host/vision/red_cylinder.py red_mask, _candidates): the red
 * grid in s->mask and its stacked pieces in s->cands, biggest first; returns their number. */
static int32_t red_pieces(const uint8_t *rgb, int32_t W, int32_t H, const red_scratch_t *rs,
                          mg_ops_t *o)
{
    const int32_t gw = (W + 1) / 2, gh = (H + 1) / 2;
    uint8_t *mask = rs->mask;
    int32_t *stats = rs->stats, *used = rs->used;
    cand_t *comps = rs->comps, *cands = rs->cands;

    /* 1. red on every second pixel of every second row */
    for (int32_t gy = 0; gy < gh; gy++) {
        for (int32_t gx = 0; gx < gw; gx++) {
            const uint8_t *q = rgb + 3 * ((2 * gy) * W + 2 * gx);
            int32_t gb = q[1] > q[2] ? q[1] : q[2], r = q[0];
            mask[gy * gw + gx] = (r > gb ? r - gb : 0) >= T_RED && 2 * r >= 5 * gb;
        }
    }
    /* per grid pixel three byte loads, max, subtract, the hue test and a store; every other
     * row of the frame from SDRAM (red_grid_ops) */
    const int64_t m = (int64_t)gw * gh;
    mg_ops_charge(o, 3 * m, 0, 7 * m, 0, m, 0, 0, 0, (int64_t)(H + 1) / 2 * W * 3);
    o->pixels_written += m;
    /* 2. red pieces, biggest first (then left, then top), merged when stacked */
    int32_t nl = mg_label(mask, gw, gh, rs->labels, rs->block_lab, rs->parent, stats);
    mg_components_ops(o, m);
    int32_t nc = 0;
    for (int32_t i = 1; i < nl; i++) {
        const int32_t *s = stats + 5 * i;
        if (s[4] < MIN_AREA_HALF_PX)
            continue;
        cand_t c = {s[4], s[0], s[1], s[0] + s[2], s[1] + s[3], 0, 0};
        int32_t j = nc++;
        while (j > 0 && (comps[j - 1].area < c.area
                         || (comps[j - 1].area == c.area && (comps[j - 1].x0 > c.x0
                             || (comps[j - 1].x0 == c.x0 && comps[j - 1].y0 > c.y0))))) {
            comps[j] = comps[j - 1];
            j--;
        }
        comps[j] = c;
    }
    /* the merge */
    mg_ops_charge(o, 0, 0, 10 * (int64_t)nc * nc + 10, 2 * (int64_t)nc * nc, 0, 0, 0, 0, 0);
    for (int32_t i = 0; i < nc; i++)
        used[i] = 0;
    int32_t nm = 0;
    for (int32_t i = 0; i < nc; i++) {
        if (used[i])
            continue;
        used[i] = 1;
        cand_t m = comps[i];
        m.ix0 = m.x0;
        m.ix1 = m.x1;
        for (int changed = 1; changed;) {
            changed = 0;
            for (int32_t j = 0; j < nc; j++) {
                const cand_t *c = comps + j;
                if (used[j])
                    continue;
                int32_t overlap = imin(m.ix1, c->x1) - imax(m.ix0, c->x0);
                if (2 * overlap >= imin(m.ix1 - m.ix0, c->x1 - c->x0)) {
                    used[j] = 1;
                    m.area += c->area;
                    m.x0 = imin(m.x0, c->x0);
                    m.y0 = imin(m.y0, c->y0);
                    m.x1 = imax(m.x1, c->x1);
                    m.y1 = imax(m.y1, c->y1);
                    m.ix0 = imax(m.ix0, c->x0);
                    m.ix1 = imin(m.ix1, c->x1);
                    changed = 1;
                }
            }
        }
        int32_t j = nm++;
        while (j > 0 && cands[j - 1].area < m.area) {
            cands[j] = cands[j - 1];
            j--;
        }
        cands[j] = m;
    }
    return nm;
}

/* the colour ROI (detect_red_roi), its counts added to *o */
static int32_t roi(const uint8_t *rgb, int32_t W, int32_t H, uint8_t *scratch, int32_t *out,
                   mg_ops_t *o)
{
    const red_scratch_t rs = red_layout(scratch, W, H);
    const int32_t nm = red_pieces(rgb, W, H, &rs, o);
    mg_ops_charge(o, 0, 0, 12, 0, 0, 0, 0, 0, 0);
    if (nm == 0 || rs.cands[0].area < MIN_ROI_AREA_HALF_PX)
        return 0;
    const cand_t *c = rs.cands;
    /* grid cell k covers pixels 2k, 2k + 1: a run [a, b) of cells has its middle at
     * a + b - 1/2 px */
    out[0] = (c->ix0 + c->ix1) * 16 - 8;
    out[1] = (c->y0 + c->y1) * 16 - 8;
    out[2] = 2 * c->x0;
    out[3] = 2 * c->y0;
    out[4] = 2 * (c->x1 - c->x0);
    out[5] = 2 * (c->y1 - c->y0);
    out[6] = 4 * c->area;
    out[7] = c->y0 == 0 || c->y1 >= (H + 1) / 2;
    return 1;
}

int32_t mg_red_roi(const uint8_t *rgb, int32_t W, int32_t H, uint8_t *scratch, int32_t *out,
                   mg_ops_t *ops)
{
    mg_ops_t none, *o = ops != 0 ? ops : &none;
    mg_ops_clear(o);
    const int32_t found = roi(rgb, W, H, scratch, out, o);
    return found;
}

/* the cylinder and its rings (detect_red_cylinder), its counts added to *o */
static int32_t cylinder(const uint8_t *rgb, int32_t W, int32_t H, uint8_t *scratch,
                        int32_t *out, mg_ops_t *o)
{
    const int32_t gw = (W + 1) / 2;
    const red_scratch_t rs = red_layout(scratch, W, H);
    const int32_t nm = red_pieces(rgb, W, H, &rs, o);
    const uint8_t *mask = rs.mask;
    const cand_t *cands = rs.cands;
    int32_t *prof = rs.prof, *rprof = rs.rprof, *tmp = rs.tmp, *strips = rs.strips;
    uint8_t *ok = rs.ok;
    /* 3-4. rings, their columns and the silhouette, on the three biggest candidates */
    for (int32_t ci = 0; ci < nm && ci < 3; ci++) {
        const cand_t *c = cands + ci;
        int32_t gx0 = c->x0, gy0 = c->y0, gx1 = c->x1, gy1 = c->y1;
        int32_t x0 = imax(0, 2 * gx0 - 2), y0 = imax(0, 2 * gy0 - 2);
        int32_t x1 = imin(W, 2 * gx1 + 2), y1 = imin(H, 2 * gy1 + 2);
        int32_t gix0 = c->ix0, gix1 = c->ix1;
        const int64_t box = (int64_t)(gx1 - gx0) * (gy1 - gy0); /* the column counts */
        mg_ops_charge(o, box, 0, 2 * box, 0, 0, 0, 0, 0, 0);
        if (gix1 - gix0 >= 2) { /* the run around the tallest common column */
            int32_t top = 0, topv = -1, nci = gix1 - gix0;
            for (int32_t x = 0; x < nci; x++) {
                int32_t cnt = 0;
                for (int32_t y = gy0; y < gy1; y++)
                    cnt += mask[y * gw + gix0 + x];
                tmp[x] = cnt;
                if (cnt > topv) { topv = cnt; top = x; }
            }
            int32_t a = 0, bb = nci;
            for (int32_t x = 0; x < nci; x++) {
                if (2 * tmp[x] < topv) {
                    if (x < top) a = x + 1;
                    if (x > top && bb == nci) bb = x;
                }
            }
            gix1 = gix0 + bb;
            gix0 = gix0 + a;
        }
        int32_t ix0 = 2 * gix0, ix1 = imin(W, 2 * gix1);
        if (ix1 - ix0 < 4 || y1 - y0 < 4)
            continue;
        int32_t cx0 = ix0 + (ix1 - ix0) / 4, cx1 = ix1 - (ix1 - ix0) / 4, m[5];
        int have = measure(rgb, W, y0, y1, cx0, cx1, prof, rprof, tmp, m, o);
        if (!have) {
            int32_t sw = imax(4, (x1 - x0) / 8), mid = (cx0 + cx1) / 2, ns = 0;
            for (int32_t sx = x0; sx < x1 - sw + 1 && ns < MAX_STRIPS; sx += sw / 2) {
                int32_t j = ns++, key = iabs(sx + sw / 2 - mid);
                while (j > 0 && iabs(strips[j - 1] + sw / 2 - mid) > key) {
                    strips[j] = strips[j - 1];
                    j--;
                }
                strips[j] = sx;
            }
            for (int32_t k = 0; k < ns && !have; k++) {
                if (measure(rgb, W, y0, y1, strips[k], strips[k] + sw, prof, rprof, tmp, m,
                            o)) {
                    cx0 = strips[k];
                    cx1 = strips[k] + sw;
                    have = 1;
                }
            }
        }
        if (!have)
            continue;
        int32_t left, right;
        if (!ring_columns(rgb, W, H, x0, x1, m[0], m[1], m[2], ok, &left, &right, o)
                || right - left < 3)
            continue;
        int32_t r1 = m[0], r2 = m[1], red_l, red_r;
        red_run(rgb, W, H, (r1 >> 4) + m[3], (r2 >> 4) - m[4] + 1, x0, x1, (left + right) / 2,
                &red_l, &red_r, o);
        int32_t ml = left - red_l, mr = red_r - right;
        if (iabs(ml - mr) > imax(3, (right - left) / 8))
            ml = mr = imax(0, imin(ml, mr));
        left -= ml;
        right += mr;
        if (left <= 0 || right >= W - 1)
            continue;
        int32_t q = (right - left + 1) / 4;
        if (iabs(left + q - cx0) + iabs(right + 1 - q - cx1) > imax(2, q / 2)) {
            int32_t m2[5];
            if (!measure(rgb, W, y0, y1, left + q, right + 1 - q, prof, rprof, tmp, m2, o))
                continue;
            r1 = m2[0];
            r2 = m2[1];
        }
        out[0] = (left + right) * 8;
        out[1] = (r1 + r2 + 1) >> 1;
        out[2] = r1;
        out[3] = r2;
        out[4] = r2 - r1;
        out[5] = (right - left + 1) * 16;
        out[6] = x0;
        out[7] = y0;
        out[8] = x1 - x0;
        out[9] = y1 - y0;
        return 1;
    }
    return 0;
}

int32_t mg_red_cylinder(const uint8_t *rgb, int32_t W, int32_t H, uint8_t *scratch,
                        int32_t *out, mg_ops_t *ops)
{
    mg_ops_t none, *o = ops != 0 ? ops : &none;
    mg_ops_clear(o);
    const int32_t found = cylinder(rgb, W, H, scratch, out, o);
    return found;
}
