/* The arm's joint table on the host (host/arm_calib.py): limits and the servo law of
 * firmware/protocol/joints.c, the one table both boards read. Channel 0 is the gripper (closure
 * in per mille), 1..5 the joints theta1..theta5 in mrad. */
#ifndef MOBIGRASP_HOSTC_ARM_CALIB_H
#define MOBIGRASP_HOSTC_ARM_CALIB_H

#include <stdint.h>

#define MG_N_CHANNELS 6

int32_t mg_joint_lo_mrad(int32_t ch);
int32_t mg_joint_hi_mrad(int32_t ch);
int32_t mg_clamp_mrad(int32_t ch, int32_t angle_mrad);
int mg_within_limits(int32_t ch, int32_t angle_mrad);
/* the servo law with the angle clamped first; always in [500, 2500] us */
int32_t mg_mrad_to_pulse_us(int32_t ch, int32_t angle_mrad);
/* the inverse law, clamped to the limits: 1 and *out, or 0 for a pulse outside 500..2500 us */
int mg_pulse_us_to_mrad(int32_t ch, int32_t pulse_us, int32_t *out_mrad);
/* all six channels: 1, or 0 (out untouched past the bad one) for a pulse out of range */
int mg_pulses_to_joints_mrad(const int32_t pulses_us[MG_N_CHANNELS],
                             int32_t out_mrad[MG_N_CHANNELS]);
void mg_joints_to_pulses_us(const int32_t angles_mrad[MG_N_CHANNELS],
                            int32_t out_us[MG_N_CHANNELS]);
void mg_clamp_joints_mrad(const int32_t angles_mrad[MG_N_CHANNELS],
                          int32_t out_mrad[MG_N_CHANNELS]);

#endif
