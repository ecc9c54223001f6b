/* The table of the C host's methods (host/task's method table in Python). */
#include "task.h"

#include <string.h>

const mg_method_t mg_methods[] = {
    {"idle", sizeof(mg_task_idle_t), mg_task_idle_init, mg_task_idle_step, mg_task_idle_needed,
     NULL},
};
const int32_t mg_n_methods = (int32_t)(sizeof mg_methods / sizeof mg_methods[0]);

const mg_method_t *mg_method_find(const char *name)
{
    for (int32_t i = 0; i < mg_n_methods; i++)
        if (strcmp(mg_methods[i].method, name) == 0)
            return &mg_methods[i];
    return NULL;
}

mg_task_if_t mg_method_bind(const mg_method_t *m, void *state)
{
    m->init(state);
    const mg_task_if_t t = {state, m->step, m->detectors_needed, m->fallback_of};
    return t;
}
