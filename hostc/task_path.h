/* The path the approach of 000 and 001 follows, the task's part of it (host/task/machine.py:
 * follower, plan_job, plan_obj, plan_us, plan_attempts, counters["plans"]), and the plan whose
 * modelled time is charged in slices of the control step before its path is taken
 * (host/planning/anytime.py PlanJob). Data only: the approach is task_approach.c. */
#ifndef MOBIGRASP_HOSTC_TASK_PATH_H
#define MOBIGRASP_HOSTC_TASK_PATH_H

#include <stdint.h>

#include "budget.h"
#include "path_follow.h"

enum {
    MG_TASK_PLAN_SLICE_US = 8000, /* anytime.py PLAN_SLICE_US: a step's share of planning */
    MG_TASK_PLAN_CYCLES_PER_US = 400, /* FCLK 400 MHz */
    MG_PLAN_REASON = 160 /* bytes of a plan's reason, its terminating 0 included */
};

/* what a planner gives (the Python's (follower, ops, detail)): a path or none, why */
typedef struct {
    int32_t has_path;     /* the curve's reference table was written, follow it */
    int32_t v_limit_mm_s; /* the follower's wheel limit (the plan's Vmax) */
    int64_t time_us;      /* the plan's modelled ARM9 time, charged in slices */
    char reason[MG_PLAN_REASON];
} mg_plan_outcome_t;

typedef struct {
    /* the path followed now (t.follower), its reference table */
    int32_t has_follower;
    mg_path_follower_t follower;
    mg_trajectory_t traj;
    /* the plan being charged (t.plan_job): the slices left, the path it gives (has_next,
     * next_traj, next_v_limit_mm_s), its outcome to handle once charged (has_detail: a plan's,
     * 0: a replan's whose failure needs nothing more) */
    int32_t has_job;
    int64_t job_remaining_us;
    int32_t has_next;
    mg_trajectory_t next_traj;
    int32_t next_v_limit_mm_s;
    int32_t job_has_detail;
    char job_reason[MG_PLAN_REASON];
    /* the estimate the last plan went to (t.plan_obj), its time, the failed attempts */
    int32_t has_plan_obj, plan_obj_mm[2];
    int64_t plan_us;
    int32_t plan_attempts;
    int32_t plans;  /* plans made (counters["plans"]) */
    mg_ops_t ops;   /* this step's planning work charged (t.charge), reset by the approach */
} mg_task_path_t;

#endif
