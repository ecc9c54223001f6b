/* APPROACH's path approach of 000 and 001 (host/task/approach.py), and the plan charged in
 * slices (host/planning/anytime.py PlanJob). */
#include "task_approach.h"

#include <string.h>

#include "fixedpoint.h"
#include "task_method.h"
#include "trig.h"

int mg_task_text_has(const char *s, const char *word)
{
    const size_t n = strlen(word), m = strlen(s);
    for (size_t i = 0; i + n <= m; i++)
        if (strncmp(s + i, word, n) == 0)
            return 1;
    return 0;
}

void mg_task_charge(mg_task_t *t, const mg_ops_t *ops)
{
    t->path.ops = mg_ops_add(t->path.ops, *ops);
}

void mg_task_turn_in_place(int32_t direction, int32_t wheel_mmps, int32_t wheels[2])
{
    wheels[0] = -direction * wheel_mmps;
    wheels[1] = direction * wheel_mmps;
}

void mg_task_plan_job_start(mg_task_t *t, int32_t has_path, int32_t v_limit_mm_s,
                            int32_t has_detail, const char *reason, int64_t time_us)
{
    mg_task_path_t *ps = &t->path;
    ps->has_job = 1;
    ps->job_remaining_us = time_us;
    ps->has_next = has_path;
    ps->next_v_limit_mm_s = v_limit_mm_s;
    ps->job_has_detail = has_detail;
    mg_task_text(ps->job_reason, sizeof ps->job_reason, 0, reason);
}

int mg_task_plan_job_step(mg_task_t *t)
{
    mg_task_path_t *ps = &t->path;
    const int64_t take = ps->job_remaining_us < MG_TASK_PLAN_SLICE_US ? ps->job_remaining_us
                                                                      : MG_TASK_PLAN_SLICE_US;
    ps->job_remaining_us -= take;
    mg_ops_t ops;
    memset(&ops, 0, sizeof ops);
    ops.alu = take * MG_TASK_PLAN_CYCLES_PER_US;
    mg_task_charge(t, &ops);
    return ps->job_remaining_us <= 0;
}

void mg_task_enter_path(mg_task_t *t)
{
    t->path.has_follower = 0;
    t->path.plan_attempts = 0;
    t->path.has_job = 0;
}

static int32_t obj_dist_mm(const mg_task_t *t, const mg_task_inputs_t *in)
{
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    return (int32_t)(mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1]) >> 4);
}

/* the base's travel after its wheels are set to 0 (approach.py BRAKE_MS) */
#define BRAKE_MS 150

/* the object's estimate within clear_mm of the footprint (radius sonar_offset_mm) once the
 * base, stopped now, has braked (BRAKE_MS at its speed); clear_mm 0: not checked */
static int object_at_footprint(const mg_task_t *t, const mg_task_inputs_t *in, int32_t clear_mm)
{
    if (!clear_mm)
        return 0;
    const int64_t dx = (int64_t)t->obj_mm[0] - in->x_mm, dy = (int64_t)t->obj_mm[1] - in->y_mm;
    const int64_t axle_mm = mg_isqrt(dx * dx + dy * dy);
    const int64_t brake_mm = (int64_t)(in->v_mmps > 0 ? in->v_mmps : 0) * BRAKE_MS / 1000;
    return axle_mm - brake_mm <= (int64_t)t->p.sonar_offset_mm + clear_mm;
}

/* the follower's command for the present pose, its wheels by the method, the method's count
 * of the step along the path charged */
static mg_wheel_command_t follow(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const mg_pose_t pose = {(int64_t)in->x_mm * 1000, (int64_t)in->y_mm * 1000,
                            in->heading_mrad, in->v_mmps, 0};
    const mg_wheel_command_t cmd = mg_path_follower_step(&t->path.follower, now_us, &pose);
    t->rules->path->path_wheels(&cmd, t->wheels);
    if (t->rules->path->follow_ops) {
        const mg_ops_t ops = t->rules->path->follow_ops();
        mg_task_charge(t, &ops);
    }
    return cmd;
}

/* the path of the plan just charged, its time starting now */
static void start_path(mg_task_t *t, int64_t now_us)
{
    mg_task_path_t *ps = &t->path;
    memcpy(&ps->traj, &ps->next_traj, sizeof ps->traj);
    const mg_follow_gains_t gains = {6144, 16, 8}; /* path_follow.py FollowGains() */
    mg_path_follower_init(&ps->follower, &ps->traj, now_us, ps->next_v_limit_mm_s, &gains, 30,
                          3000000);
    ps->has_follower = 1;
    if (t->rules->path->start_path)
        t->rules->path->start_path(t, now_us);
}

/* Turn the base in place toward the object; 1 once it faces it (ours, not the papers': a
 * curve from a standstill facing away can violate A_max or R_min). */
