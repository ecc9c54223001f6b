/* The method table (host/task/method.py METHODS): one row per method. */
#include "task_method.h"

#include <string.h>

#include "task_method000.h"
#include "task_method001.h"
#include "task_method002.h"

const mg_task_method_t mg_task_methods[] = {
    {"000", sizeof(mg_state000_t), mg_method000_ms_init, mg_method000_params,
     mg_task_reason_as_is, NULL, mg_method000_look_height_mm, "dual_plus",
     mg_task_sighting_position, 1, mg_method000_adjust_done, mg_method000_adjust_goal_mm,
     mg_method000_adjust_vmax_mmps, MG_ALPHA_DOWN_MRAD, {611, 160, 120}, {1528, 1424, 1552},
     &mg_path000},
    {"001", sizeof(mg_state001_t), mg_method001_ms_init, mg_method001_params,
     mg_task_reason_as_is, NULL, mg_method000_look_height_mm, "dual_plus",
     mg_task_sighting_position, 1, mg_method000_adjust_done, mg_method000_adjust_goal_mm,
     mg_method000_adjust_vmax_mmps, MG_ALPHA_DOWN_MRAD, {611, 160, 120}, {2560, 2560, 3200},
     &mg_path001},
    {"002", sizeof(mg_state002_t), mg_method002_ms_init, mg_method002_params,
     mg_method002_failure_reason, NULL, mg_method002_look_height_mm, "red_cylinder",
     mg_method002_red_cylinder_position, 1, mg_method002_adjust_done_seen,
     mg_method002_adjust_goal_mm, mg_method002_adjust_vmax_mmps, 0, {350, 160, 120},
     {1552, 1424, 1528}, NULL},
};
const int32_t mg_n_task_methods = (int32_t)(sizeof mg_task_methods / sizeof mg_task_methods[0]);

const mg_task_method_t *mg_task_method_find(const char *name)
{
    for (int32_t i = 0; i < mg_n_task_methods; i++)
        if (strcmp(mg_task_methods[i].name, name) == 0)
            return &mg_task_methods[i];
    return NULL;
}

/* host/search.py SearchParams(): 000 section IV's pattern */
static const mg_search_params_t SEARCH_DEFAULTS = {
    .theta2_min_mrad = -2800, .theta2_max_mrad = -2100, .d_theta2_mrad = 60,
    .theta5_min_mrad = -800, .theta5_max_mrad = 800, .d_theta5_mrad = 200, .theta3_mrad = -200,
    .theta4_mrad = 2300, .base_turn_mrad = 1047, .n_coarse = 3,
    .coarse_theta2_mrad = {-2250, -2500, -2750}, .coarse_base_turn_mrad = 1571,
    .dense_cycles = 0, .turns_per_wander = 4, .wander_mm = 1800, .wander_sweep = 1,
    .wander_theta5_mrad = 1400, .stop_cycles = 0, .frames_per_pose = 2,
    .frame_period_us = 66667, .servo_speed_mrad_per_s = 5000};

/* host/control/fuzzy.py FuzzyParams() */
static const mg_fuzzy_params_t FUZZY_DEFAULTS = {1430, 5000, 1000, 150, 4096, 45};

void mg_task_params_default(mg_task_params_t *p)
{
    static const int64_t timeouts_us[MG_N_TASK_STATES] = {
        180000000, 120000000, 60000000, 15000000, 30000000, 16000000, -1, 5000000, -1};
    memset(p, 0, sizeof *p);
    memcpy(p->timeouts_us, timeouts_us, sizeof timeouts_us);
    p->servo_speed_mrad_per_s = 3000;
    p->settle_margin_us = 300000;
    p->frame_latency_us = 50000;
    p->lost_timeout_us = 1500000;
    p->grasp_r_mm = 110;
    p->grasp_r_tol_mm = 20;
    p->adjust_vmax_mmps = 80;
    p->blind_approach_mm = 1000;
    p->blind_keep_mm = 700;
    p->blind_approach_us = 8000000;
    p->slow_mmps = 60;
    p->mount_forward_mm = 100;
    p->h_shoulder_mm = 200;
    p->object_top_mm = 100;
    p->grasp_height_mm = 80;
    p->t_d_px = 45;
    p->cylinder_near_px = 12;
    p->cross_near_px = 75;
    p->bearing_tol_mrad = 60;
    p->adjust_theta3_mrad = -1000;
    p->adjust_theta4_mrad = 1571;
    p->blind_finish_mm = 80;
    p->approach_standoff_mm = 400;
    p->replan_shift_mm = 150;
    p->max_plan_attempts = 3;
    p->direct_max_mm = 1200;
    p->turn_wheel_mmps = 80;
    p->replan_period_us = 300000;
    p->sonar_sweep_us = 200000;
    p->search = SEARCH_DEFAULTS;
    p->posture_step_mrad = 20;
    /* eq. (10)'s gains of 000 section IV: 1, 0, 0 */
    p->posture.k_theta_q12[0] = 4096;
    p->posture.margin_mode = MG_MARGIN_PRINTED;
    p->fuzzy = FUZZY_DEFAULTS;
}

void mg_task_reason_as_is(const mg_task_t *t, const char *reason, char *out, size_t cap)
{
    (void)t;
    mg_task_text(out, cap, 0, reason);
}
