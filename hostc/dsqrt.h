/* Double-precision square root without an FPU or libm: the IEEE 754 correctly rounded result
 * (what sqrt() and numpy's sqrt give), from the integer root of the 53-bit mantissa shifted up
 * by 52 bits, two bits of the radicand per step (53 steps, a 64-bit remainder). */
#ifndef MG_DSQRT_H
#define MG_DSQRT_H

#include <stdint.h>

static inline double mg_dsqrt(double x)
{
    union { double d; uint64_t u; } v = { x };
    const uint64_t frac_mask = ((uint64_t)1 << 52) - 1;
    int e = (int)((v.u >> 52) & 0x7ff);
    uint64_t m = v.u & frac_mask;
    if (v.u >> 63)  /* negative (or -0) */
        return (x == 0.0) ? x : (x - x) / (x - x);
    if (e == 0x7ff || x == 0.0)  /* inf, nan, +0 */
        return x;
    if (e == 0) {  /* subnormal: normalise */
        e = 1;
        while (!(m >> 52)) {
            m <<= 1;
            e--;
        }
    } else {
        m |= (uint64_t)1 << 52;
    }
    /* x = m * 2^E with E = e - 1075 made even by doubling m: m in [2^52, 2^54) */
    int E = e - 1075;
    if (E & 1) {
        m <<= 1;
        E--;
    }
    /* root = floor(sqrt(m * 2^52)) in [2^52, 2^53); radicand bits come from m, then zeros */
    uint64_t rem = 0, root = 0;
    for (int i = 0; i < 53; i++) {
        const int at = 104 - 2 * i;  /* bit position of this pair in m * 2^52 */
        const uint64_t pair = at >= 52 ? (m >> (at - 52)) & 3u : 0u;
        rem = (rem << 2) | pair;
        const uint64_t trial = (root << 2) | 1u;
        root <<= 1;
        if (rem >= trial) {
            rem -= trial;
            root |= 1u;
        }
    }
    root += rem > root;  /* nearest: sqrt is never halfway between two integers */
    /* sqrt(x) = root * 2^(E/2 - 26); root's leading bit is 2^52 (a carry to 2^53 bumps e) */
    v.u = ((uint64_t)(E / 2 + 26 + 1023) << 52) + (root - ((uint64_t)1 << 52));
    return v.d;
}

#endif