static int face_object(mg_task_t *t, const mg_task_inputs_t *in)
{
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    /* seen from the axle */
    const int32_t bearing = mg_atan2_mrad(xy[0], (int64_t)xy[1] + t->p.mount_forward_mm * 16);
    if ((bearing < 0 ? -bearing : bearing) <= t->p.bearing_tol_mrad) {
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    mg_task_turn_in_place(bearing > 0 ? -1 : 1, t->p.turn_wheel_mmps, t->wheels);
    return 0;
}

/* No path from the plan: already there, fewer attempts, the direct approach, a detour, or a
 * failure. */
static void plan_failed(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                        const char *reason)
{
    char why[MG_TASK_WHY];
    if (mg_task_text_has(reason, "already")) {
        const size_t n = mg_task_text(why, sizeof why, 0, "no path needed: ");
        mg_task_text(why, sizeof why, n, reason);
        t->rules->path->path_end(t, now_us, in, why, NULL);
        return;
    }
    t->path.plan_attempts++;
    if (t->path.plan_attempts < t->p.max_plan_attempts)
        return;
    const int32_t dist = obj_dist_mm(t, in);
    if (dist <= t->p.direct_max_mm && !t->rules->path->way_blocked(t, in, dist)) {
        /* the close approach can do it */
        size_t n = mg_task_text(why, sizeof why, 0, "no feasible curve (");
        n = mg_task_text(why, sizeof why, n, reason);
        n = mg_task_text(why, sizeof why, n, "); object ");
        n = mg_task_text_int(why, sizeof why, n, dist);
        mg_task_text(why, sizeof why, n, " mm away: direct approach");
        mg_task_go(t, now_us, MG_ADJUST, why);
    } else if (t->rules->path->start_detour(t, in)) {
        t->path.plan_attempts = 0;
        t->path.has_follower = 0;
    } else { /* not straight into something in the way */
        const size_t n = mg_task_text(why, sizeof why, 0, "no feasible approach path: ");
        mg_task_text(why, sizeof why, n, reason);
        mg_task_fail(t, now_us, why);
    }
}

/* This step's slice of the plan being charged; 1 once it is done (its path installed,
 * starting now, or its failure handled), 0 while it is still computed. */
static int plan_slice(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_task_path_t *ps = &t->path;
    if (!mg_task_plan_job_step(t)) {
        if (ps->has_follower) { /* the old path meanwhile */
            mg_task_look_at_object(t, in, 1);
            follow(t, now_us, in);
        } else {
            t->wheels[0] = t->wheels[1] = 0;
        }
        return 0;
    }
    ps->has_job = 0;
    if (ps->has_next)
        start_path(t, now_us);
    else if (ps->job_has_detail)
        plan_failed(t, now_us, in, ps->job_reason);
    return 1;
}

static void plan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_task_path_t *ps = &t->path;
    mg_plan_outcome_t o;
    memset(&o, 0, sizeof o);
    t->rules->path->plan(t, now_us, in, &ps->next_traj, &o);
    ps->plans++;
    ps->plan_us = now_us;
    ps->has_plan_obj = 1;
    ps->plan_obj_mm[0] = t->obj_mm[0];
    ps->plan_obj_mm[1] = t->obj_mm[1];
    mg_task_plan_job_start(t, o.has_path, o.v_limit_mm_s, 1, o.reason, o.time_us);
    plan_slice(t, now_us, in);
}

void mg_task_follow_path(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                         const mg_sighting_t *radial)
{
    const mg_path_method_t *rules = t->rules->path;
    mg_task_path_t *ps = &t->path;
    if (!rules) { /* a method without a path approach: stand */
        t->wheels[0] = t->wheels[1] = 0;
        return;
    }
    if (radial && rules->sighting_usable(t, now_us, in))
        mg_task_see_object(t, now_us, in, mg_task_sighting_position, radial, 1);
    if (ps->has_job) { /* planning in slices */
        if (!plan_slice(t, now_us, in))
            return; /* not done: the old path or a standstill meanwhile */
        if (t->state != MG_APPROACH || !ps->has_follower) {
            t->wheels[0] = t->wheels[1] = 0;
            return;
        }
    }
    int moved = 0;
    if (ps->has_plan_obj) {
        const int64_t dx = (int64_t)t->obj_mm[0] - ps->plan_obj_mm[0];
        const int64_t dy = (int64_t)t->obj_mm[1] - ps->plan_obj_mm[1];
        moved = mg_isqrt(dx * dx + dy * dy) > t->p.replan_shift_mm;
    }
    const int replan = rules->sonar_replan(t, now_us, in, moved);
    if (replan >= 0) {
        if (replan)
            return;
    } else if (!ps->has_follower || moved) {
        if (rules->hold_before_plan(t, now_us, in))
            return;
        if (!ps->has_follower && ps->plan_attempts && !face_object(t, in))
            return; /* no feasible curve from here: face the object in place, then replan */
        plan(t, now_us, in);
        if (ps->has_job)
            return; /* its slices go on in the next steps */
        if (t->state != MG_APPROACH || !ps->has_follower) {
            t->wheels[0] = t->wheels[1] = 0;
            return;
        }
    }
    mg_task_look_at_object(t, in, 1);
    const int32_t dist = obj_dist_mm(t, in);
    const mg_wheel_command_t cmd = follow(t, now_us, in);
    if (cmd.done || dist <= t->p.grasp_r_mm + rules->near_margin_mm
        || object_at_footprint(t, in, rules->object_clear_mm)) {
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "path followed (error ");
        n = mg_task_text_int(why, sizeof why, n, cmd.error_mm);
        n = mg_task_text(why, sizeof why, n, " mm), object ");
        n = mg_task_text_int(why, sizeof why, n, dist);
        mg_task_text(why, sizeof why, n, " mm from the waist");
        rules->path_end(t, now_us, in, why, &cmd.error_mm);
    }
}
