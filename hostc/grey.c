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
