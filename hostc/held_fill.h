/* held_fill.c: the colour filling the hand camera's frame (host/vision/held_fill.py). */
#ifndef MOBIGRASP_HOSTC_HELD_FILL_H
#define MOBIGRASP_HOSTC_HELD_FILL_H

#include <stdint.h>

#include "budget.h"

#define MG_HELD_STEP 4               /* sample grid: 80 x 60 of a 320 x 240 frame */
#define MG_HELD_TOL 48               /* a sample within this of the median, every channel */
#define MG_HELD_FILL_MIN_PERMILLE 900

#define MG_HELD_SCRATCH_WORDS 768 /* the three channels' histograms of 256 bins */

/* the median colour (r, g, b) and the share of samples near it (per mille) of an interleaved
 * RGB frame: 1, or 0 when no colour fills it (or the frame is under MG_HELD_STEP px a side);
 * scratch: MG_HELD_SCRATCH_WORDS words */
int32_t mg_held_fill(const uint8_t *rgb, int32_t w, int32_t h, uint32_t *scratch,
                     int32_t out[4]);
/* what it charges on any frame of h x w */
mg_ops_t mg_held_fill_ops(int32_t h, int32_t w);

#endif
