/* trig.c: sine and cosine in Q12 of an angle in mrad (|angle| up to 12.8e6 mrad, 2000 turns:
 * the mrad-to-binary-angle product stays in 64 bits), atan2 in micro-radians and in mrad of two
 * integers in a common unit (|y|, |x| < 2^62); host/fixedpoint.py sin_q12, cos_q12, atan2_urad,
 * atan2_mrad. Shared by the vision kernels (kernels.h) and the host's fixed point. */
#ifndef MOBIGRASP_HOSTC_TRIG_H
#define MOBIGRASP_HOSTC_TRIG_H

#include <stdint.h>

int32_t mg_sin_q12(int32_t angle_mrad);
int32_t mg_cos_q12(int32_t angle_mrad);
/* sin and cos (Q12) of num / den of a turn (den > 0, |num / den| < 2^11), through a binary
 * angle of 2^-20 turn, rounded: exact at the quarter turns */
void mg_sincos_turn_q12(int64_t num, int64_t den, int32_t *sin_q12, int32_t *cos_q12);
/* sin and cos (Q14) of an angle in urad (|angle| < 2^32), through a binary angle of 2^-20
 * turn, rounded (host/fixedpoint.py sincos_urad_q14) */
void mg_sincos_urad_q14(int64_t angle_urad, int32_t *sin_q14, int32_t *cos_q14);
int32_t mg_atan2_urad(int64_t y, int64_t x);
int32_t mg_atan2_mrad(int64_t y, int64_t x);

#endif
