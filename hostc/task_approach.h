/* APPROACH's path approach of 000 and 001 (host/task/approach.py ApproachStates.follow_path):
 * the radial symbol updates the estimate, the method plans (its planner's time charged in
 * slices of the control step, host/planning/anytime.py), the follower of eq. (8) of 000 drives
 * the curve while the posture adjustment (eq. (10) of 000) keeps the object in view; at the
 * curve's end or near the object the method's next state (000: ADJUST; 001: the grasp from
 * its grasp circle). Where 000 and 001 differ the step asks the method's path hooks
 * (approach.py PathMethod). */
#ifndef MOBIGRASP_HOSTC_TASK_APPROACH_H
#define MOBIGRASP_HOSTC_TASK_APPROACH_H

#include <stdint.h>

#include "path_follow.h"
#include "task_machine.h"

/* approach.py PathMethod: the hooks of the path approach */
typedef struct mg_path_method {
    /* plan from the present pose toward the estimate: the curve's table into traj (the
     * task's next_traj), the outcome (a path or none, its wheel limit, its modelled time, its
     * reason) into o */
    void (*plan)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, mg_trajectory_t *traj,
                 mg_plan_outcome_t *o);
    /* the planned path's time starts now, in the step of its plan's last slice (NULL: only
     * the follower's) */
    void (*start_path)(mg_task_t *t, int64_t now_us);
    /* this step's radial symbol may update the estimate */
    int (*sighting_usable)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* the sonar check of the path followed: -1 none due, 1 the step ends here (the base
     * stopped), 0 follow on */
    int (*sonar_replan)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, int moved);
    /* something else than a plan in this step (1: the wheels are set) */
    int (*hold_before_plan)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* no feasible curve: the straight close approach toward the object dist_mm away is
     * blocked */
    int (*way_blocked)(mg_task_t *t, const mg_task_inputs_t *in, int32_t dist_mm);
    /* no feasible curve, no direct approach: a drive aside started (1) or not */
    int (*start_detour)(mg_task_t *t, const mg_task_inputs_t *in);
    /* the wheels from the follower's command */
    void (*path_wheels)(const mg_wheel_command_t *cmd, int32_t wheels[2]);
    /* the path followed to its end (the follower's error there, *error_mm), the object near,
     * or no path needed (error_mm NULL), for the reason why: the transition (000: ADJUST; 001:
     * ROUGH_GRASP on its grasp circle) */
    void (*path_end)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, const char *why,
                     const int32_t *error_mm);
    /* the path ends early with the object this much beyond ADJUST's goal (grasp_r_mm) */
    int32_t near_margin_mm;
    /* and, when not 0, with the object (by the estimate) within this much of the footprint
     * once the base has braked (approach.py _object_at_footprint) */
    int32_t object_clear_mm;
    /* the work of a step along the path, charged each step (PathMethod.follow_ops); NULL:
     * not charged */
    mg_ops_t (*follow_ops)(void);
} mg_path_method_t;


/* APPROACH's common entry (approach.py enter_APPROACH before the method's): no path, no
 * attempts, no plan being charged */
void mg_task_enter_path(mg_task_t *t);
/* one step of the path approach (a method without path hooks stands); radial: this frame's
 * radial symbol as its glue gives it (its pixel and depth), NULL: none */
void mg_task_follow_path(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                         const mg_sighting_t *radial);

/* a plan charged in slices (anytime.py PlanJob.start and step): the job of a plan of
 * time_us, its path t->path.next_traj with v_limit_mm_s (has_path 0: none) and its outcome to
 * handle (has_detail, reason); and one control step's slice charged to the step's ops, 1 once
 * all its slices are charged */
void mg_task_plan_job_start(mg_task_t *t, int32_t has_path, int32_t v_limit_mm_s,
                            int32_t has_detail, const char *reason, int64_t time_us);
int mg_task_plan_job_step(mg_task_t *t);
/* modelled ARM9 work charged to this step (t.charge) */
void mg_task_charge(mg_task_t *t, const mg_ops_t *ops);
/* the wheels turning the base on the spot: direction +1 counter-clockwise, -1 clockwise
 * (drive.py turn_in_place) */
void mg_task_turn_in_place(int32_t direction, int32_t wheel_mmps, int32_t wheels[2]);
/* s holds word (Python's `word in s`) */
int mg_task_text_has(const char *s, const char *word);

#endif
