/* The host's per-frame vision kernels in C99, integer only, no allocation: every buffer is the
 * caller's. Each kernel gives the same result as its Python counterpart in host/vision/, bit for
 * bit (calib/ tests compare them on a corpus of frames). Built twice: by the host compiler for
 * the comparison, by arm-none-eabi-gcc for the ARM920T timing (calib/arm.py). */
#ifndef MOBIGRASP_HOSTC_KERNELS_H
#define MOBIGRASP_HOSTC_KERNELS_H

#include <stdint.h>

#include "budget.h" /* mg_ops_t: what a kernel call charges on the ARM920T */

/* grey.c: Y = (77 R + 150 G + 29 B) >> 8 of an interleaved RGB frame (host/vision/grey.py) */
void mg_grey(const uint8_t *rgb, uint8_t *grey, int32_t n_px);
/* adds to *o what mg_grey charges on an h x w frame (host/vision/grey.py grey_cost) */
void mg_grey_ops(mg_ops_t *o, int32_t h, int32_t w);

/* dark.c: the dark threshold from the bright level (the grey level of the brightest 1/500 of
 * the pixels, times 45/100, clamped to 40..130; when it clips at 255, at least 65/100 of the
 * median level) and the 0/1 mask grey < threshold
 * (host/vision/dark_blobs.py dark_mask); returns the threshold. hist: 256 words of scratch. */
int32_t mg_dark_mask(const uint8_t *grey, uint8_t *mask, int32_t n_px, uint32_t *hist);
/* adds to *o what mg_dark_mask charges on n_px pixels (host/vision/dark_blobs.py
 * dark_mask_cost) */
void mg_dark_mask_ops(mg_ops_t *o, int64_t n_px);

/* label.c: 8-connected components of a 0/1 mask, numbered and measured as OpenCV's
 * connectedComponentsWithStats does (labels in the order of each component's first 2x2 block
 * in block raster order; stats rows left, top, width, height, area; row 0 the background).
 * Scratch: block_lab ((w+1)/2 * (h+1)/2 words), parent (as many + 1), stats (5 words per label,
 * at most blocks + 1 labels). Returns the number of labels including the background. */
int32_t mg_label(const uint8_t *mask, int32_t w, int32_t h, int32_t *labels,
                 int32_t *block_lab, int32_t *parent, int32_t *stats);
/* adds to *o what mg_label charges on a mask of n_px pixels (host/vision/dark_blobs.py
 * components_cost) */
void mg_components_ops(mg_ops_t *o, int64_t n_px);

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
 * when found, 0 when not. ops (NULL: not wanted): the operation counts the Python detector
 * charges for the same frame, its front end apart (mg_grey_ops, mg_dark_mask_ops,
 * mg_components_ops). */
int32_t mg_radial_scratch_bytes(int32_t w, int32_t h);
int32_t mg_radial_symbol(const uint8_t *grey, int32_t w, int32_t h, const int32_t *stats,
                         int32_t n_lab, int32_t f_px, int32_t u0_px, int32_t v0_px,
                         uint8_t *scratch, int32_t *out, mg_ops_t *ops);

/* radial_symbol.c: the 000 radial symbol cut by the frame's border, from the front end's
 * component stats (host/vision/radial_symbol.py detect_radial_cut). out: x, y, w, h of the
 * component's box, side (-1 left, 1 right, 0 top or bottom alone). Returns 1 when found, 0
 * when not. ops (NULL: not wanted): the counts the Python detector charges beyond its front
 * end. */
int32_t mg_radial_cut(const int32_t *stats, int32_t n_lab, int32_t w, int32_t h, int32_t *out,
                      mg_ops_t *ops);

/* red_cylinder.c: the 002 red cylinder and its two rings from the RGB frame
 * (host/vision/red_cylinder.py detect_red_cylinder). out: u_c_q4, v_c_q4, ring1_v_q4,
 * ring2_v_q4, d_pixel_q4, width_q4, roi x, y, w, h. scratch: mg_red_scratch_bytes(w, h)
 * bytes, 4-byte aligned. Returns 1 when found, 0 when not. ops (NULL: not wanted): the
 * operation counts the Python detector charges for the same frame. */
int32_t mg_red_scratch_bytes(int32_t w, int32_t h);
int32_t mg_red_cylinder(const uint8_t *rgb, int32_t w, int32_t h, uint8_t *scratch,
                        int32_t *out, mg_ops_t *ops);
