/* Integer RGB -> grey (BT.601 weights scaled to sum 256), host/vision/grey.py to_grey. */
#include "kernels.h"

void mg_grey(const uint8_t *rgb, uint8_t *grey, int32_t n_px)
{
    for (int32_t i = 0; i < n_px; i++) {
        uint32_t r = rgb[0], g = rgb[1], b = rgb[2];
        grey[i] = (uint8_t)((77u * r + 150u * g + 29u * b) >> 8);
        rgb += 3;
    }
}

void mg_grey_ops(mg_ops_t *o, int32_t h, int32_t w)
{
    /* per pixel three byte loads, three multiplies, two adds and a shift, a store; the loop
     * unrolled four times; the frame read from SDRAM once (host/vision/grey.py grey_cost) */
    const int64_t n = (int64_t)h * w;
    mg_ops_charge(o, 3 * n, n, 3 * n + n / 4, n / 4, 3 * n, 0, 0, 0, 3 * n);
}
