/* A V4L2 capture device read with read() (camera.h, v4l2:DEVICE): the board's camera, the
 * mini2440's CAMIF with its OV9650 or a USB camera. The format is set to 320x240 RGB24 and, when
 * the driver offers RGB565 instead, taken as that and expanded to RGB. The structures are the
 * kernel's (include/uapi/linux/videodev2.h), with the pointer member that sets the union's
 * alignment, so the request's size (and so its number) is the kernel's on 32- and 64-bit
 * ABIs. Compiled for both targets; it cannot be tested here (no capture device): see
 * docs/porting.md. */
#include <string.h>

#include "camera.h"
#include "sys.h"

struct v4l2_pix_format_k {
    uint32_t width, height, pixelformat, field, bytesperline, sizeimage, colorspace, priv;
    uint32_t flags, ycbcr_enc, quantization, xfer_func;
};

struct v4l2_format_k {
    uint32_t type;
    union {
        struct v4l2_pix_format_k pix;
        uint8_t raw_data[200];
        void *align; /* struct v4l2_window holds pointers */
    } fmt;
};

#define FOURCC(a, b, c, d) \
    ((uint32_t)(a) | (uint32_t)(b) << 8 | (uint32_t)(c) << 16 | (uint32_t)(d) << 24)
#define PIX_RGB24 FOURCC('R', 'G', 'B', '3')
#define PIX_RGB565 FOURCC('R', 'G', 'B', 'P')
#define BUF_TYPE_VIDEO_CAPTURE 1u
#define FIELD_NONE 1u
/* _IOWR('V', 5, struct v4l2_format) */
#define VIDIOC_S_FMT ((3u << 30) | ((uint32_t)sizeof(struct v4l2_format_k) << 16) | ('V' << 8) | 5u)

int mg_camera_v4l2_open(mg_camera_t *c, const char *device, const char **why)
{
    c->fd = sys_open(device, SYS_O_RDWR, 0);
    if (c->fd < 0) {
        *why = "cannot open the V4L2 device of --camera ";
        return c->fd;
    }
    c->kind = MG_CAMERA_V4L2;
    struct v4l2_format_k f;
    memset(&f, 0, sizeof f);
    f.type = BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.width = MG_FRAME_W;
    f.fmt.pix.height = MG_FRAME_H;
    f.fmt.pix.pixelformat = PIX_RGB24;
    f.fmt.pix.field = FIELD_NONE;
    const int r = sys_ioctl(c->fd, VIDIOC_S_FMT, &f); /* the driver answers what it will give */
    if (r < 0 || f.fmt.pix.width != MG_FRAME_W || f.fmt.pix.height != MG_FRAME_H
        || (f.fmt.pix.pixelformat != PIX_RGB24 && f.fmt.pix.pixelformat != PIX_RGB565)) {
        *why = "the V4L2 device does not give 320x240 RGB24 or RGB565: --camera ";
        mg_camera_close(c);
        return r < 0 ? r : -1;
    }
    c->w = MG_FRAME_W;
    c->h = MG_FRAME_H;
    c->bpp = f.fmt.pix.pixelformat == PIX_RGB24 ? 3 : 2;
    return 0;
}

int mg_camera_v4l2_read(mg_camera_t *c, mg_hal_frame_t *out, int64_t now_us)
{
    uint8_t *px = mg_camera_buffer(c->filling);
    const uint32_t n = (uint32_t)(c->w * c->h * c->bpp);
    const long r = sys_read(c->fd, px, n); /* read() I/O: one whole frame per read */
    if (r < 0)
        return (int)r;
    if ((uint32_t)r != n) {
        c->bad++;
        return 0;
    }
    if (c->bpp == 2) /* RGB565 little-endian to RGB, from the end (3i >= 2i) */
        for (int32_t i = c->w * c->h - 1; i >= 0; i--) {
            const uint32_t p = (uint32_t)px[2 * i] | (uint32_t)px[2 * i + 1] << 8;
            const uint32_t r5 = p >> 11, g6 = (p >> 5) & 0x3f, b5 = p & 0x1f;
            px[3 * i] = (uint8_t)(r5 << 3 | r5 >> 2);
            px[3 * i + 1] = (uint8_t)(g6 << 2 | g6 >> 4);
            px[3 * i + 2] = (uint8_t)(b5 << 3 | b5 >> 2);
        }
    *out = (mg_hal_frame_t){c->seq++, now_us, c->w, c->h, px};
    c->filling ^= 1;
    c->frames++;
    return 1;
}
