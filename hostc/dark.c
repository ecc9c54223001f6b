/* Dark threshold and mask of the 000 detectors, host/vision/dark_blobs.py dark_mask. */
#include "kernels.h"

#define THRESH_NUM 45
#define THRESH_DEN 100
#define THRESH_MIN 40
#define THRESH_MAX 130
#define BRIGHT_FRACTION_DEN 500
#define CLIP_MEDIAN_NUM 65 /* bright level clipped: the threshold at least 65/100 of the median */

int32_t mg_dark_mask(const uint8_t *grey, uint8_t *mask, int32_t n_px, uint32_t *hist)
{
    for (int i = 0; i < 256; i++)
        hist[i] = 0;
    for (int32_t i = 0; i < n_px; i++)
        hist[grey[i]]++;
    /* bright level: the highest level with at least n/500 pixels at or above it (the first k
     * from 255 down whose running count reaches n/500, numpy's searchsorted left) */
    uint32_t want = (uint32_t)n_px / BRIGHT_FRACTION_DEN, cum = 0;
    int k = 0;
    for (; k < 256; k++) {
        cum += hist[255 - k];
        if (cum >= want)
            break;
    }
    int32_t bright = 255 - k;
    int32_t t = bright * THRESH_NUM / THRESH_DEN;
    if (t < THRESH_MIN)
        t = THRESH_MIN;
    if (t > THRESH_MAX)
        t = THRESH_MAX;
    if (k == 0 && want > 0) {
        /* the bright level clips at 255: the same walk goes on to the median level (at least
         * n/2 pixels at or above it), which still follows the camera gain */
        const uint32_t half = (uint32_t)n_px / 2;
        int m = 0;
        while (cum < half && m < 255) {
            m++;
            cum += hist[255 - m];
        }
        int32_t tm = (255 - m) * CLIP_MEDIAN_NUM / THRESH_DEN;
        if (tm > t)
            t = tm;
    }
    uint8_t tb = (uint8_t)t;
    for (int32_t i = 0; i < n_px; i++)
        mask[i] = grey[i] < tb;
    return t;
}

void mg_dark_mask_ops(mg_ops_t *o, int64_t n_px)
{
    /* the histogram pass (a read, the bin's load, increment and store, the loop: 11 cycles),
     * the mask pass (read, compare, store, loop: 10), both fetching the grey image from SDRAM,
     * the level search over at most 256 bins, on to the median in a clipped frame
     * (host/vision/dark_blobs.py dark_mask_cost) */
    mg_ops_charge(o, 2 * n_px, 2 * n_px, 7 * n_px + 512, 2 * n_px + 256, 0, 0, 0, n_px,
                  2 * n_px);
}
