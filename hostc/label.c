/* 8-connected component labelling by 2x2 blocks, numbered as OpenCV's block-based labelling
 * (Grana, Borghesani, Cucchiara 2010, "Optimized block-based connected components labeling with
 * decision trees"): all foreground pixels of a 2x2 block touch each other, so a block is one
 * node; a block joins its left, top-left, top and top-right neighbours when their facing pixels
 * touch. Equivalences by union-find with the smaller label as root, so a component's root is
 * its first block in raster order and the flattened numbers follow that order, as OpenCV's. */
#include "kernels.h"

static int32_t find_root(const int32_t *parent, int32_t i)
{
    while (parent[i] < i)
        i = parent[i];
    return i;
}

static int32_t set_union(int32_t *parent, int32_t i, int32_t j)
{
    int32_t ri = find_root(parent, i), rj = find_root(parent, j);
    int32_t r = ri < rj ? ri : rj;
    parent[ri] = r;
    parent[rj] = r;
    return r;
}

int32_t mg_label(const uint8_t *mask, int32_t w, int32_t h, int32_t *labels,
                 int32_t *block_lab, int32_t *parent, int32_t *stats)
{
    const int32_t bw = (w + 1) / 2, bh = (h + 1) / 2;
    int32_t next = 1;
    parent[0] = 0;
    for (int32_t by = 0; by < bh; by++) {
        const int32_t y = 2 * by;
        const uint8_t *r0 = mask + (int32_t)y * w;
        const uint8_t *r1 = y + 1 < h ? r0 + w : 0;
        const uint8_t *up = y > 0 ? r0 - w : 0; /* the row above the block */
        int32_t *bl = block_lab + by * bw;
        for (int32_t bx = 0; bx < bw; bx++) {
            const int32_t x = 2 * bx;
            const int has_right = x + 1 < w;
            const int a = r0[x], b = has_right && r0[x + 1];
            const int c = r1 && r1[x], d = r1 && has_right && r1[x + 1];
            if (!(a | b | c | d)) {
                bl[bx] = 0;
                continue;
            }
            int32_t lab = 0;
            /* left block: its right column touches this block's left column */
            if (bx > 0 && (a | c) && bl[bx - 1]) {
                const uint8_t *p0 = r0 + x - 1;
                if (p0[0] || (r1 && r1[x - 1]))
                    lab = bl[bx - 1];
            }
            if (up) {
                const int32_t *tl = bl - bw;
                /* top-left: pixel (x-1, y-1) against (x, y) */
                if (bx > 0 && a && up[x - 1] && tl[bx - 1])
                    lab = lab ? set_union(parent, lab, tl[bx - 1]) : tl[bx - 1];
                /* top: the row above over x, x+1 against this block's top row */
                if ((a | b) && tl[bx] && (up[x] || (has_right && up[x + 1])))
                    lab = lab ? set_union(parent, lab, tl[bx]) : tl[bx];
                /* top-right: pixel (x+2, y-1) against (x+1, y) */
                if (b && x + 2 < w && up[x + 2] && tl[bx + 1])
                    lab = lab ? set_union(parent, lab, tl[bx + 1]) : tl[bx + 1];
            }
            if (!lab) {
                lab = next++;
                parent[lab] = lab;
            }
            bl[bx] = lab;
        }
    }
    /* flatten: roots numbered 1, 2, ... in order of their provisional label */
    int32_t n = 1;
    for (int32_t i = 1; i < next; i++) {
        if (parent[i] < i)
            parent[i] = parent[parent[i]];
        else
            parent[i] = n++;
    }
    for (int32_t i = 0; i < n; i++) {
        int32_t *s = stats + 5 * i;
        s[0] = w; /* left */
        s[1] = h; /* top */
        s[2] = -1; /* right, made a width below */
        s[3] = -1; /* bottom, made a height below */
        s[4] = 0;
    }
    for (int32_t y = 0; y < h; y++) {
        const uint8_t *mr = mask + y * w;
        const int32_t *bl = block_lab + (y >> 1) * bw;
        int32_t *lr = labels + y * w;
        for (int32_t x = 0; x < w; x++) {
            const int32_t l = mr[x] ? parent[bl[x >> 1]] : 0;
            int32_t *s = stats + 5 * l;
            lr[x] = l;
            if (x < s[0])
                s[0] = x;
            if (x > s[2])
                s[2] = x;
            if (y < s[1])
                s[1] = y;
            s[3] = y;
            s[4]++;
        }
    }
    for (int32_t i = 0; i < n; i++) {
        int32_t *s = stats + 5 * i;
        if (s[4] == 0) { /* only the background can be empty: OpenCV's row for it */
            s[0] = -1;
            s[1] = INT32_MAX;
            s[2] = 0;
            s[3] = 0;
            continue;
        }
        s[2] = s[2] - s[0] + 1;
        s[3] = s[3] - s[1] + 1;
    }
    return n;
}

void mg_components_ops(mg_ops_t *o, int64_t n_px)
{
    /* both passes over the mask and each pixel's label stats (host/vision/dark_blobs.py
     * components_cost, docs/budget.md) */
    mg_ops_charge(o, 2 * n_px, 4 * n_px, 14 * n_px, 2 * n_px, 0, 0, 0, 6 * n_px, 2 * n_px);
}
