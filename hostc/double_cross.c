/* Double-cross approach-guidance marker of paper 002 (section 2.1): both cross centres, the
 * marker centre weighted by the crosses' apparent heights, their spacing and the bearing e.
 * The steps and their reasons are those of host/vision/double_cross.py, which this follows
 * step by step (same integers). Input: the grey image (grey.c).
 *
 * Where the Python works on whole arrays the C works on one pixel at a time, with the same
 * result: the ring max and min (its dilate and erode) only at the pixels the candidate test
 * reads (6 px or more from the border, where the ring never leaves the image), the min only
 * where the max has passed; the Omega_p2 points summed per grid cell as they are found (a
 * group's count and sums are those of its cells). */
#include "isqrt.h"
#include "kernels.h"

#define T_H 30
#define RING_N 24
#define RING_R 6
#define LEVELS 3
#define RING_HAMMING 4
#define STOP_VOTES 3
#define U0_PX 160
#define V0_PX 120
#define EXTENT_MAX_PX 120
#define RING_MASK ((1u << RING_N) - 1)
#define N_TEMPLATES 24

/* round(6 cos(2 pi k / 24)), round(6 sin(2 pi k / 24)): the 24-point ring of radius 6 */
static const int8_t ring24[RING_N][2] = {
    {6, 0}, {6, 2}, {5, 3}, {4, 4}, {3, 5}, {2, 6}, {0, 6}, {-2, 6}, {-3, 5}, {-4, 4},
    {-5, 3}, {-6, 2}, {-6, 0}, {-6, -2}, {-5, -3}, {-4, -4}, {-3, -5}, {-2, -6}, {0, -6},
    {2, -6}, {3, -5}, {4, -4}, {5, -3}, {6, -2}};

/* ideal rings of four equal spokes (w = 1..4 dark points a quarter) and four equal gaps, every
 * phase p = 0..5: bit i light when (i + p) mod 6 >= w */
static const uint32_t templates[N_TEMPLATES] = {
    0xfbefbe, 0x7df7df, 0xbefbef, 0xdf7df7, 0xefbefb, 0xf7df7d,
    0xf3cf3c, 0x79e79e, 0x3cf3cf, 0x9e79e7, 0xcf3cf3, 0xe79e79,
    0xe38e38, 0x71c71c, 0x38e38e, 0x1c71c7, 0x8e38e3, 0xc71c71,
    0xc30c30, 0x618618, 0x30c30c, 0x186186, 0x0c30c3, 0x861861};

typedef struct {
    int32_t votes, u_q4, v_q4;
} group_t;

typedef struct { /* Omega_p2 points of one grid cell */
    int32_t n, su, sv;
} cell_t;

typedef struct { /* a group's sums while its cells are added */
    int32_t n;
    int64_t su, sv;
} acc_t;

typedef struct {
    uint8_t *lvl[LEVELS]; /* level 0 is the caller's grey image */
    uint32_t *hist;
    cell_t *cells;
    uint8_t *occ;
    int32_t *labels, *block_lab, *parent, *stats;
    acc_t *acc;
    group_t *groups;
} scratch_t;

static int32_t align8(int32_t n) { return (n + 7) & ~7; }

static int32_t popcount32(uint32_t x)
{
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0fu;
    return (int32_t)((x * 0x01010101u) >> 24);
}

/* num / den rounded, halves up, num >= 0, den > 0 (host/fixedpoint.py div_round); 32-bit
 * division when the operands allow it */
static int32_t div_round_pos(int64_t num, int64_t den)
{
    if (num < (1 << 29) && den < (1 << 29))
        return (int32_t)((2 * (uint32_t)num + (uint32_t)den) / (2 * (uint32_t)den));
    return mg_div_round(num, den);
}

/* The operation counts (host/vision/double_cross.py, which states the ARM920T code each count
 * stands for; docs/budget.md), added to *o. One pyramid level of n pixels (_downsample_ops): */
static void downsample_ops(mg_ops_t *o, int64_t n)
{
    mg_ops_charge(o, 4 * n, n, 7 * n, n, 0, 0, 0, 0, 4 * n);
}

