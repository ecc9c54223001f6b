/* ADJUST (host/task/adjust.py): the close approach on the object estimate with the posture
 * adjustment: 000 and 001 close in on the dual "+" (the radial symbol when the "+" are out of
 * the detector's range, 000 section III.B); 002 "slows down and goes straight with posture
 * adjustment" (002 section 1) until the method's stop rule (d_pixel > T_d) says the object is
 * in the workspace. */
#ifndef MOBIGRASP_HOSTC_TASK_ADJUST_H
#define MOBIGRASP_HOSTC_TASK_ADJUST_H

#include <stdint.h>

#include "task_machine.h"

/* the close-look posture (shoulder up, elbow bent, alpha kept); frames count from its settling */
void mg_task_enter_adjust(mg_task_t *t, int64_t now_us);
/* one step; det: this frame's result of the method's adjust detector (NULL: none); radial:
 * the radial symbol's sighting (its glue's pixel and depth) of 000 and 001, read when det is
 * NULL (the dual "+" out of the detector's range; NULL: none) */
void mg_task_do_adjust(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       const void *det, const mg_sighting_t *radial);

#endif
