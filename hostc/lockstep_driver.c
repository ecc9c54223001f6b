/* The lockstep driver (drivers/lockstep.py LockstepClient.serve, serve_stream). */
#include "lockstep_driver.h"

#include <string.h>

#include "json.h"
#include "sys.h"

void mg_lockstep_init(mg_lockstep_t *ls, mg_app_t *app)
{
    memset(ls, 0, sizeof *ls);
    ls->app = app;
}

size_t mg_lockstep_serve(mg_lockstep_t *ls, const mg_ls_grant_t *g, const uint8_t *uart,
                         const uint8_t *const *pixels, uint8_t *done, size_t cap)
{
    mg_app_t *app = ls->app;
    ls->clock_us = g->start_us;
    size_t offset = 0;
    for (int32_t i = 0; i < g->n_uart; i++) {
        mg_app_on_uart(app, uart + offset, g->uart[i].nbytes, g->uart[i].t_us);
        offset += g->uart[i].nbytes;
    }
    for (int32_t i = 0; i < g->n_frames; i++) {
        const mg_ls_frame_t *f = &g->frames[i];
        const uint8_t *rgb = f->nbytes > 0 && pixels != NULL ? pixels[i] : NULL;
        mg_app_on_frame(app, f->seq, f->capture_us, f->arrival_us, rgb, (int32_t)f->width,
                        (int32_t)f->height);
    }
    mg_app_advance_to(app, g->until_us);
    mg_wire_chunk_t chunks[MG_OUTBOX_CHUNKS];
    mg_ls_chunk_t writes[MG_OUTBOX_CHUNKS];
    const int32_t n = mg_link_take_output(&app->link, g->until_us, chunks, MG_OUTBOX_CHUNKS);
    ls->out_len = 0;
    for (int32_t i = 0; i < n; i++) {
        if (ls->out_len + chunks[i].len > sizeof ls->out)
            return 0;
        memcpy(ls->out + ls->out_len, chunks[i].wire, chunks[i].len);
        ls->out_len += chunks[i].len;
        writes[i].t_us = chunks[i].at_us;
        writes[i].nbytes = chunks[i].len;
    }
    ls->clock_us = g->until_us;
    int64_t index[MG_LOAD_WINDOWS_KEPT], micro[MG_LOAD_WINDOWS_KEPT];
    int32_t n_windows = 0;
    const int64_t w = app->config.load_window_us;
    if (g->until_us / w > ls->loads_sent) { /* a window may have finished */
        n_windows = mg_app_load_windows(app, ls->loads_sent, index, micro,
                                        MG_LOAD_WINDOWS_KEPT);
        for (int32_t i = 0; i < n_windows; i++)
            if (index[i] + 1 > ls->loads_sent)
                ls->loads_sent = index[i] + 1;
    }
    size_t events_len;
    const int32_t n_events = mg_app_take_events(app, ls->events, sizeof ls->events,
                                                &events_len);
    const mg_ls_done_t d = {g->until_us, n, writes, n_events, ls->events, events_len, w,
                            n_windows, index, micro, app->state, app->finished,
                            mg_app_wants_frames(app), mg_app_quiet_until_us(app)};
    return mg_ls_encode_done(done, cap, &d);
}

/* ---- the run over the socket ---- */

static int read_exact(int fd, uint8_t *buf, size_t n)
{
    for (size_t got = 0; got < n;) {
        const long r = sys_read(fd, buf + got, n - got);
        if (r <= 0)
            return r < 0 ? (int)r : -1;
        got += (size_t)r;
    }
    return 0;
}

static int write_all(int fd, const uint8_t *buf, size_t n)
{
    for (size_t put = 0; put < n;) {
        const long r = sys_write(fd, buf + put, n - put);
        if (r <= 0)
            return r < 0 ? (int)r : -1;
        put += (size_t)r;
    }
    return 0;
}

/* the pixels a shared frame names. Its ring file is mapped once, read-only, when a GRANT first
 * names it: the rig removes the file's name once the host has answered that GRANT
 * (cosim/frame_ring.py), so it cannot be opened again. The ring's size is not in the GRANT:
 * MG_LS_RING_MAP bytes of address space are mapped, of which only the slots the GRANTs name
 * (inside the file) are ever read. */