/* the noise estimate (_noise_ops) */
static void noise_ops(mg_ops_t *o, int32_t h, int32_t w)
{
    if (w < 2)
        return;
    const int64_t rows = (h + 3) / 4, n = rows * (w - 1);
    mg_ops_charge(o, 2 * n, n, 3 * n + 512, n + 256, 0, 0, 0, n, rows * w);
}

/* one level's fixed scan (_scan_ops) and its points past each test (_level_candidates) */
static void level_ops(mg_ops_t *o, int32_t h, int32_t w, const int32_t tally[4])
{
    const int64_t cells = (int64_t)((h >> 2) + 1) * ((w >> 2) + 1);
    mg_ops_charge(o, 0, 3 * cells, 2 * cells, cells, 0, 0, 0, 0, 0);
    if (h <= 2 * RING_R || w <= 2 * RING_R)
        return;
    const int64_t n = (int64_t)(h - 2 * RING_R) * (w - 2 * RING_R);
    mg_ops_charge(o, 9 * n, 0, 20 * n, 2 * n, 0, 0, 0, 0, (int64_t)h * w);
    const int64_t k = tally[0], ks = tally[1], n4 = tally[2], m = tally[3];
    mg_ops_charge(o, 8 * k, 8 * k, 34 * k, 24 * k, 0, 0, 0, 8 * k, 0);
    mg_ops_charge(o, ks * RING_N, 0, ks * (12 * RING_N + 68), ks * RING_N, 0, 0, 0,
                  ks * RING_N, 0);
    mg_ops_charge(o, 0, 0, 563 * n4, 24 * n4, 0, 0, 0, 24 * n4, 0);
    mg_ops_charge(o, 0, 3 * m, m * (2 * RING_N + 12), 2 * m, 0, 4 * m, 0, 0, 0);
}

/* one level's grouping of cells (_group: the labelling of hostc/label.c, the sums, a rounded
 * division per group mean) and the pair search over its ng groups */
static void group_ops(mg_ops_t *o, int64_t cells, int64_t ng)
{
    mg_components_ops(o, cells);
    mg_ops_charge(o, 3 * cells, cells, 6 * cells, 3 * cells, 0, 0, 2 * ng, 0, 26 * cells);
    mg_ops_charge(o, 0, 0, 12 * ng * ng, 0, 0, 2 * ng * ng, 0, 0, 0);
}

static void layout(uint8_t *scratch, int32_t w, int32_t h, scratch_t *s)
{
    const int32_t gw = (w >> 2) + 1, gh = (h >> 2) + 1, cells = gw * gh;
    const int32_t blocks = ((gw + 1) / 2) * ((gh + 1) / 2);
    uint8_t *p = scratch;
    s->lvl[0] = 0;
    for (int32_t l = 1; l < LEVELS; l++) {
        s->lvl[l] = p;
        p += align8((h >> l) * (w >> l));
    }
    s->hist = (uint32_t *)p;
    p += 256 * 4;
    s->cells = (cell_t *)p;
    p += align8(cells * (int32_t)sizeof(cell_t));
    s->occ = p;
    p += align8(cells);
    s->labels = (int32_t *)p;
    p += align8(4 * cells);
    s->block_lab = (int32_t *)p;
    p += align8(4 * blocks);
    s->parent = (int32_t *)p;
    p += align8(4 * (blocks + 1));
    s->stats = (int32_t *)p;
    p += align8(20 * (blocks + 1));
    s->acc = (acc_t *)p;
    p += align8((blocks + 1) * (int32_t)sizeof(acc_t));
    s->groups = (group_t *)p;
}

int32_t mg_double_cross_scratch_bytes(int32_t w, int32_t h)
{
    const int32_t gw = (w >> 2) + 1, gh = (h >> 2) + 1, cells = gw * gh;
    const int32_t blocks = ((gw + 1) / 2) * ((gh + 1) / 2);
    int32_t n = 0;
    for (int32_t l = 1; l < LEVELS; l++)
        n += align8((h >> l) * (w >> l));
    return n + 256 * 4 + align8(cells * (int32_t)sizeof(cell_t)) + align8(cells)
        + align8(4 * cells) + align8(4 * blocks) + align8(4 * (blocks + 1))
        + align8(20 * (blocks + 1)) + align8((blocks + 1) * (int32_t)sizeof(acc_t))
        + (blocks + 1) * (int32_t)sizeof(group_t);
}

