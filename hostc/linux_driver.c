/* The free-running driver (drivers/realtime.py run): wall time from CLOCK_MONOTONIC. */
#include "linux_driver.h"

#include <string.h>

#include "sys.h"

static void say(const char *text)
{
    sys_write(2, text, strlen(text));
}

int mg_linux_run(mg_app_t *app, int serial_fd, mg_camera_t *camera)
{
    static uint8_t buf[4096];
    static char events[MG_EVENTS_BYTES + 1];
    const int64_t t0 = sys_monotonic_us();
    while (!app->finished) {
        const int64_t now = sys_monotonic_us() - t0;
        int64_t wait_us = app->next_tick_us - now;
        const int has_camera = camera != NULL && camera->fd >= 0;
        struct sys_pollfd p[2] = {{serial_fd, SYS_POLLIN, 0},
                                  {has_camera ? camera->fd : -1, SYS_POLLIN, 0}};
        const int r = sys_poll(p, has_camera ? 2 : 1,
                               wait_us > 0 ? (int)((wait_us + 999) / 1000) : 0);
        if (r < 0)
            return r;
        const int64_t t = sys_monotonic_us() - t0;
        if (p[0].revents & SYS_POLLIN) {
            const long n = sys_read(serial_fd, buf, sizeof buf);
            if (n <= 0)
                return n < 0 ? (int)n : -1; /* the MCU side closed the port */
            mg_app_on_uart(app, buf, (size_t)n, t);
        } else if (p[0].revents & (SYS_POLLHUP | SYS_POLLERR)) {
            return -1;
        }
        if (has_camera && (p[1].revents & (SYS_POLLIN | SYS_POLLHUP | SYS_POLLERR))) {
            mg_hal_frame_t f;
            const int got = mg_camera_read(camera, &f, t);
            if (got == 1) /* arrived now: after everything the program has passed */
                mg_app_on_frame(app, f.seq, f.capture_us, t > app->now_us ? t : app->now_us,
                                f.rgb, f.w, f.h);
            else if (got < 0) {
                mg_camera_close(camera);
                say("mobigrasp-host-c: the camera's source ended or failed; going on without "
                    "frames\n");
            }
        }
        mg_app_advance_to(app, t + 1);
        mg_wire_chunk_t out[MG_OUTBOX_CHUNKS];
        const int32_t k = mg_link_take_output(&app->link, t + 1, out, MG_OUTBOX_CHUNKS);
        for (int32_t i = 0; i < k; i++)
            for (size_t put = 0; put < out[i].len;) {
                const long w = sys_write(serial_fd, out[i].wire + put, out[i].len - put);
                if (w <= 0)
                    return w < 0 ? (int)w : -1;
                put += (size_t)w;
            }
        size_t len; /* the trace events to the log, one line per quantum that had some */
        if (mg_app_take_events(app, events, sizeof events - 1, &len) > 0) {
            events[len] = '\n';
            sys_write(2, events, len + 1);
        }
    }
    return 0;
}
