/* The method table (host/task/method.py METHODS): one row per method. */
#include "task_method.h"

#include <string.h>

#include "sonar_guard.h"
#include "task_method000.h"
#include "task_method001.h"
#include "task_method002.h"

/* the hooks 001 takes from 000 (Method001 is a Method000): 000's vision, APPROACH's path,
 * ADJUST and grasp (but the entry of PRECISE_GRASP, each row's own) */
#define HOOKS_000                                                                          \
    .failure_reason = mg_task_reason_as_is, .look_height_mm = mg_method000_look_height_mm,  \
    .adjust_detector = "dual_plus", .adjust_position = mg_task_plus_position,               \
    .adjust_is_object = 1, .adjust_done = mg_method000_adjust_done,                         \
    .adjust_goal_mm = mg_method000_adjust_goal_mm,                                          \
    .adjust_vmax_mmps = mg_method000_adjust_vmax_mmps,                                      \
    .adjust_result = mg_method000_plus_result, .radial_result = mg_method000_radial_result, \
    .search_sighting = mg_method000_search_sighting, .found = mg_method000_found,           \
    .found_why = mg_method000_found_why, .keeps_sightings = 1,                              \
    .enter_approach = mg_method000_enter_approach_state,                                    \
    .approach = mg_method000_approach_state,                                                \
    .object_detectors = "dual_plus, radial_symbol", .rough_target = mg_method000_rough_target, \
    .grasp_ik = mg_method000_grasp_ik, .lowers_hover = 1,                                   \
    .spoke_reading = mg_method000_spoke_reading, .held_in_view = mg_method000_held_in_view, \
    .n_checks = 2,                                                                          \
    .checks = {{"dual_plus", mg_method000_plus_result, mg_task_plus_position, 1},           \
               {"radial_symbol", mg_method000_radial_check, mg_task_sighting_position, 1}}, \
    .grasp_alpha_mrad = MG_ALPHA_DOWN_MRAD, .camera = {611, 160, 120},                      \
    .frame_of = mg_method000_frame_of
/* the detectors of 000's states after SEARCH (method000.py detectors) */
#define DETECTORS_000                                                                      \
    [MG_APPROACH] = 1u << MG_DET_RADIAL_SYMBOL,                                             \
    [MG_ADJUST] = 1u << MG_DET_DUAL_PLUS | 1u << MG_DET_RADIAL_SYMBOL,                      \
    [MG_PRECISE_GRASP] = 1u << MG_DET_SPOKE,                                                \
    [MG_LIFT] = 1u << MG_DET_DUAL_PLUS | 1u << MG_DET_RADIAL_SYMBOL | 1u << MG_DET_HELD_FILL

