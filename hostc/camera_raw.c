/* The raw-frame endpoint's client (camera.h, unix:PATH): the messages of cosim/serve/
 * raw_frames.py, a 32-byte little-endian header (magic "MGRF", version 1, format 1 RGB or 2
 * grey, width, height, seq, capture_us, nbytes) then the pixels; read as they arrive, never
 * waiting. A message that is not one (magic, version, format, a size beyond 320x240) is counted
 * and the stream closed: the client cannot find the next header again. */
#include <string.h>

#include "camera.h"
#include "sys.h"

static uint32_t u16le(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8;
}

static uint32_t u32le(const uint8_t *p)
{
    return u16le(p) | u16le(p + 2) << 16;
}

int mg_camera_raw_open(mg_camera_t *c, const char *path)
{
    c->fd = sys_unix_connect(path);
    if (c->fd < 0)
        return c->fd;
    c->kind = MG_CAMERA_RAW;
    c->need = sizeof c->head;
    return 0;
}

/* the header just read: its frame's geometry, or -1 */
static int take_header(mg_camera_t *c)
{
    const uint8_t *h = c->head;
    const uint32_t fmt = u16le(h + 6), w = u16le(h + 8), ht = u16le(h + 10);
    const uint32_t bpp = fmt == 1 ? 3 : fmt == 2 ? 1 : 0;
    if (memcmp(h, "MGRF", 4) != 0 || u16le(h + 4) != 1 || bpp == 0 || w == 0 || ht == 0
        || w > MG_FRAME_W || ht > MG_FRAME_H || u32le(h + 24) != w * ht * bpp)
        return -1;
    c->seq = u32le(h + 12);
    c->w = (int32_t)w;
    c->h = (int32_t)ht;
    c->bpp = (int32_t)bpp;
    return 0;
}

int mg_camera_raw_read(mg_camera_t *c, mg_hal_frame_t *out, int64_t now_us)
{
    const int in_header = c->bpp == 0;
    uint8_t *dst = in_header ? c->head : mg_camera_buffer(c->filling);
    const long n = sys_read(c->fd, dst + c->got, c->need - c->got);
    if (n <= 0)
        return n < 0 ? (int)n : -1; /* the simulation ended the stream */
    c->got += (uint32_t)n;
    if (c->got < c->need)
        return 0;
    c->got = 0;
    if (in_header) {
        if (take_header(c) != 0) {
            c->bad++;
            return -1;
        }
        c->need = (uint32_t)(c->w * c->h * c->bpp);
        return 0;
    }
    uint8_t *px = mg_camera_buffer(c->filling);
    if (c->bpp == 1) /* grey to RGB, from the end so nothing is overwritten before it is read */
        for (int32_t i = c->w * c->h - 1; i >= 0; i--)
            px[3 * i] = px[3 * i + 1] = px[3 * i + 2] = px[i];
    *out = (mg_hal_frame_t){c->seq, now_us, c->w, c->h, px};
    c->filling ^= 1;
    c->bpp = 0;
    c->need = sizeof c->head;
    c->frames++;
    return 1;
}