/* red_cylinder.c: the colour ROI of 002 section 2.2 step 1 alone, with the same scratch
 * (host/vision/red_cylinder.py detect_red_roi). out: u_c_q4, v_c_q4, roi x, y, w, h, area_px,
 * touches_edge. Returns 1 when found, 0 when not; ops as mg_red_cylinder's. */
int32_t mg_red_roi(const uint8_t *rgb, int32_t w, int32_t h, uint8_t *scratch, int32_t *out,
                   mg_ops_t *ops);

#include "trig.h" /* sin, cos (Q12) and atan2 (mrad) */

/* dual_plus.c: the 000 dual "+" from the front end's grey image, labels and component stats
 * (host/vision/dual_plus.py detect_dual_plus). out: u1_q4, v1_q4, u2_q4, v2_q4, d_pixel_q4,
 * d_eff_q4, dist_mm, dist_raw_mm, x_oc_mm, y_oc_mm, z_oc_mm. scratch:
 * mg_dual_plus_scratch_bytes(w, h) bytes, 8-byte aligned. Returns 1 when found, 0 when not.
 * ops (NULL: not wanted): the operation counts the Python detector charges for the same frame,
 * its front end apart (mg_grey_ops, mg_dark_mask_ops, mg_components_ops). */
int32_t mg_dual_plus_scratch_bytes(int32_t w, int32_t h);
/* the "+" candidates of dual_plus.c (host/vision/dual_plus.py plus_candidates), shared with
 * spoke.c: at most MG_MAX_PLUS; lvl: 6 (h + 2) words of scratch; the counts plus_candidates
 * charges added to *ops */
#define MG_MAX_PLUS 64
typedef struct {
    int64_t m[6]; /* m00, m10, m01, m20, m11, m02 */
    int32_t u_q4, v_q4;
    int32_t box[4]; /* x, y, w, h */
} mg_plus_t;
int32_t mg_plus_candidates(const uint8_t *grey, const int32_t *labels, int32_t w, int32_t h,
                           const int32_t *stats, int32_t n_lab, mg_plus_t *out, int32_t *lvl,
                           mg_ops_t *ops);
int32_t mg_dual_plus(const uint8_t *grey, const int32_t *labels, int32_t w, int32_t h,
                     const int32_t *stats, int32_t n_lab, int32_t alpha_mrad, int32_t f_px,
                     int32_t u0_px, uint8_t *scratch, int32_t *out, mg_ops_t *ops);

/* spoke.c: the 000 single "+" spoke from the front end's grey image, labels and stats
 * (host/vision/spoke.py detect_spoke). out: u_c_q4, v_c_q4, slope_q12, angle_mrad, width_q4,
 * n_points, then n_points (u_q4, v_q4) pairs (at most 10). scratch:
 * mg_dual_plus_scratch_bytes(w, h) bytes, 8-byte aligned. Returns 1 when found, 0 when not;
 * ops as mg_dual_plus's. */
int32_t mg_spoke(const uint8_t *grey, const int32_t *labels, int32_t w, int32_t h,
                 const int32_t *stats, int32_t n_lab, uint8_t *scratch, int32_t *out,
                 mg_ops_t *ops);

/* ranging.c: the 002 ring-pair ranging (host/ranging.py locate_ring_pair). out: x_mm, y_mm,
 * z_mm, dist_mm, bearing_mrad, radius_mm. Returns 1, or 0 (out untouched) when d_pixel_q4 <= 0
 * or the inputs leave the range where its 64-bit products are exact: f_px and the image
 * offsets |u - u0|, |v - v0| up to MG_RANGING_MAX_PX, width up to that, D up to
 * MG_RANGING_MAX_UM, the point and the radius within MG_RANGING_MAX_UM_OUT (500 m). */
#define MG_RANGING_MAX_PX 2048
#define MG_RANGING_MAX_UM 100000
#define MG_RANGING_MAX_UM_OUT 500000000LL
int32_t mg_locate_ring_pair(int32_t d_pixel_q4, int32_t u_q4, int32_t v_q4, int32_t width_q4,
                            int32_t alpha_mrad, int32_t theta5_mrad, int32_t f_px,
                            int32_t u0_px, int32_t v0_px, int32_t d_um, int32_t *out);

