/* The base drive the states share (host/task/drive.py): so far the angle wrap. */
#ifndef MOBIGRASP_HOSTC_TASK_DRIVE_H
#define MOBIGRASP_HOSTC_TASK_DRIVE_H

#include <stdint.h>

int32_t mg_task_wrap_mrad(int64_t a_mrad); /* to [-pi, pi): [-3142, 3140], 2 pi = 6283 mrad */

#endif
