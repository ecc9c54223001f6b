/* The base drive the states share (host/task/drive.py): so far the angle wrap. */
#ifndef MOBIGRASP_HOSTC_TASK_DRIVE_H
#define MOBIGRASP_HOSTC_TASK_DRIVE_H

#include <stdint.h>

int32_t mg_task_wrap_mrad(int64_t a_mrad); /* to [-pi, pi): [-3142, 3140], 2 pi = 6283 mrad */

/* the close approach toward an object at platform (X_r, Y_r) Q4 mm: the wheels (eq. (8) of
 * 000), 1 when it is grasp_r_mm +- tol_mm ahead within bearing_tol_mrad; its distance, bearing
 * and error */
typedef struct {
    int32_t dist_mm, bearing_mrad, err_mm;
} mg_close_in_t;
int mg_close_in(const int32_t obj_q4[2], int32_t grasp_r_mm, int32_t tol_mm,
                int32_t bearing_tol_mrad, int32_t vmax_mmps, int32_t wheels[2],
                mg_close_in_t *d);

#endif
