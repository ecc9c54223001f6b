/* Integer square root, shared by the kernels (host/fixedpoint.py isqrt): floor(sqrt(n)) bit by
 * bit, 16 steps. static inline so each kernel's loop sees it as the Python loop does. */
#ifndef MG_ISQRT_H
#define MG_ISQRT_H

#include <stdint.h>

static inline int32_t mg_isqrt32(uint32_t n)
{
    uint32_t res = 0, bit = 1u << 30;
    while (bit > n)
        bit >>= 2;
    while (bit) {
        if (n >= res + bit) {
            n -= res + bit;
            res = (res >> 1) + bit;
        } else {
            res >>= 1;
        }
        bit >>= 2;
    }
    return (int32_t)res;
}

/* the same on 64 bits (the ring-pair ranging's squared distances in µm) */
static inline int64_t mg_isqrt64(uint64_t n)
{
    uint64_t res = 0, bit = (uint64_t)1 << 62;
    while (bit > n)
        bit >>= 2;
    while (bit) {
        if (n >= res + bit) {
            n -= res + bit;
            res = (res >> 1) + bit;
        } else {
            res >>= 1;
        }
        bit >>= 2;
    }
    return (int64_t)res;
}

#endif
