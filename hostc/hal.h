/* The board HAL of the C host, the ArduPilot AP_HAL way (host/hal.py is the Python one): the
 * portable host code reaches the UART to the ATmega128, the camera, the clock and the log only
 * through this table; a driver fills it in (lockstep: the rig's grants and frame ring; linux:
 * termios, V4L2 or the simulator's raw frames, the free-running clock). Time is integer
 * microseconds owned by the driver. */
#ifndef MOBIGRASP_HOSTC_HAL_H
#define MOBIGRASP_HOSTC_HAL_H

#include <stddef.h>
#include <stdint.h>

/* The UART to the ATmega128 (host/hal.py SerialPort). */
typedef struct {
    void *ctx;
    /* what arrived since the last read, without waiting: bytes copied (0: nothing), < 0 error */
    long (*read)(void *ctx, uint8_t *buf, size_t n);
    /* send all n bytes: n, or < 0 on error */
    long (*write)(void *ctx, const uint8_t *buf, size_t n);
    /* wait up to timeout_us for bytes to read: 1 there are some, 0 none, < 0 error */
    int (*wait_readable)(void *ctx, int32_t timeout_us);
} mg_hal_serial_t;

/* One camera image as the host receives it (host/hal.py CameraFrame): interleaved RGB, owned by
 * the driver and valid until the next poll. */
#define MG_FRAME_W 320
#define MG_FRAME_H 240
typedef struct {
    uint32_t seq;
    int64_t capture_us;
    int32_t w, h;
    const uint8_t *rgb;
} mg_hal_frame_t;

typedef struct {
    void *ctx;
    /* the newest frame not yet returned: 1 and *out filled, 0 none, < 0 error */
    int (*poll)(void *ctx, mg_hal_frame_t *out);
} mg_hal_camera_t;

typedef struct {
    void *ctx;
    int64_t (*now_us)(void *ctx); /* never goes back */
} mg_hal_clock_t;

typedef struct {
    void *ctx;
    /* one line of text, without its newline */
    void (*line)(void *ctx, const char *text, size_t n);
} mg_hal_log_t;

typedef struct {
    mg_hal_serial_t serial;
    mg_hal_camera_t camera;
    mg_hal_clock_t clock;
    mg_hal_log_t log;
} mg_hal_t;

#endif
