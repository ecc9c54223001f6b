/* The plan charged in slices of the control steps (host/planning/anytime.py PlanJob). */
#include "anytime.h"

#include <string.h>

#define CYCLES_PER_US (MG_FCLK_HZ / 1000000)

int mg_plan_job_start(mg_plan_job_t *job, const mg_ops_t *ops, int64_t slice_us)
{
    if (slice_us <= 0)
        return -1;
    job->remaining_us = mg_ops_time_us(ops);
    job->slice_us = slice_us;
    return 0;
}

int mg_plan_job_done(const mg_plan_job_t *job)
{
    return job->remaining_us <= 0;
}

mg_ops_t mg_plan_job_step(mg_plan_job_t *job)
{
    const int64_t take = job->remaining_us < job->slice_us ? job->remaining_us : job->slice_us;
    job->remaining_us -= take;
    mg_ops_t ops;
    memset(&ops, 0, sizeof ops);
    ops.alu = take * CYCLES_PER_US;
    return ops;
}

int64_t mg_plan_job_slices(const mg_plan_job_t *job)
{
    /* Python's -(-remaining // slice): the ceiling, for either sign of remaining */
    const int64_t r = job->remaining_us, s = job->slice_us;
    const int64_t q = r / s;
    return (r % s != 0 && r > 0) ? q + 1 : q;
}