/* bezier000.c, bezier001.c (bezier.h, bezier.c): the Bezier candidate evaluation of the 000
 * and 001 planners in fixed point (host/planning/bezier_q.py), from the candidates' control
 * points (12 int32 each: P0..P3 as x, y, t in 1/16 mm and 1/16 ms). Reasons per candidate
 * (bezier.h), the first violated sample, the cost of eq. (9) / (17) in Q16 (INT64_MAX when
 * infeasible). mg_bezier000 returns the best candidate (-1: none); mg_bezier001_coarse the
 * curves taken before the anytime cut; mg_bezier001_fine the first of the pool that passes
 * (-1: none) and in *tried how many it checked. */
int32_t mg_bezier000(const int32_t *ctrl, int32_t n_cand, int32_t n, const int32_t *lim,
                     int32_t k1_q16, int32_t k2_q16, int32_t *reason, int32_t *first,
                     int64_t *cost);
int32_t mg_bezier001_coarse(const int32_t *ctrl, int32_t n_cand, int32_t n,
                            const int32_t *lim, const int64_t *geo, int32_t n_reg,
                            int32_t per_sample_cycles, int32_t setup_cycles, int32_t cut_cycles,
                            int32_t k1_q16, int32_t k2_q16, int32_t *reason, int32_t *first,
                            int64_t *cost);
int32_t mg_bezier001_fine(const int32_t *ctrl, int32_t n_pool, int32_t n, const int32_t *lim,
                          const int64_t *geo, int32_t n_reg, int32_t per_sample_cycles,
                          int32_t setup_cycles, int32_t worst_us, int32_t budget_us,
                          int32_t *reason, int32_t *tried);
/* The same two passes in slices of a control step (the plan as an anytime computation,
 * host/planning/anytime.py): state[0] the next candidate, state[1] the pass's modelled cycles
 * so far (both 0 at the start); each call starts candidates while state[1] is below
 * slice_end_cycles and returns as the whole pass would once it has ended, else -1 (coarse)
 * or -2 (fine). Slice by slice they give the whole pass's results. */
int32_t mg_bezier001_coarse_slice(const int32_t *ctrl, int32_t n_cand, int32_t n,
                                  const int32_t *lim, const int64_t *geo, int32_t n_reg,
                                  int32_t per_sample_cycles, int32_t setup_cycles,
                                  int32_t cut_cycles, int32_t k1_q16, int32_t k2_q16,
                                  int32_t slice_end_cycles, int32_t *state, int32_t *reason,
                                  int32_t *first, int64_t *cost);
int32_t mg_bezier001_fine_slice(const int32_t *ctrl, int32_t n_pool, int32_t n,
                                const int32_t *lim, const int64_t *geo, int32_t n_reg,
                                int32_t per_sample_cycles, int32_t setup_cycles,
                                int32_t worst_us, int32_t budget_us, int32_t slice_end_cycles,
                                int32_t *state, int32_t *reason, int32_t *tried);

/* clearance.c: D_m of eq. (18) of 001 (host/planning/clearance_q.py) of one path of n samples
 * (x, y in 1/16 mm) to n_reg regions of MG_CLEAR_WORDS words each (clearance_words: sensing
 * position, cos, sin of the bisector and tan of the half-angle in Q14, eta, R_r, the arc's two
 * end points); MG_NO_REGION_Q4 without regions. */
#define MG_CLEAR_WORDS 11
#define MG_NO_REGION_Q4 ((int64_t)1 << 62)
int64_t mg_path_clearance(const int64_t *words, int32_t n_reg, const int64_t *x,
                          const int64_t *y, int32_t n);

/* double_cross.c: the 002 double cross from the grey image (host/vision/double_cross.py
 * detect_double_cross; the image centre U0 = 160, V0 = 120 px as there). out: u1_q4, v1_q4,
 * u2_q4, v2_q4, um_q4, vm_q4, d_pixel_q4, e_mrad, votes1, votes2. scratch:
 * mg_double_cross_scratch_bytes(w, h) bytes, 8-byte aligned. Returns 1 when found, 0 when not.
 * ops (NULL: not wanted): the operation counts the Python detector charges for the same frame,
 * its grey image apart (mg_grey_ops). */
int32_t mg_double_cross_scratch_bytes(int32_t w, int32_t h);
int32_t mg_double_cross(const uint8_t *grey, int32_t w, int32_t h, int32_t yaw_mrad,
                        int32_t pitch_mrad, int32_t f_px, uint8_t *scratch, int32_t *out,
                        mg_ops_t *ops);

#endif
