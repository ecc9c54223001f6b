/* The planner as an anytime computation in slices of the 20 ms control step
 * (host/planning/anytime.py): a plan of modelled time remaining_us is charged at most slice_us
 * a control step; its result is taken in the step of the last slice. */
#ifndef MG_ANYTIME_H
#define MG_ANYTIME_H

#include <stdint.h>

#include "budget.h"

#define MG_PLAN_SLICE_US 8000

typedef struct {
    int64_t remaining_us;
    int64_t slice_us;
} mg_plan_job_t;

/* a job for a plan of modelled cost ops; -1 (job untouched) when slice_us <= 0 */
int mg_plan_job_start(mg_plan_job_t *job, const mg_ops_t *ops, int64_t slice_us);
/* all slices charged: the plan's result may be used */
int mg_plan_job_done(const mg_plan_job_t *job);
/* the slice of this control step (at most slice_us) as ARM9 cycles (alu) */
mg_ops_t mg_plan_job_step(mg_plan_job_t *job);
/* control steps still needed */
int64_t mg_plan_job_slices(const mg_plan_job_t *job);

#endif
