/* A straight way out through free sonar space, clear of 001's infeasible regions (eq. (16))
 * (host/planning/escape.py): the detour's test of a straight segment and its choice of
 * heading. Positions and lengths in 1/16 mm, headings in mrad (segment) or urad (choice); the
 * regions as bezier.h's geo (one region each: geo_each, MG_GEO_HEAD + MG_REGION_WORDS words a
 * region) and clearance.c's words (clear_each, MG_CLEAR_WORDS a region), already grown by the
 * caller's margin. */
#ifndef MG_ESCAPE_H
#define MG_ESCAPE_H

#include <stdint.h>

#include "budget.h"

#define MG_ESCAPE_MAX_HEADINGS 65 /* 2 n_side + 1 */

/* 1 when the segment of length_q4 along heading_mrad from (px, py) enters none of the n_reg
 * regions at its samples points after the start (samples >= 1); leave_ok: a region the start
 * lies in may be crossed where the segment keeps farther from its echo than the start less
 * LEAVE_TOL (escape.py segment_clear; 1 for a length <= 0). *ops the test's ARM9 cost, the
 * regions' set-up not included. */
int mg_segment_clear_q(const int64_t *geo_each, const int64_t *clear_each, int32_t n_reg,
                       int64_t px_q4, int64_t py_q4, int32_t heading_mrad, int64_t length_q4,
                       int32_t samples, int leave_ok, mg_ops_t *ops);
/* the heading (urad, wrapped) nearest goal_urad among h_urad + j step_urad, |j| <= n_side,
 * whose segment is clear (leave_ok), the side's headings first (side +1 left, -1 right, 0
 * none): 1 and *out_urad, or 0 (none, or n_side beyond the capacity); *ops its ARM9 cost,
 * the regions' set-up not included (escape.py REGION_WORDS_OPS, float in Python) */
int mg_escape_heading_q(const int64_t *geo_each, const int64_t *clear_each, int32_t n_reg,
                        int64_t px_q4, int64_t py_q4, int64_t h_urad, int64_t goal_urad,
                        int64_t step_urad, int32_t n_side, int64_t length_q4, int32_t samples,
                        int32_t side, int64_t *out_urad, mg_ops_t *ops);

#endif
