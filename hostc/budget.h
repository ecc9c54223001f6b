/* ARM920T cycle accounting of the host (host/budget.py): operation counts of a kernel call, the
 * cycles they cost at the constants cited there (ARM DDI 0151C ch. 7 and 8; docs/budget.md for
 * the calibrated ones) and the modelled time at FCLK = 400 MHz, so the C host charges the same
 * ARM9 time as the Python host. */
#ifndef MOBIGRASP_HOSTC_BUDGET_H
#define MOBIGRASP_HOSTC_BUDGET_H

#include <stdint.h>

#define MG_FCLK_HZ 400000000LL

/* host/budget.py OpCounts, its fields in the same order */
typedef struct {
    int64_t pixels_read, pixels_written, alu, branches, muls, muls32, divs, luts, float_ops,
        float_divs, bytes_streamed;
} mg_ops_t;

mg_ops_t mg_ops_add(mg_ops_t a, mg_ops_t b);
mg_ops_t mg_ops_scaled(mg_ops_t a, int64_t k);
int64_t mg_ops_cycles(const mg_ops_t *ops);
int64_t mg_ops_time_us(const mg_ops_t *ops); /* whole microseconds, rounded up */

/* The vision kernels' counting in place, field by field: their calibration build (calib/arm.py)
 * has no libc for a struct copy or an initialiser. mg_ops_clear sets *o to 0; mg_ops_charge adds
 * to it (the fields of mg_ops_t but the float ones: the kernels are integer only). */
static inline void mg_ops_clear(mg_ops_t *o)
{
    o->pixels_read = o->pixels_written = o->alu = o->branches = o->muls = o->muls32 = 0;
    o->divs = o->luts = o->float_ops = o->float_divs = o->bytes_streamed = 0;
}

static inline void mg_ops_charge(mg_ops_t *o, int64_t pixels_read, int64_t pixels_written,
                                 int64_t alu, int64_t branches, int64_t muls, int64_t muls32,
                                 int64_t divs, int64_t luts, int64_t bytes_streamed)
{
    o->pixels_read += pixels_read;
    o->pixels_written += pixels_written;
    o->alu += alu;
    o->branches += branches;
    o->muls += muls;
    o->muls32 += muls32;
    o->divs += divs;
    o->luts += luts;
    o->bytes_streamed += bytes_streamed;
}

#endif
