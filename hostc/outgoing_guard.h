/* Validation of every value the host sends to the MCU (host/outgoing_guard.py): a value outside
 * its limit is refused with a reason and counted, never clamped here (clamping is the caller's
 * policy, app_link.c). Limits: servo targets per the joint table (channel 0 the gripper closure
 * in per mille), wheel speeds within +-1000 mm/s, the gripper 0..1000 per mille. In C every
 * value is an integer by type, so of the Python reasons only out_of_limits can arise. */
#ifndef MOBIGRASP_HOSTC_OUTGOING_GUARD_H
#define MOBIGRASP_HOSTC_OUTGOING_GUARD_H

#include <stdint.h>

enum { MG_OUT_OK = 0, MG_OUT_OF_LIMITS = 1 };

typedef struct {
    uint32_t passed;
    uint32_t out_of_limits; /* refusals, host/outgoing_guard.py's "out_of_limits" */
} mg_outgoing_guard_t;

int32_t mg_check_servo_mrad(const int32_t targets[6]); /* MG_OUT_OK or the reason */
int32_t mg_check_wheels(int32_t left_mmps, int32_t right_mmps);
int32_t mg_check_gripper(int32_t close_permille);

void mg_guard_init(mg_outgoing_guard_t *g);
/* the checks with counted refusals: 1 passed, 0 refused */
int mg_guard_servo_mrad(mg_outgoing_guard_t *g, const int32_t targets[6]);
int mg_guard_wheels(mg_outgoing_guard_t *g, int32_t left_mmps, int32_t right_mmps);
int mg_guard_gripper(mg_outgoing_guard_t *g, int32_t close_permille);

#endif
