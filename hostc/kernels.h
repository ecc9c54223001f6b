/* The host's per-frame vision kernels in C99, integer only, no allocation: every buffer is the
 * caller's. Each kernel gives the same result as its Python counterpart in host/vision/, bit for
 * bit (calib/ tests compare them on a corpus of frames). Built twice: by the host compiler for
 * the comparison, by arm-none-eabi-gcc for the ARM920T timing (calib/arm.py). */
#ifndef MOBIGRASP_HOSTC_KERNELS_H
#define MOBIGRASP_HOSTC_KERNELS_H

#include <stdint.h>

/* grey.c: Y = (77 R + 150 G + 29 B) >> 8 of an interleaved RGB frame (host/vision/grey.py) */
void mg_grey(const uint8_t *rgb, uint8_t *grey, int32_t n_px);

/* dark.c: the dark threshold from the bright level (the grey level of the brightest 1/500 of
 * the pixels, times 45/100, clamped to 40..130) and the 0/1 mask grey < threshold
 * (host/vision/dark_blobs.py dark_mask); returns the threshold. hist: 256 words of scratch. */
int32_t mg_dark_mask(const uint8_t *grey, uint8_t *mask, int32_t n_px, uint32_t *hist);

/* label.c: 8-connected components of a 0/1 mask, numbered and measured as OpenCV's
 * connectedComponentsWithStats does (labels in the order of each component's first 2x2 block
 * in block raster order; stats rows left, top, width, height, area; row 0 the background).
 * Scratch: block_lab ((w+1)/2 * (h+1)/2 words), parent (as many + 1), stats (5 words per label,
 * at most blocks + 1 labels). Returns the number of labels including the background. */
int32_t mg_label(const uint8_t *mask, int32_t w, int32_t h, int32_t *labels,
                 int32_t *block_lab, int32_t *parent, int32_t *stats);

#endif
