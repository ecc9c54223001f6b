/* Rounded 64-bit division and Q12 product (host/fixedpoint.py div_round, mul_q12), inline:
 * the vision kernels use them in their loops, fixedpoint.c exports them. */
#ifndef MOBIGRASP_HOSTC_DIV_ROUND_H
#define MOBIGRASP_HOSTC_DIV_ROUND_H

#include <stdint.h>

/* num / den rounded, halves away from zero, either sign of den; den != 0 */
static inline int64_t mg_div_round_i64(int64_t num, int64_t den)
{
    const uint64_t an = num < 0 ? (uint64_t)0 - (uint64_t)num : (uint64_t)num;
    const uint64_t ad = den < 0 ? (uint64_t)0 - (uint64_t)den : (uint64_t)den;
    uint64_t q = an / ad;
    if (2 * (an - q * ad) >= ad)
        q++;
    return ((num >= 0) == (den > 0)) ? (int64_t)q : -(int64_t)q;
}

/* the Q12 product rounded half up; the shift is arithmetic, as Python's >> */
static inline int64_t mg_mul_q12_i64(int64_t a, int64_t b)
{
    return (a * b + 2048) >> 12;
}

#endif
