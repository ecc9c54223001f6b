/* The free-running driver's camera (linux_driver.c): where the board's frames come from.
 *   unix:PATH   the raw-frame endpoint of `mobigrasp sim --raw-frames PATH` (camera_raw.c;
 *               docs/porting.md, "The raw-frame endpoint"): frames of the simulation
 *   v4l2:DEVICE a V4L2 capture device read with read() (camera_v4l2.c), /dev/video0 or the
 *               mini2440's CAMIF; 320x240, RGB24 or RGB565 (expanded to RGB)
 * Frames are handed over as interleaved RGB (hal.h mg_hal_frame_t), each valid until the next
 * frame is returned (two buffers: the program reads one while the next arrives). */
#ifndef MOBIGRASP_HOSTC_CAMERA_H
#define MOBIGRASP_HOSTC_CAMERA_H

#include <stdint.h>

#include "hal.h"

#define MG_CAMERA_FRAME_BYTES (MG_FRAME_W * MG_FRAME_H * 3)

typedef struct {
    int fd;   /* to poll for readability; -1: no camera */
    int kind; /* MG_CAMERA_RAW or MG_CAMERA_V4L2 */
    uint32_t seq;
    int64_t frames, bad; /* frames handed over; messages or reads refused */
    /* the message being read (raw): its header, then pixels into buffer `filling` */
    uint8_t head[32];
    uint32_t got, need;
    int32_t w, h, bpp, filling;
} mg_camera_t;

enum { MG_CAMERA_RAW = 1, MG_CAMERA_V4L2 = 2 };

/* open SOURCE ("unix:PATH" or "v4l2:DEVICE"): 0, or < 0 with *why naming what failed */
int mg_camera_open(mg_camera_t *c, const char *source, const char **why);
/* read what is there (call when the fd polls readable): 1 when a whole frame is ready (*out
 * filled, capture_us = now_us: the time it arrived), 0 not yet, < 0 the source closed or
 * failed */
int mg_camera_read(mg_camera_t *c, mg_hal_frame_t *out, int64_t now_us);
void mg_camera_close(mg_camera_t *c);

/* camera_raw.c */
int mg_camera_raw_open(mg_camera_t *c, const char *path);
int mg_camera_raw_read(mg_camera_t *c, mg_hal_frame_t *out, int64_t now_us);
/* camera_v4l2.c */
int mg_camera_v4l2_open(mg_camera_t *c, const char *device, const char **why);
int mg_camera_v4l2_read(mg_camera_t *c, mg_hal_frame_t *out, int64_t now_us);

/* the two frame buffers the sources share (only one camera is open at a time) */
uint8_t *mg_camera_buffer(int32_t i);

#endif