const mg_task_method_t mg_task_methods[] = {
    {.name = "000",
     .ms_bytes = sizeof(mg_state000_t),
     .ms_init = mg_method000_ms_init,
     .params = mg_method000_params,
     HOOKS_000,
     .enter_precise = mg_method000_enter_precise,
     .guard_wheels = mg_sonar_guard_step,
     .lost_search = mg_method000_lost_search,
     .grasp_lost = mg_method000_grasp_lost,
     .plus_on_top = 1,
     .adjust_keeps_posture = 1,
     .search_back_off = mg_method000_search_back_off,
     .search_cut_look = mg_method000_search_cut_look,
     /* SEARCH: the cut symbol is looked for when the symbol is not read */
     .detectors = {[MG_SEARCH] = 1u << MG_DET_RADIAL_SYMBOL | 1u << MG_DET_RADIAL_CUT,
                   DETECTORS_000},
     .n_fallbacks = 2,
     .fallbacks = {{MG_ADJUST, MG_DET_RADIAL_SYMBOL, MG_DET_DUAL_PLUS},
                   {MG_SEARCH, MG_DET_RADIAL_CUT, MG_DET_RADIAL_SYMBOL}},
     .geom = {1528, 1424, 1552},
     .path = &mg_path000},
    {.name = "001",
     .ms_bytes = sizeof(mg_state001_t),
     .ms_init = mg_method001_ms_init,
     .params = mg_method001_params,
     HOOKS_000,
     .guard_wheels = mg_method001_guard_wheels,
     .plus_on_top = 1,
     /* the look back at the top from 140-200 mm before the grasp (method001.py sight_views),
      * the grasp by eq. (11) from the grasp circle when it confirms the object */
     .n_sight_views = 6,
     .sight_views = {{180, 900}, {160, 1000}, {180, 1000}, {200, 800}, {160, 1100}, {140, 1100}},
     .sight_result = mg_method000_plus_result,
     .sight_position = mg_task_plus_position,
     .look_decides = mg_method001_look_decides,
     .enter_precise = mg_method001_enter_precise,
     /* SEARCH: the cut symbol is looked for when the symbol is not read, as 000's */
     .search_back_off = mg_method001_search_back_off,
     .detectors = {[MG_SEARCH] = 1u << MG_DET_RADIAL_SYMBOL | 1u << MG_DET_RADIAL_CUT,
                   DETECTORS_000, [MG_ROUGH_GRASP] = 1u << MG_DET_DUAL_PLUS},
     .n_fallbacks = 2,
     .fallbacks = {{MG_ADJUST, MG_DET_RADIAL_SYMBOL, MG_DET_DUAL_PLUS},
                   {MG_SEARCH, MG_DET_RADIAL_CUT, MG_DET_RADIAL_SYMBOL}},
     .geom = {2560, 2560, 3200},
     .path = &mg_path001},
    {.name = "002",
     .ms_bytes = sizeof(mg_state002_t),
     .ms_init = mg_method002_ms_init,
     .params = mg_method002_params,
     .failure_reason = mg_method002_failure_reason,
     .object_cue_seen = mg_method002_object_cue_seen,
     .guard_wheels = mg_sonar_guard_step,
     .look_height_mm = mg_method002_look_height_mm,
     .adjust_detector = "red_cylinder",
     .adjust_position = mg_method002_red_cylinder_position,
     .adjust_is_object = 1,
     .adjust_done = mg_method002_adjust_done_seen,
     .adjust_goal_mm = mg_method002_adjust_goal_mm,
     .adjust_vmax_mmps = mg_method002_adjust_vmax_mmps,
     .adjust_result = mg_method002_red_cylinder_result,
     .search_sighting = mg_method002_search_sighting,
     .found = mg_method002_found_seen,
     .found_why = mg_method002_found_why,
     .search_gives_up = mg_method002_search_gives_up,
     .lost_search = NULL,
     .keeps_sightings = 0,
     .enter_approach = mg_method002_enter_approach_state,
     .approach = mg_method002_approach_state,
     .object_detectors = "red_cylinder",
     .grasp_reach_mm = mg_method002_grasp_reach_mm,
     .rough_target = mg_method002_rough_target,
     .grasp_ik = mg_method002_grasp_ik,
     .lowers_hover = 0,
     .enter_precise = mg_method002_enter_precise,
     .held_view_pose = mg_method002_held_view_pose,
     .held_in_view = mg_method002_held_in_view,
     .n_checks = 1,
     .checks = {{"red_cylinder", mg_method002_red_cylinder_result,
                 mg_method002_red_cylinder_position, 1}},
     .grasp_alpha_mrad = 0,
     .detectors = {[MG_SEARCH] = 1u << MG_DET_DOUBLE_CROSS | 1u << MG_DET_RED_ROI,
                   [MG_APPROACH] = 1u << MG_DET_DOUBLE_CROSS | 1u << MG_DET_RED_CYLINDER
                                   | 1u << MG_DET_RED_ROI,
                   [MG_ADJUST] = 1u << MG_DET_RED_CYLINDER,
                   [MG_LIFT] = 1u << MG_DET_RED_CYLINDER | 1u << MG_DET_HELD_FILL},
     .n_fallbacks = 0,
     .frame_of = mg_method002_frame_of,
     .camera = {350, 160, 120},
     .geom = {1552, 1424, 1528}},
};
const char *const mg_detector_names[MG_N_DETECTORS] = {
    "dual_plus", "radial_symbol", "spoke", "double_cross", "red_cylinder", "red_roi",
    "held_fill", "radial_cut"};

const int32_t mg_n_task_methods = (int32_t)(sizeof mg_task_methods / sizeof mg_task_methods[0]);

const mg_task_method_t *mg_task_method_find(const char *name)
{
    for (int32_t i = 0; i < mg_n_task_methods; i++)
        if (strcmp(mg_task_methods[i].name, name) == 0)
            return &mg_task_methods[i];
    return NULL;
}

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
    p->search_turn_wheel_mmps = 0;
    p->replan_period_us = 300000;
    p->sonar_sweep_us = 200000;
    mg_search_params_default(&p->search); /* host/search.py SearchParams() */
    p->confirm_us = 700000;
    p->lost_hold_us = 500000;
    p->max_lost = 5;
    p->wander_mmps = 200;
    p->wander_clear_mm = 500;
    p->sighting_match_mm = 200;
    p->sighting_approach_mm = 0;
    p->sighting_approaches = 2;
    p->sonar_offset_mm = 170;
    p->r_r_mm = 200;
    p->sonar_a_g_mrad = 1050;
    p->detour_mm = 500;
    p->detour_clear_mm = 900;
    p->max_detours = 6;
    p->hover_mm = 110;
    p->lift_mm = 60;
    p->pregrasp_back_mm = 50;
    p->grasp_close_timeout_us = 2000000;
    p->w_min_px = 20; /* 000 section IV */
    p->w_max_px = 40;
    p->spoke_wait_us = 3000000;
    p->precise_max_steps = 30;
    p->precise_align_ch = 1;
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

uint32_t mg_task_detectors_needed(const mg_task_t *t)
{
    return t->state >= 0 && t->state < MG_N_TASK_STATES ? t->rules->detectors[t->state] : 0;
}

int32_t mg_task_detector_fallback(const mg_task_t *t, int32_t det)
{
    for (int32_t i = 0; i < t->rules->n_fallbacks && i < MG_MAX_FALLBACKS; i++)
        if (t->rules->fallbacks[i].state == t->state && t->rules->fallbacks[i].detector == det)
            return t->rules->fallbacks[i].primary;
    return -1;
}

/* every method's frame fits the task's buffer */
typedef char mg_frame002_fits[sizeof(mg_frame002_t) <= MG_FRAME_BYTES ? 1 : -1];
typedef char mg_frame000_fits[sizeof(mg_frame000_t) <= MG_FRAME_BYTES ? 1 : -1];
