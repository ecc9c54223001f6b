/* The host program of one configuration as a caller holds it (program.h). */
#include "program.h"

int32_t mg_program_open(mg_app_t *app, mg_detectors_t *d, mg_detector_t *table,
                        uint64_t *task_state, const mg_config_t *c)
{
    const mg_method_t *m = mg_method_find(c->method);
    if (m == NULL || m->state_bytes > MG_TASK_STATE_BYTES)
        return -1;
    mg_host_config_t cfg;
    mg_host_config_default(&cfg);
    const mg_task_if_t task = mg_method_bind(m, task_state, c);
    const int32_t n_det = mg_detectors_table(d, app, c->f_px, table, MG_MAX_DETECTORS);
    d->u0_px = c->u0_px;
    d->v0_px = c->v0_px;
    mg_app_init(app, &cfg, &task, table, n_det);
    return n_det;
}
