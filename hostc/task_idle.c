/* The idle method: no paper's task, the host program around it only (task.h). */
#include "task.h"

void mg_task_idle_init(void *state, const mg_config_t *cfg)
{
    (void)cfg;
    ((mg_task_idle_t *)state)->steps = 0;
}

void mg_task_idle_step(void *state, mg_app_t *app, int64_t now_us,
                       const mg_detection_t *detections, const int32_t *present,
                       mg_task_output_t *out)
{
    (void)app, (void)now_us, (void)detections, (void)present;
    ((mg_task_idle_t *)state)->steps++;
    out->state = "INIT";
}

uint32_t mg_task_idle_needed(void *state)
{
    (void)state;
    return 0;
}
