/* The free-running driver's camera: the source chosen by its scheme (camera.h). */
#include "camera.h"

#include <string.h>

#include "sys.h"

static uint8_t buffers[2][MG_CAMERA_FRAME_BYTES];

uint8_t *mg_camera_buffer(int32_t i)
{
    return buffers[i & 1];
}

int mg_camera_open(mg_camera_t *c, const char *source, const char **why)
{
    memset(c, 0, sizeof *c);
    c->fd = -1;
    if (strncmp(source, "unix:", 5) == 0) {
        const int r = mg_camera_raw_open(c, source + 5);
        if (r < 0)
            *why = "cannot connect to the raw-frame socket of --camera ";
        return r;
    }
    if (strncmp(source, "v4l2:", 5) == 0)
        return mg_camera_v4l2_open(c, source + 5, why);
    *why = "--camera must be unix:PATH (mobigrasp sim --raw-frames) or v4l2:DEVICE: ";
    return -1;
}

int mg_camera_read(mg_camera_t *c, mg_hal_frame_t *out, int64_t now_us)
{
    return c->kind == MG_CAMERA_RAW ? mg_camera_raw_read(c, out, now_us)
                                    : mg_camera_v4l2_read(c, out, now_us);
}

void mg_camera_close(mg_camera_t *c)
{
    if (c->fd >= 0)
        sys_close(c->fd);
    c->fd = -1;
}
