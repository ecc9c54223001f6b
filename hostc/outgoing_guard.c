/* The last gate before a command is encoded (host/outgoing_guard.py). */
#include "outgoing_guard.h"

#include "arm_calib.h"
#include "messages.h"

int32_t mg_check_servo_mrad(const int32_t targets[6])
{
    for (int32_t ch = 0; ch < MG_N_CHANNELS; ch++)
        if (!mg_within_limits(ch, targets[ch]))
            return MG_OUT_OF_LIMITS;
    return MG_OUT_OK;
}

int32_t mg_check_wheels(int32_t left_mmps, int32_t right_mmps)
{
    const int32_t lim = MSG_WHEEL_LIMIT_MMPS;
    return (left_mmps < -lim || left_mmps > lim || right_mmps < -lim || right_mmps > lim)
               ? MG_OUT_OF_LIMITS
               : MG_OUT_OK;
}

int32_t mg_check_gripper(int32_t close_permille)
{
    return (close_permille < 0 || close_permille > (int32_t)MSG_GRIPPER_MAX) ? MG_OUT_OF_LIMITS
                                                                            : MG_OUT_OK;
}

void mg_guard_init(mg_outgoing_guard_t *g)
{
    g->passed = 0;
    g->out_of_limits = 0;
}

static int count(mg_outgoing_guard_t *g, int32_t reason)
{
    if (reason != MG_OUT_OK) {
        g->out_of_limits++;
        return 0;
    }
    g->passed++;
    return 1;
}

int mg_guard_servo_mrad(mg_outgoing_guard_t *g, const int32_t targets[6])
{
    return count(g, mg_check_servo_mrad(targets));
}

int mg_guard_wheels(mg_outgoing_guard_t *g, int32_t left_mmps, int32_t right_mmps)
{
    return count(g, mg_check_wheels(left_mmps, right_mmps));
}

int mg_guard_gripper(mg_outgoing_guard_t *g, int32_t close_permille)
{
    return count(g, mg_check_gripper(close_permille));
}
