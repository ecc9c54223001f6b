/* The method table (host/task/method.py METHODS): one row per method. */
#include "task_method.h"

#include <string.h>

#include "sonar_guard.h"
#include "task_method002.h"

const mg_task_method_t mg_task_methods[] = {
    {.name = "002",
     .ms_bytes = sizeof(mg_state002_t),
     .ms_init = mg_method002_ms_init,
     .params = mg_method002_params,
     .failure_reason = mg_method002_failure_reason,
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
     .check_detector = "red_cylinder",
     .check_result = mg_method002_red_cylinder_result,
     .check_position = mg_method002_red_cylinder_position,
     .check_is_object = 1,
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
    "held_fill"};

const int32_t mg_n_task_methods = (int32_t)(sizeof mg_task_methods / sizeof mg_task_methods[0]);

const mg_task_method_t *mg_task_method_find(const char *name)
{
    for (int32_t i = 0; i < mg_n_task_methods; i++)
        if (strcmp(mg_task_methods[i].name, name) == 0)
            return &mg_task_methods[i];
    return NULL;
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
