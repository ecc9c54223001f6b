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

#endif
