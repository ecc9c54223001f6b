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

/* edge.c: floor division, rounded division (den > 0) and the sub-pixel light-to-dark edge
 * ending at i_dark along a line (stride in bytes; host/vision/dark_blobs.py edge_q4): 1 and the
 * edge in Q4 px, or 0 when there is none. */
int32_t mg_floordiv(int32_t a, int32_t b);
int32_t mg_div_round(int64_t num, int64_t den);
int mg_edge_q4(const uint8_t *line, int32_t stride, int32_t n, int32_t i_dark, int32_t step,
               int32_t *out_q4);

/* radial_symbol.c: the 000 radial symbol from the front end's grey image and component stats
 * (host/vision/radial_symbol.py detect_radial_symbol). out: u_q4, v_q4, diameter_q4, y_oc_mm,
 * x_oc_mm, z_oc_mm. scratch: mg_radial_scratch_bytes(w, h) bytes, 4-byte aligned. Returns 1
 * when found, 0 when not. */
int32_t mg_radial_scratch_bytes(int32_t w, int32_t h);
int32_t mg_radial_symbol(const uint8_t *grey, int32_t w, int32_t h, const int32_t *stats,
                         int32_t n_lab, int32_t f_px, int32_t u0_px, int32_t v0_px,
                         uint8_t *scratch, int32_t *out);

/* red_cylinder.c: the 002 red cylinder and its two rings from the RGB frame
 * (host/vision/red_cylinder.py detect_red_cylinder). out: u_c_q4, v_c_q4, ring1_v_q4,
 * ring2_v_q4, d_pixel_q4, width_q4, roi x, y, w, h. scratch: mg_red_scratch_bytes(w, h)
 * bytes, 4-byte aligned. Returns 1 when found, 0 when not. */
int32_t mg_red_scratch_bytes(int32_t w, int32_t h);
int32_t mg_red_cylinder(const uint8_t *rgb, int32_t w, int32_t h, uint8_t *scratch,
                        int32_t *out);

#endif
