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

void mg_task_reason_as_is(const mg_task_t *t, const char *reason, char *out, size_t cap)
{
    (void)t;
    mg_task_text(out, cap, 0, reason);
}