static const uint8_t *ring_pixels(mg_lockstep_t *ls, const mg_ls_frame_t *f)
{
    mg_ls_ring_t *r = NULL;
    for (int32_t i = 0; i < ls->n_rings; i++)
        if (strcmp(ls->rings[i].path, f->path) == 0)
            r = &ls->rings[i];
    if (r == NULL) {
        if (ls->n_rings >= MG_LS_RINGS)
            return NULL;
        const int fd = sys_open(f->path, SYS_O_RDONLY, 0);
        if (fd < 0)
            return NULL;
        const void *p = sys_mmap_shared(fd, MG_LS_RING_MAP, 0);
        sys_close(fd);
        if (p == NULL)
            return NULL;
        r = &ls->rings[ls->n_rings++];
        memcpy(r->path, f->path, sizeof r->path);
        r->base = p;
        r->len = MG_LS_RING_MAP;
    }
    if ((uint64_t)f->shared_offset + (uint64_t)f->nbytes > r->len)
        return NULL;
    return r->base + f->shared_offset;
}

/* The buffers of one message: the metadata, the blob (frames sent inside the GRANT) and the
 * serial bytes of a grant. Static: no allocation after start-up, and too large for a stack. */
static uint8_t meta_buf[1 << 16];
static uint8_t blob_buf[8 * 320 * 240 * 3];
static uint8_t uart_buf[1 << 16];
static uint8_t done_buf[MG_LS_DONE_BYTES];
static mg_ls_grant_t grant;

int mg_lockstep_run(mg_lockstep_t *ls, int sock_fd, int serial_fd, const char **why)
{
    size_t n = mg_ls_encode_hello(done_buf, sizeof done_buf, "mobigrasp-host-c");
    int err = write_all(sock_fd, done_buf, n);
    if (err)
        return *why = "writing HELLO", err;
    for (;;) {
        uint8_t head[MG_LS_HEADER_BYTES];
        int32_t kind;
        uint32_t meta_len, blob_len;
        if ((err = read_exact(sock_fd, head, sizeof head)) != 0)
            return *why = "the rig closed the channel", err;
        if (mg_ls_decode_header(head, &kind, &meta_len, &blob_len) != 0
            || meta_len > sizeof meta_buf || blob_len > sizeof blob_buf)
            return *why = "a malformed message header", -1;
        if ((err = read_exact(sock_fd, meta_buf, meta_len)) != 0
            || (err = read_exact(sock_fd, blob_buf, blob_len)) != 0)
            return *why = "the rig closed the channel mid-message", err;
        if (kind == MG_LS_END) {
            mg_ls_end_t end;
            if (mg_ls_decode_end(meta_buf, meta_len, &end) != 0)
                return *why = "a malformed END", -1;
            static char stats[MG_APP_STATS_BYTES];
            const size_t len = mg_app_stats_json(ls->app, stats, sizeof stats);
            n = mg_ls_encode_bye(done_buf, sizeof done_buf, len ? stats : "{}", len ? len : 2);
            err = write_all(sock_fd, done_buf, n);
            return *why = "END", err;
        }
        if (mg_ls_decode_grant(kind, meta_buf, meta_len, blob_len, &grant) != 0)
            return *why = "a malformed GRANT", -1;
        size_t uart_n = 0;
        for (int32_t i = 0; i < grant.n_uart; i++)
            uart_n += grant.uart[i].nbytes;
        if (uart_n > sizeof uart_buf)
            return *why = "a GRANT with more UART bytes than the buffer", -1;
        if ((err = read_exact(serial_fd, uart_buf, uart_n)) != 0)
            return *why = "the serial port closed", err;
        const uint8_t *pixels[MG_LS_MAX_FRAMES];
        for (int32_t i = 0; i < grant.n_frames; i++) {
            const mg_ls_frame_t *f = &grant.frames[i];
            pixels[i] = f->shared ? ring_pixels(ls, f) : blob_buf + f->offset;
            if (f->nbytes > 0 && pixels[i] == NULL)
                return *why = "a shared frame that cannot be mapped", -1;
        }
        n = mg_lockstep_serve(ls, &grant, uart_buf, pixels, done_buf, sizeof done_buf);
        if (n == 0)
            return *why = "a DONE larger than its buffer", -1;
        if (ls->out_len && (err = write_all(serial_fd, ls->out, ls->out_len)) != 0)
            return *why = "writing the serial port", err;
        if ((err = write_all(sock_fd, done_buf, n)) != 0)
            return *why = "writing DONE", err;
    }
}
