/* The lockstep channel's codec on the host's side (cosim/lockstep.py). */
#include "lockstep.h"

#include <string.h>

#include "json.h"

static const uint8_t magic[4] = {'M', 'G', 'L', 'S'};

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static int64_t get64(const uint8_t *p)
{
    return (int64_t)((uint64_t)get32(p) | (uint64_t)get32(p + 4) << 32);
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void put64(uint8_t *p, int64_t v)
{
    put32(p, (uint32_t)(uint64_t)v);
    put32(p + 4, (uint32_t)((uint64_t)v >> 32));
}

static void header(uint8_t *out, int32_t kind, uint32_t meta_len, uint32_t blob_len)
{
    memcpy(out, magic, 4);
    out[4] = (uint8_t)kind;
    put32(out + 5, meta_len);
    put32(out + 9, blob_len);
}

int mg_ls_decode_header(const uint8_t *h, int32_t *kind, uint32_t *meta_len,
                        uint32_t *blob_len)
{
    if (memcmp(h, magic, 4) != 0 || h[4] < MG_LS_HELLO || h[4] > MG_LS_DONE_COMPACT)
        return -1;
    *kind = h[4];
    *meta_len = get32(h + 5);
    *blob_len = get32(h + 9);
    return (*meta_len > MG_LS_MAX_META || *blob_len > MG_LS_MAX_BLOB) ? -1 : 0;
}

/* chunk times non-negative and never going back, as _chunks / _compact_chunks check */
static int chunks_ordered(const mg_ls_chunk_t *c, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        if (c[i].t_us < 0 || (i > 0 && c[i].t_us < c[i - 1].t_us))
            return 0;
    return 1;
}

static int decode_compact_grant(const uint8_t *b, uint32_t n, mg_ls_grant_t *g)
{
    if (n < 20)
        return -1;
    g->start_us = get64(b);
    g->until_us = get64(b + 8);
    const uint32_t k = get32(b + 16);
    if (g->start_us < 0 || g->until_us < g->start_us || k > MG_LS_MAX_CHUNKS
        || n != 20 + 12 * k)
        return -1;
    g->n_uart = (int32_t)k;
    for (uint32_t i = 0; i < k; i++) {
        g->uart[i].t_us = get64(b + 20 + 12 * i);
        g->uart[i].nbytes = get32(b + 28 + 12 * i);
    }
    g->n_frames = 0;
    return chunks_ordered(g->uart, g->n_uart) ? 0 : -1;
}

static int read_nonneg(mg_json_in_t *in, int64_t *out)
{
    return mg_json_read_int(in, out) && *out >= 0;
}

static int read_chunks(mg_json_in_t *in, mg_ls_chunk_t *c, int32_t *n)
{
    int first = 1, r;
    *n = 0;
    if (!mg_json_begin_array_in(in))
        return 0;
    while ((r = mg_json_next_element(in, &first)) == 1) {
        int f2 = 1;
        int64_t t, k;
        if (*n >= MG_LS_MAX_CHUNKS || !mg_json_begin_array_in(in)
            || mg_json_next_element(in, &f2) != 1 || !read_nonneg(in, &t)
            || mg_json_next_element(in, &f2) != 1 || !read_nonneg(in, &k) || k > UINT32_MAX
            || mg_json_next_element(in, &f2) != 0)
            return 0;
        c[*n].t_us = t;
        c[(*n)++].nbytes = (uint32_t)k;
    }
    return r == 0 && chunks_ordered(c, *n);
}

static int read_shared(mg_json_in_t *in, mg_ls_frame_t *f)
{
    int first = 1, r, have = 0;
    char key[16];
    int64_t nbytes = -1;
    if (!mg_json_begin_object_in(in))
        return 0;
    while ((r = mg_json_next_member(in, &first, key, sizeof key)) == 1) {
        if (strcmp(key, "path") == 0)
            have |= mg_json_read_string(in, f->path, sizeof f->path) ? 1 : 8;
        else if (strcmp(key, "offset") == 0)
            have |= read_nonneg(in, &f->shared_offset) ? 2 : 8;
        else if (strcmp(key, "nbytes") == 0)
            have |= read_nonneg(in, &nbytes) ? 4 : 8;
        else if (!mg_json_skip_value(in))
            return 0;
    }
    f->shared = 1;
    return r == 0 && have == 7 && nbytes == f->nbytes;
}

static int read_frame(mg_json_in_t *in, mg_ls_frame_t *f, uint32_t blob_len)
{
    static const char *const names[8] = {"seq", "capture_us", "arrival_us", "width", "height",
                                         "channels", "offset", "nbytes"};
    int64_t *fields[8] = {&f->seq, &f->capture_us, &f->arrival_us, &f->width, &f->height,
                          &f->channels, &f->offset, &f->nbytes};
    int first = 1, r, have = 0, shared_at = 0;
    char key[16];
    mg_json_in_t shared_in;
    memset(f, 0, sizeof *f);
    if (!mg_json_begin_object_in(in))
        return 0;
    while ((r = mg_json_next_member(in, &first, key, sizeof key)) == 1) {
        int known = 0;
        for (int i = 0; i < 8; i++)
            if (strcmp(key, names[i]) == 0) {
                if (!read_nonneg(in, fields[i]))
                    return 0;
                have |= 1 << i;
                known = 1;
            }
        if (!known && strcmp(key, "shared") == 0) { /* read once nbytes is known */
            shared_in = *in;
            shared_at = 1;
        }
        if (!known && !mg_json_skip_value(in))
            return 0;
    }
    if (r != 0 || have != 0xFF)
        return 0;
    /* the pixels where the frame says (the blob, or the ring), as many as width x height x
     * channels (FrameBlob), arriving after their capture */
    const int where = shared_at ? read_shared(&shared_in, f)
                                : f->offset + f->nbytes <= (int64_t)blob_len;
    return where && f->width <= 65535 && f->height <= 65535 && f->channels <= 255
           && f->nbytes == f->width * f->height * f->channels && f->arrival_us >= f->capture_us;
}

static int decode_json_grant(const uint8_t *meta, uint32_t n, uint32_t blob_len,
                             mg_ls_grant_t *g)
{
    mg_json_in_t in;
    int first = 1, r, have = 0;
    char key[16];
    mg_json_in_init(&in, (const char *)meta, n);
    g->n_uart = g->n_frames = 0;
    if (!mg_json_utf8_valid((const char *)meta, n) || !mg_json_begin_object_in(&in))
        return -1;
    while ((r = mg_json_next_member(&in, &first, key, sizeof key)) == 1) {
        int ok;
        if (strcmp(key, "start_us") == 0)
            ok = read_nonneg(&in, &g->start_us), have |= 1;
        else if (strcmp(key, "until_us") == 0)
            ok = read_nonneg(&in, &g->until_us), have |= 2;
        else if (strcmp(key, "uart") == 0)
            ok = read_chunks(&in, g->uart, &g->n_uart);
        else if (strcmp(key, "frames") == 0) {
            int f1 = 1, rf;
            ok = mg_json_begin_array_in(&in);
            while (ok && (rf = mg_json_next_element(&in, &f1)) == 1)
                ok = g->n_frames < MG_LS_MAX_FRAMES
                     && read_frame(&in, &g->frames[g->n_frames++], blob_len);
            ok = ok && rf == 0;
        } else
            ok = mg_json_skip_value(&in);
        if (!ok)
            return -1;
    }
    return (r == 0 && have == 3 && g->until_us >= g->start_us && mg_json_at_end(&in)) ? 0 : -1;
}

int mg_ls_decode_grant(int32_t kind, const uint8_t *meta, uint32_t n, uint32_t blob_len,
                       mg_ls_grant_t *g)
{
    if (kind == MG_LS_GRANT_COMPACT)
        return blob_len == 0 ? decode_compact_grant(meta, n, g) : -1;
    if (kind == MG_LS_GRANT)
        return decode_json_grant(meta, n, blob_len, g);
    return -1;
}

int mg_ls_decode_end(const uint8_t *meta, uint32_t n, mg_ls_end_t *e)
{
    mg_json_in_t in;
    int first = 1, r, have = 0;
    char key[16];
    mg_json_in_init(&in, (const char *)meta, n);
    e->reason[0] = 0;
    if (!mg_json_utf8_valid((const char *)meta, n) || !mg_json_begin_object_in(&in))
        return -1;
    while ((r = mg_json_next_member(&in, &first, key, sizeof key)) == 1) {
        int ok;
        if (strcmp(key, "at_us") == 0)
            ok = read_nonneg(&in, &e->at_us), have = 1;
        else if (strcmp(key, "reason") == 0)
            ok = mg_json_read_string(&in, e->reason, sizeof e->reason);
        else
            ok = mg_json_skip_value(&in);
        if (!ok)
            return -1;
    }
    return r == 0 && have ? 0 : -1;
}

/* the JSON message of kind around the metadata the writer filled */
static size_t finish_json(uint8_t *out, int32_t kind, const mg_json_t *j)
{
    if (j->overflow)
        return 0;
    header(out, kind, (uint32_t)j->len, 0);
    return MG_LS_HEADER_BYTES + j->len;
}

size_t mg_ls_encode_hello(uint8_t *out, size_t cap, const char *host_id)
{
    mg_json_t j;
    if (cap < MG_LS_HEADER_BYTES)
        return 0;
    mg_json_init(&j, (char *)out + MG_LS_HEADER_BYTES, cap - MG_LS_HEADER_BYTES);
    mg_json_begin_object(&j);
    mg_json_key(&j, "host_id");
    mg_json_string(&j, host_id, strlen(host_id));
    mg_json_key(&j, "version");
    mg_json_int(&j, MG_LS_VERSION);
    mg_json_end_object(&j);
    return finish_json(out, MG_LS_HELLO, &j);
}

size_t mg_ls_encode_bye(uint8_t *out, size_t cap, const char *stats_json, size_t n)
{
    mg_json_t j;
    if (cap < MG_LS_HEADER_BYTES)
        return 0;
    mg_json_init(&j, (char *)out + MG_LS_HEADER_BYTES, cap - MG_LS_HEADER_BYTES);
    mg_json_begin_object(&j);
    mg_json_key(&j, "stats");
    mg_json_raw(&j, stats_json, n);
    mg_json_end_object(&j);
    return finish_json(out, MG_LS_BYE, &j);
}

static size_t encode_done_compact(uint8_t *out, size_t cap, const mg_ls_done_t *d, size_t name)
{
    const size_t body = 31 + name + 12 * (size_t)d->n_writes;
    if (cap < MG_LS_HEADER_BYTES + body)
        return 0;
    header(out, MG_LS_DONE_COMPACT, (uint32_t)body, 0);
    uint8_t *b = out + MG_LS_HEADER_BYTES;
    put64(b, d->until_us);
    put64(b + 8, d->quiet_until);
    put64(b + 16, d->window_us);
    b[24] = (uint8_t)(d->finished != 0);
    b[25] = (uint8_t)(d->camera != 0);
    b[26] = (uint8_t)name;
    put32(b + 27, (uint32_t)d->n_writes);
    memcpy(b + 31, d->state, name);
    for (int32_t i = 0; i < d->n_writes; i++) {
        put64(b + 31 + name + 12 * (size_t)i, d->writes[i].t_us);
        put32(b + 39 + name + 12 * (size_t)i, d->writes[i].nbytes);
    }
    return MG_LS_HEADER_BYTES + body;
}

/* a <= b comparing the decimal strings of two non-negative window indices (the JSON object's
 * keys are sorted as strings) */
static int key_le(int64_t a, int64_t b)
{
    char sa[24], sb[24];
    mg_json_t ja, jb;
    mg_json_init(&ja, sa, sizeof sa - 1);
    mg_json_init(&jb, sb, sizeof sb - 1);
    mg_json_int(&ja, a);
    mg_json_int(&jb, b);
    sa[ja.len] = 0, sb[jb.len] = 0;
    return strcmp(sa, sb) <= 0;
}

size_t mg_ls_encode_done(uint8_t *out, size_t cap, const mg_ls_done_t *d)
{
    const size_t name = strlen(d->state);
    if (d->n_events == 0 && d->n_windows == 0 && name <= 255)
        return encode_done_compact(out, cap, d, name);
    mg_json_t j;
    if (cap < MG_LS_HEADER_BYTES)
        return 0;
    mg_json_init(&j, (char *)out + MG_LS_HEADER_BYTES, cap - MG_LS_HEADER_BYTES);
    mg_json_begin_object(&j);
    mg_json_key(&j, "events");
    mg_json_begin_array(&j);
    if (d->n_events > 0)
        mg_json_raw(&j, d->events, d->events_len);
    mg_json_end_array(&j);
    mg_json_key(&j, "load");
    mg_json_begin_object(&j);
    mg_json_key(&j, "camera");
    mg_json_bool(&j, d->camera);
    mg_json_key(&j, "finished");
    mg_json_bool(&j, d->finished);
    mg_json_key(&j, "quiet_until");
    mg_json_int(&j, d->quiet_until);
    mg_json_key(&j, "state");
    mg_json_string(&j, d->state, name);
    mg_json_key(&j, "window_us");
    mg_json_int(&j, d->window_us);
    mg_json_key(&j, "windows");
    mg_json_begin_object(&j);
    int32_t done[MG_LS_MAX_CHUNKS] = {0};
    for (int32_t k = 0; k < d->n_windows && k < MG_LS_MAX_CHUNKS; k++) {
        int32_t pick = -1; /* the smallest key not written yet */
        for (int32_t i = 0; i < d->n_windows && i < MG_LS_MAX_CHUNKS; i++)
            if (!done[i] && (pick < 0 || key_le(d->window_index[i], d->window_index[pick])))
                pick = i;
        done[pick] = 1;
        char key[24];
        mg_json_t jk;
        mg_json_init(&jk, key, sizeof key - 1);
        mg_json_int(&jk, d->window_index[pick]);
        key[jk.len] = 0;
        mg_json_key(&j, key);
        mg_json_micro(&j, d->window_micro[pick]);
    }
    mg_json_end_object(&j);
    mg_json_end_object(&j);
    mg_json_key(&j, "until_us");
    mg_json_int(&j, d->until_us);
    mg_json_key(&j, "writes");
    mg_json_begin_array(&j);
    for (int32_t i = 0; i < d->n_writes; i++) {
        mg_json_int_pair(&j, d->writes[i].t_us, d->writes[i].nbytes);
    }
    mg_json_end_array(&j);
    mg_json_end_object(&j);
    return finish_json(out, MG_LS_DONE, &j);
}
