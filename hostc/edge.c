/* Sub-pixel light-to-dark edge along a line of grey pixels, host/vision/dark_blobs.py edge_q4. */
#include "kernels.h"

int32_t mg_floordiv(int32_t a, int32_t b)
{
    int32_t q = a / b;
    return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

int32_t mg_div_round(int64_t num, int64_t den)
{
    /* den > 0: num / den rounded, halves away from zero (host/fixedpoint.py div_round) */
    if (num >= 0)
        return (int32_t)((2 * num + den) / (2 * den));
    return (int32_t)-((den - 2 * num) / (2 * den));
}

int mg_edge_q4(const uint8_t *line, int32_t stride, int32_t n, int32_t i_dark, int32_t step,
               int32_t *out_q4)
{
    int32_t g_dark = 256, g_light = -1;
    for (int32_t k = 0; k < 3; k++) {
        int32_t i = i_dark - k * step;
        if (i >= 0 && i < n && line[i * stride] < g_dark)
            g_dark = line[i * stride];
    }
    for (int32_t k = 1; k < 4; k++) {
        int32_t i = i_dark + k * step;
        if (i >= 0 && i < n && (int32_t)line[i * stride] > g_light)
            g_light = line[i * stride];
    }
    if (g_dark > 255 || g_light < 0)
        return 0;
    int32_t mid2 = g_dark + g_light;
    if (g_light - g_dark < 8)
        return 0;
    for (int32_t k = -2; k < 4; k++) {
        int32_t a = i_dark + (k + 1) * step, b = i_dark + k * step;
        if (a < 0 || a >= n || b < 0 || b >= n)
            continue;
        int32_t ga2 = 2 * line[a * stride], gb2 = 2 * line[b * stride];
        if (ga2 >= mid2 && mid2 > gb2) {
            int32_t frac_q4 = (16 * (ga2 - mid2)) / (ga2 - gb2);
            *out_q4 = 16 * a - step * frac_q4;
            return 1;
        }
    }
    return 0;
}
