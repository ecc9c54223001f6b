/* The host program as the calibration replays it (calib_program.h). */
#include "calib_program.h"

#include <string.h>

int32_t mg_calib_program_open(mg_calib_program_t *p, const char *config, int32_t n)
{
    static char why[MG_CONFIG_WHY]; /* the refusal's reason: the caller has the Python's */
    memset(p, 0, sizeof *p);
    mg_config_t c;
    if (n < 0 || mg_config_parse(config, (size_t)n, &c, why, sizeof why) != 0)
        return -1;
    return mg_program_open(&p->app, &p->detectors, p->table, p->task_state, &c);
}

const mg_detector_t *mg_calib_table(const mg_calib_program_t *p)
{
    return p->table;
}

int64_t mg_calib_stage_us(const mg_app_t *app, const char *name)
{
    int64_t us = 0;
    for (int32_t i = 0; i < app->n_stages; i++)
        if (name == NULL || strcmp(app->stages[i].name, name) == 0)
            us += app->stages[i].total_us;
    return us;
}

int32_t mg_calib_take_output(mg_app_t *app, int64_t before_us, uint8_t *out, int32_t cap)
{
    static mg_wire_chunk_t chunks[MG_OUTBOX_CHUNKS];
    const int32_t n = mg_link_take_output(&app->link, before_us, chunks, MG_OUTBOX_CHUNKS);
    int32_t len = 0;
    for (int32_t i = 0; i < n; i++) {
        if (len + (int32_t)chunks[i].len > cap)
            return -1;
        memcpy(out + len, chunks[i].wire, chunks[i].len);
        len += (int32_t)chunks[i].len;
    }
    return len;
}
