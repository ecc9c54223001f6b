/* The C host program in the simulator's process (inproc.h): main.c's start-up, then
 * lockstep_driver.c's quantum on the GRANTs the caller hands over. */
#include "inproc.h"

#include <string.h>

#include "program.h"

int mg_inproc_open(mg_inproc_t *h, const char *config, size_t n, char *why, size_t cap)
{
    memset(h, 0, sizeof *h);
    mg_config_t c;
    if (mg_config_parse(config, n, &c, why, cap) != 0)
        return -1;
    if (mg_program_open(&h->app, &h->detectors, h->table, h->task_state, &c) < 0) {
        size_t k = mg_task_text(why, cap, 0, "method ");
        k = mg_task_text(why, cap, k, c.method);
        mg_task_text(why, cap, k, " is not in the C host yet");
        return -1;
    }
    mg_lockstep_init(&h->driver, &h->app);
    return 0;
}

size_t mg_inproc_serve(mg_inproc_t *h, const uint8_t *msg, size_t n, const uint8_t *uart,
                       size_t uart_n, uint8_t *done, size_t cap, uint8_t *out, size_t out_cap,
                       size_t *out_len)
{
    int32_t kind;
    uint32_t meta_len, blob_len;
    *out_len = 0;
    if (n < MG_LS_HEADER_BYTES || mg_ls_decode_header(msg, &kind, &meta_len, &blob_len) != 0
        || (uint64_t)MG_LS_HEADER_BYTES + meta_len + blob_len != n)
        return 0;
    const uint8_t *meta = msg + MG_LS_HEADER_BYTES, *blob = meta + meta_len;
    mg_ls_grant_t *g = &h->grant;
    if (mg_ls_decode_grant(kind, meta, meta_len, blob_len, g) != 0)
        return 0;
    size_t announced = 0;
    for (int32_t i = 0; i < g->n_uart; i++)
        announced += g->uart[i].nbytes;
    if (announced != uart_n)
        return 0;
    const uint8_t *pixels[MG_LS_MAX_FRAMES];
    for (int32_t i = 0; i < g->n_frames; i++) {
        if (g->frames[i].shared)
            return 0; /* in process the frames travel in the blob */
        pixels[i] = blob + g->frames[i].offset;
    }
    const size_t len = mg_lockstep_serve(&h->driver, g, uart, pixels, done, cap);
    if (len == 0 || h->driver.out_len > out_cap)
        return 0;
    memcpy(out, h->driver.out, h->driver.out_len);
    *out_len = h->driver.out_len;
    return len;
}

size_t mg_inproc_bye(const mg_inproc_t *h, uint8_t *out, size_t cap)
{
    char stats[MG_APP_STATS_BYTES];
    const size_t len = mg_app_stats_json(&h->app, stats, sizeof stats);
    return mg_ls_encode_bye(out, cap, len ? stats : "{}", len ? len : 2);
}