/* one pyramid level: the rounded mean of each 2x2 block (an odd last row or column dropped) */
static void downsample(const uint8_t *src, int32_t w, int32_t h, uint8_t *dst)
{
    const int32_t w2 = w >> 1, h2 = h >> 1;
    for (int32_t y = 0; y < h2; y++) {
        const uint8_t *a = src + 2 * y * w, *b = a + w;
        uint8_t *d = dst + y * w2;
        for (int32_t x = 0; x < w2; x++)
            d[x] = (uint8_t)((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
    }
}

/* the noise sigma (host/vision/grey.py noise_sigma): the median absolute difference of
 * horizontal neighbours on every 4th row, times 67/64 */
static int32_t noise_sigma(const uint8_t *g, int32_t w, int32_t h, uint32_t *hist)
{
    if (w < 2)
        return 0;
    for (int32_t i = 0; i < 256; i++)
        hist[i] = 0;
    int32_t n = 0;
    for (int32_t y = 0; y < h; y += 4) {
        const uint8_t *r = g + y * w;
        for (int32_t x = 1; x < w; x++) {
            const int32_t d = r[x] - r[x - 1];
            hist[d < 0 ? -d : d]++;
        }
        n += w - 1;
    }
    const uint32_t half = (uint32_t)(n + 1) / 2;
    uint32_t cum = 0;
    int32_t median = 0;
    while (median < 255 && (cum += hist[median]) < half)
        median++;
    return (median * 67 + 32) >> 6;
}

/* Omega_p1 and Omega_p2 of one level (002 section 2.1 steps 1-3), each point added to its grid
 * cell; returns the number of points. tally: the points past each test, as the Python charges
 * them (Omega_p1, the symmetric ones, the words with four dark runs, those near a template) */
static int32_t level_points(const uint8_t *g, int32_t w, int32_t h, int32_t th, int32_t lvl,
                            int32_t gw, cell_t *cells, int32_t tally[4])
{
    const int32_t r = RING_R;
    if (h <= 2 * r || w <= 2 * r)
        return 0;
    int32_t off[RING_N];
    for (int32_t i = 0; i < RING_N; i++)
        off[i] = ring24[i][1] * w + ring24[i][0];
    /* the 8-point ring of step 1's max, min and symmetry: (6,0) (4,4) (0,6) (-4,4) (-6,0)
     * (-4,-4) (0,-6) (4,-4), opposite points 4 apart */
    const int32_t oa = 4 * w + 4, ob = 6 * w, od = 4 * w - 4;
    const int32_t o8[8] = {6, oa, ob, od, -6, -oa, -ob, -od};
    int32_t npts = 0;
    for (int32_t y = r; y < h - r; y++) {
        const uint8_t *row = g + y * w;
        for (int32_t x = r; x < w - r; x++) {
            const uint8_t *p = row + x;
            const int32_t c = *p;
            /* step 1 with step 3's contrast: max - g >= 2 T_h, min - g < T_h, g - min <=
             * max - g (saturating differences, as the uint8 arithmetic of the Python). The
             * max first, its eight loads unrolled: most pixels fail on it alone. */
            int32_t mx = p[6], t;
            t = p[oa]; mx = t > mx ? t : mx;
            t = p[ob]; mx = t > mx ? t : mx;
            t = p[od]; mx = t > mx ? t : mx;
            t = p[-6]; mx = t > mx ? t : mx;
            t = p[-oa]; mx = t > mx ? t : mx;
            t = p[-ob]; mx = t > mx ? t : mx;
            t = p[-od]; mx = t > mx ? t : mx;
            const int32_t up = mx - c;
            if (up < 2 * th)
                continue;
            int32_t v[8], mn = 255;
            for (int32_t k = 0; k < 8; k++) {
                v[k] = p[o8[k]];
                mn = v[k] < mn ? v[k] : mn;
            }
            if (mn - c >= th || c - mn > up)
                continue;
            tally[0]++;
            /* central symmetry: opposite points on the same side of g + T_h in >= 2 pairs */
            const int32_t ct = c + th;
            int32_t same = 0;
            for (int32_t k = 0; k < 4; k++)
                same += (v[k] >= ct) == (v[k + 4] >= ct);
            if (same < 2)
                continue;
            tally[1]++;
            /* step 2: the binarised ring word, and the sums of its light and dark samples */
            uint32_t code = 0;
            int32_t n_light = 0, s_light = 0, s_all = 0;
            for (int32_t i = 0; i < RING_N; i++) {
                const int32_t s = p[off[i]];
                s_all += s;
                if (s >= ct) {
                    code |= 1u << i;
                    n_light++;
                    s_light += s;
                }
            }
            /* step 3: four dark runs, within RING_HAMMING points of an ideal ring */
            const uint32_t rot = ((code << 1) | (code >> (RING_N - 1))) & RING_MASK;
            if (popcount32(code & ~rot & RING_MASK) != 4)
                continue;
            tally[2]++;
            int near = 0;
            for (int32_t t = 0; t < N_TEMPLATES && !near; t++)
                near = popcount32(code ^ templates[t]) <= RING_HAMMING;
            if (!near)
                continue;
            tally[3]++;
            const int32_t n_dark = RING_N - n_light, s_dark = s_all - s_light;
            if (s_light * n_dark - s_dark * n_light < 2 * th * n_light * n_dark
                || s_light - c * n_light < 2 * th * n_light || s_dark < (c - th) * n_dark)
                continue;
            /* the point's centre in level-0 Q4 and its cell of 4 level pixels */
            const int32_t xs = ((2 * x + 1) << (lvl + 3)) - 8;
            const int32_t ys = ((2 * y + 1) << (lvl + 3)) - 8;
            cell_t *cl = cells + (ys >> (6 + lvl)) * gw + (xs >> (6 + lvl));
            cl->n++;
            cl->su += xs;
            cl->sv += ys;
            npts++;
        }
    }
    return npts;
}

static int before(const group_t *a, const group_t *b) /* (-votes, u, v) order */
{
    if (a->votes != b->votes)
        return a->votes > b->votes;
    if (a->u_q4 != b->u_q4)
        return a->u_q4 < b->u_q4;
    return a->v_q4 < b->v_q4;
}

/* step 4 on one level: 8-connected occupied cells form a group; most votes first */
static int32_t group_level(const scratch_t *s, int32_t gw, int32_t gh)
{
    const int32_t cells = gw * gh;
    for (int32_t i = 0; i < cells; i++)
        s->occ[i] = s->cells[i].n > 0;
    const int32_t n_lab = mg_label(s->occ, gw, gh, s->labels, s->block_lab, s->parent,
                                   s->stats);
    for (int32_t l = 0; l < n_lab; l++) {
        s->acc[l].n = 0;
        s->acc[l].su = 0;
        s->acc[l].sv = 0;
    }
    for (int32_t i = 0; i < cells; i++)
        if (s->cells[i].n) {
            acc_t *a = s->acc + s->labels[i];
            a->n += s->cells[i].n;
            a->su += s->cells[i].su;
            a->sv += s->cells[i].sv;
        }
    int32_t ng = 0;
    for (int32_t l = 1; l < n_lab; l++) {
        const acc_t *a = s->acc + l;
        group_t gr = {a->n, div_round_pos(a->su, a->n), div_round_pos(a->sv, a->n)};
        int32_t j = ng++;
        for (; j > 0 && before(&gr, s->groups + j - 1); j--) /* insertion sort */
            s->groups[j] = s->groups[j - 1];
        s->groups[j] = gr;
    }
    return ng;
}

/* the pair with the most votes between one ring diameter and 24 ring radii apart (first of
 * equals); returns its score, 0 when there is none */
static int32_t pick_pair(const group_t *gr, int32_t ng, int32_t lvl, group_t *a, group_t *b)
{
    const int64_t lo = (int64_t)(2 * RING_R - 1) << (lvl + 4);
    const int64_t hi = (int64_t)(24 * RING_R) << (lvl + 4);
    int32_t best = 0;
    for (int32_t i = 0; i < ng; i++)
        for (int32_t j = i + 1; j < ng; j++) {
            const int32_t du = gr[i].u_q4 - gr[j].u_q4, dv = gr[i].v_q4 - gr[j].v_q4;
            const int64_t d2 = (int64_t)du * du + (int64_t)dv * dv;
            if (d2 < lo * lo || d2 > hi * hi)
                continue;
            const int32_t score = gr[i].votes + gr[j].votes;
            if (score > best) {
                best = score;
                *a = gr[i];
                *b = gr[j];
            }
        }
    return best;
}

/* a cross's apparent height (Q4): its vertical spokes from the centre up and down to the
 * dark/light mid-level crossings; 0 when there is no clear crossing */
static int32_t vertical_extent_q4(const uint8_t *g, int32_t w, int32_t h, int32_t u_q4,
                                  int32_t v_q4, mg_ops_t *o)
{
    const int32_t x = (u_q4 + 8) >> 4, y0 = (v_q4 + 8) >> 4;
    if (!(x >= 0 && x < w && y0 >= 1 && y0 < h - 1))
        return 0;
    const int32_t lo = y0 - EXTENT_MAX_PX < 0 ? 0 : y0 - EXTENT_MAX_PX;
    const int32_t hi = y0 + EXTENT_MAX_PX + 1 > h ? h : y0 + EXTENT_MAX_PX + 1;
    const uint8_t *col = g + x;
    mg_ops_charge(o, 2 * (hi - lo), 0, 3 * (hi - lo), hi - lo, 0, 0, 2, 0, 0);
    int32_t light = 0, dark = 255;
    for (int32_t y = lo; y < hi; y++)
        light = col[y * w] > light ? col[y * w] : light;
    for (int32_t y = y0 - 1; y <= y0 + 1; y++)
        dark = col[y * w] < dark ? col[y * w] : dark;
    if (light - dark < 2 * T_H)
        return 0;
    const int32_t mid2 = light + dark;
    int32_t total = 0;
    for (int32_t step = -1; step <= 1; step += 2) { /* from the centre up, then down */
        const int32_t n = step < 0 ? y0 - lo + 1 : hi - y0;
        int32_t k = 0;
        while (k < n && 2 * col[(y0 + step * k) * w] < mid2)
            k++;
        if (k == n || k == 0)
            return 0;
        const int32_t a = col[(y0 + step * (k - 1)) * w], b = col[(y0 + step * k) * w];
        total += 16 * (k - 1) + div_round_pos(16 * (mid2 - 2 * a), 2 * (b - a));
    }
    return total;
}

/* the detector (002 section 2.1), its operation counts added to *o */
static int32_t detect(const uint8_t *grey, int32_t w, int32_t h, int32_t yaw_mrad,
                      int32_t pitch_mrad, int32_t f_px, uint8_t *scratch, int32_t *out,
                      mg_ops_t *o)
{
    scratch_t s;
    layout(scratch, w, h, &s);
    const uint8_t *lv[LEVELS];
    lv[0] = grey;
    for (int32_t l = 1; l < LEVELS; l++) {
        downsample(lv[l - 1], w >> (l - 1), h >> (l - 1), s.lvl[l]);
        lv[l] = s.lvl[l];
        downsample_ops(o, (int64_t)(h >> l) * (w >> l));
    }
    /* T_h follows the noise (4 sigma, halved per level by the 2x2 means) */
    const int32_t sigma = noise_sigma(grey, w, h, s.hist);
    noise_ops(o, h, w);
    int32_t pair_score = 0;
    group_t pa = {0, 0, 0}, pb = {0, 0, 0};
    for (int32_t lvl = LEVELS - 1; lvl >= 0; lvl--) { /* coarse to fine */
        const int32_t gw = (w >> (2 + lvl)) + 1, gh = (h >> (2 + lvl)) + 1;
        for (int32_t i = 0; i < gw * gh; i++) {
            s.cells[i].n = 0;
            s.cells[i].su = 0;
            s.cells[i].sv = 0;
        }
        const int32_t th4 = (4 * sigma) >> lvl;
        int32_t tally[4] = {0, 0, 0, 0};
        const int32_t npts = level_points(lv[lvl], w >> lvl, h >> lvl, th4 > T_H ? th4 : T_H,
                                          lvl, gw, s.cells, tally);
        level_ops(o, h >> lvl, w >> lvl, tally);
        if (npts < 2)
            continue;
        const int32_t ng = group_level(&s, gw, gh);
        group_ops(o, (int64_t)gw * gh, ng);
        group_t a = {0, 0, 0}, b = {0, 0, 0};
        const int32_t score = pick_pair(s.groups, ng, lvl, &a, &b);
        if (score > 0 && score >= pair_score) { /* finer levels win ties */
            pair_score = score;
            pa = a;
            pb = b;
        }
        if (pair_score > 0 && (pa.votes < pb.votes ? pa.votes : pb.votes) >= STOP_VOTES)
            break;
    }
    if (pair_score == 0)
        return 0;
    const group_t g1 = pb.u_q4 < pa.u_q4 ? pb : pa, g2 = pb.u_q4 < pa.u_q4 ? pa : pb;
    const int32_t du = g2.u_q4 - g1.u_q4, dv = g2.v_q4 - g1.v_q4;
    const uint64_t d2 = (uint64_t)((int64_t)du * du + (int64_t)dv * dv);
    const int32_t d_q4 = d2 <= 0xffffffffu ? mg_isqrt32((uint32_t)d2)
                                           : (int32_t)mg_isqrt64(d2);
    int32_t rounds = 0; /* the isqrt's: one per pair of bits of d2, at least one */
    for (uint64_t u = d2; u; u >>= 2)
        rounds++;
    mg_ops_charge(o, 0, 0, 4 * (rounds > 1 ? rounds : 1) + 4, rounds > 1 ? rounds : 1, 0, 2, 0,
                  0, 0);
    int32_t um = (g1.u_q4 + g2.u_q4 + 1) >> 1, vm = (g1.v_q4 + g2.v_q4 + 1) >> 1;
    /* perspective: weight the centres by the crosses' apparent sizes (depth ~ 1 / size) */
    const int32_t r1 = vertical_extent_q4(grey, w, h, g1.u_q4, g1.v_q4, o);
    const int32_t r2 = vertical_extent_q4(grey, w, h, g2.u_q4, g2.v_q4, o);
    if (r1 && r2 && 5 * r1 >= 3 * r2 && 5 * r2 >= 3 * r1) {
        mg_ops_charge(o, 0, 0, 6, 0, 0, 4, 2, 0, 0);
        um = div_round_pos((int64_t)r2 * g1.u_q4 + (int64_t)r1 * g2.u_q4, r1 + r2);
        vm = div_round_pos((int64_t)r2 * g1.v_q4 + (int64_t)r1 * g2.v_q4, r1 + r2);
    }
    /* bearing of (um, vm): theta5 + atan2(x_n, cos a + y_n sin a), Q12 x Q4 */
    const int64_t xn_q4 = um - 16 * U0_PX, yn_q4 = vm - 16 * V0_PX;
    const int64_t fwd = (int64_t)mg_cos_q12(pitch_mrad) * 16 * f_px
        + (int64_t)mg_sin_q12(pitch_mrad) * yn_q4;
    const int32_t e = yaw_mrad + mg_atan2_mrad(xn_q4 * 4096, fwd);
    /* a sine and a cosine, an atan2 (host/fixedpoint.py sin_ops, atan2_ops), the products */
    mg_ops_charge(o, 0, 0, 2 * 10 + 14 + 6, 2 * 2 + 4, 2 * 1 + 1, 2 * 1 + 3, 1, 2 * 2 + 2, 0);
    out[0] = g1.u_q4;
    out[1] = g1.v_q4;
    out[2] = g2.u_q4;
    out[3] = g2.v_q4;
    out[4] = um;
    out[5] = vm;
    out[6] = d_q4;
    out[7] = e;
    out[8] = g1.votes;
    out[9] = g2.votes;
    return 1;
}

int32_t mg_double_cross(const uint8_t *grey, int32_t w, int32_t h, int32_t yaw_mrad,
                        int32_t pitch_mrad, int32_t f_px, uint8_t *scratch, int32_t *out,
                        mg_ops_t *ops)
{
    mg_ops_t none, *o = ops != 0 ? ops : &none;
    mg_ops_clear(o);
    const int32_t found = detect(grey, w, h, yaw_mrad, pitch_mrad, f_px, scratch, out, o);
    return found;
}
