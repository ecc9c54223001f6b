/* The free-running driver of the C host on a Linux board (drivers/realtime.py): the
 * monotonic clock, the serial port to the ATmega128 in raw mode (/dev/ttySAC1 on a mini2440,
 * a pty here), the program advanced to the clock whenever bytes arrive or a tick is due.
 * Camera frames are not read yet (no V4L2 nor simulator frame endpoint in C). */
#ifndef MOBIGRASP_HOSTC_LINUX_DRIVER_H
#define MOBIGRASP_HOSTC_LINUX_DRIVER_H

#include "app.h"

/* Run until the task finishes (0) or the port closes or fails (< 0). */
int mg_linux_run(mg_app_t *app, int serial_fd);

#endif
