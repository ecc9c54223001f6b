/* A frame filled by one colour: the object the gripper holds, seen by the camera in the hand
 * (host/vision/held_fill.py, whose docstring says why): every MG_HELD_STEP-th pixel of every
 * MG_HELD_STEP-th row, the lower median of each channel (a 256-bin histogram walk), the share
 * of samples within MG_HELD_TOL of it in all three channels. */
#include "held_fill.h"

#include <string.h>

static int32_t cells(int32_t n)
{
    return (n + MG_HELD_STEP - 1) / MG_HELD_STEP;
}

mg_ops_t mg_held_fill_ops(int32_t h, int32_t w)
{
    const int64_t n = (int64_t)cells(h) * cells(w);
    mg_ops_t ops;
    memset(&ops, 0, sizeof ops);
    ops.pixels_read = 2 * 3 * n;
    ops.alu = 3 * n + 3 * 256 + 8 * n;
    ops.branches = n + 3 * 256;
    ops.divs = 1;
    ops.bytes_streamed = (int64_t)cells(h) * w * 3;
    return ops;
}

int32_t mg_held_fill(const uint8_t *rgb, int32_t w, int32_t h, uint32_t *scratch,
                     int32_t out[4])
{
    if (w < MG_HELD_STEP || h < MG_HELD_STEP)
        return 0;
    uint32_t(*hist)[256] = (uint32_t(*)[256])scratch;
    memset(scratch, 0, MG_HELD_SCRATCH_WORDS * sizeof scratch[0]);
    const int64_t n = (int64_t)cells(h) * cells(w);
    for (int32_t y = 0; y < h; y += MG_HELD_STEP)
        for (int32_t x = 0; x < w; x += MG_HELD_STEP)
            for (int c = 0; c < 3; c++)
                hist[c][rgb[((int64_t)y * w + x) * 3 + c]]++;
    int32_t med[3];
    for (int c = 0; c < 3; c++) { /* the ((n - 1) / 2)-th smallest sample */
        int64_t seen = 0;
        int32_t v = 0;
        while ((seen += hist[c][v]) <= (n - 1) / 2)
            v++;
        med[c] = v;
    }
    int64_t near = 0;
    for (int32_t y = 0; y < h; y += MG_HELD_STEP)
        for (int32_t x = 0; x < w; x += MG_HELD_STEP) {
            const uint8_t *p = &rgb[((int64_t)y * w + x) * 3];
            int ok = 1;
            for (int c = 0; c < 3; c++) {
                const int32_t d = p[c] - med[c];
                ok &= (d < 0 ? -d : d) <= MG_HELD_TOL;
            }
            near += ok;
        }
    const int32_t fill = (int32_t)(near * 1000 / n);
    if (fill < MG_HELD_FILL_MIN_PERMILLE)
        return 0;
    out[0] = med[0], out[1] = med[1], out[2] = med[2], out[3] = fill;
    return 1;
}
