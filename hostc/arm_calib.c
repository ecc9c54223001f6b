/* Joint limits and the servo law on the host (host/arm_calib.py), from the joint table of
 * firmware/protocol/joints.c. */
#include "arm_calib.h"

#include "fixedpoint.h"
#include "joints.h"

int32_t mg_joint_lo_mrad(int32_t ch)
{
    return joint_row((uint8_t)ch).lo;
}

int32_t mg_joint_hi_mrad(int32_t ch)
{
    return joint_row((uint8_t)ch).hi;
}

int32_t mg_clamp_mrad(int32_t ch, int32_t angle_mrad)
{
    const joint_t j = joint_row((uint8_t)ch);
    return angle_mrad < j.lo ? j.lo : angle_mrad > j.hi ? j.hi : angle_mrad;
}

int mg_within_limits(int32_t ch, int32_t angle_mrad)
{
    const joint_t j = joint_row((uint8_t)ch);
    return j.lo <= angle_mrad && angle_mrad <= j.hi;
}

int32_t mg_mrad_to_pulse_us(int32_t ch, int32_t angle_mrad)
{
    const int32_t p = joint_pulse_us((uint8_t)ch, mg_clamp_mrad(ch, angle_mrad));
    return p < JOINT_PULSE_MIN_US   ? JOINT_PULSE_MIN_US
           : p > JOINT_PULSE_MAX_US ? JOINT_PULSE_MAX_US
                                    : p;
}

int mg_pulse_us_to_mrad(int32_t ch, int32_t pulse_us, int32_t *out_mrad)
{
    if (pulse_us < JOINT_PULSE_MIN_US || pulse_us > JOINT_PULSE_MAX_US)
        return 0;
    const joint_t j = joint_row((uint8_t)ch);
    int32_t angle;
    if (ch == JOINT_GRIPPER_CH)
        angle = pulse_us - j.pulse0_us;
    else /* protocol/joints.py angle_of_pulse */
        angle = j.direction
                * (int32_t)mg_div_round64((int64_t)(pulse_us - j.pulse0_us) * JOINT_K_DEN,
                                          JOINT_K_NUM);
    *out_mrad = mg_clamp_mrad(ch, angle);
    return 1;
}

int mg_pulses_to_joints_mrad(const int32_t pulses_us[MG_N_CHANNELS],
                             int32_t out_mrad[MG_N_CHANNELS])
{
    for (int32_t ch = 0; ch < MG_N_CHANNELS; ch++)
        if (!mg_pulse_us_to_mrad(ch, pulses_us[ch], &out_mrad[ch]))
            return 0;
    return 1;
}

void mg_joints_to_pulses_us(const int32_t angles_mrad[MG_N_CHANNELS],
                            int32_t out_us[MG_N_CHANNELS])
{
    for (int32_t ch = 0; ch < MG_N_CHANNELS; ch++)
        out_us[ch] = mg_mrad_to_pulse_us(ch, angles_mrad[ch]);
}

void mg_clamp_joints_mrad(const int32_t angles_mrad[MG_N_CHANNELS],
                          int32_t out_mrad[MG_N_CHANNELS])
{
    for (int32_t ch = 0; ch < MG_N_CHANNELS; ch++)
        out_mrad[ch] = mg_clamp_mrad(ch, angles_mrad[ch]);
}
