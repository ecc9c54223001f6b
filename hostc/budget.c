/* ARM920T cycles of operation counts (host/budget.py OpCounts.cycles, time_us). */
#include "budget.h"

/* cycles per operation, host/budget.py's constants and their sources */
#define CYCLES_ALU 1        /* TRM 8.2: single-cycle data processing */
#define CYCLES_BRANCH 3     /* a taken branch refills the 5-stage pipeline */
#define CYCLES_PIXEL_READ 2 /* LDRB + load-use interlock */
#define CYCLES_PIXEL_WRITE 1
#define CYCLES_MUL 3        /* 16-bit operands, Booth early termination */
#define CYCLES_MUL32 5
#define CYCLES_DIV 45       /* __aeabi_idiv, typical */
#define CYCLES_LUT 2
#define CYCLES_FLOAT_OP 75  /* libgcc double add/mul (calibrated, docs/budget.md) */
#define CYCLES_FLOAT_DIV 520
#define CYCLES_LINE_FILL 40 /* one 32-byte D-cache line from SDRAM */
#define CACHE_LINE_BYTES 32

mg_ops_t mg_ops_add(mg_ops_t a, mg_ops_t b)
{
    a.pixels_read += b.pixels_read;
    a.pixels_written += b.pixels_written;
    a.alu += b.alu;
    a.branches += b.branches;
    a.muls += b.muls;
    a.muls32 += b.muls32;
    a.divs += b.divs;
    a.luts += b.luts;
    a.float_ops += b.float_ops;
    a.float_divs += b.float_divs;
    a.bytes_streamed += b.bytes_streamed;
    return a;
}

mg_ops_t mg_ops_scaled(mg_ops_t a, int64_t k)
{
    a.pixels_read *= k;
    a.pixels_written *= k;
    a.alu *= k;
    a.branches *= k;
    a.muls *= k;
    a.muls32 *= k;
    a.divs *= k;
    a.luts *= k;
    a.float_ops *= k;
    a.float_divs *= k;
    a.bytes_streamed *= k;
    return a;
}

/* ceil(a / b) for b > 0, as Python's -(-a // b) */
static int64_t ceil_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b != 0 && a > 0) ? q + 1 : q;
}

int64_t mg_ops_cycles(const mg_ops_t *o)
{
    return o->pixels_read * CYCLES_PIXEL_READ + o->pixels_written * CYCLES_PIXEL_WRITE
           + o->alu * CYCLES_ALU + o->branches * CYCLES_BRANCH + o->muls * CYCLES_MUL
           + o->muls32 * CYCLES_MUL32 + o->divs * CYCLES_DIV + o->luts * CYCLES_LUT
           + o->float_ops * CYCLES_FLOAT_OP + o->float_divs * CYCLES_FLOAT_DIV
           + ceil_div(o->bytes_streamed, CACHE_LINE_BYTES) * CYCLES_LINE_FILL;
}

int64_t mg_ops_time_us(const mg_ops_t *o)
{
    /* ceil(cycles 10^6 / FCLK) = ceil(cycles / (FCLK / 10^6)): FCLK is whole MHz */
    return ceil_div(mg_ops_cycles(o), MG_FCLK_HZ / 1000000);
}
