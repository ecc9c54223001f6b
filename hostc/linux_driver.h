/* The free-running driver of the C host on a Linux board (drivers/realtime.py): the
 * monotonic clock, the serial port to the ATmega128 in raw mode (/dev/ttySAC1 on a mini2440,
 * a pty here), camera frames from the board's V4L2 device or the simulation's raw-frame
 * endpoint (camera.h), the program advanced to the clock whenever bytes or a frame arrive or a
 * tick is due. */
#ifndef MOBIGRASP_HOSTC_LINUX_DRIVER_H
#define MOBIGRASP_HOSTC_LINUX_DRIVER_H

#include "app.h"
#include "camera.h"

/* Run until the task finishes (0) or the port closes or fails (< 0). camera: NULL for none; a
 * camera whose source ends or fails is closed with one line on stderr and the run goes on. */
int mg_linux_run(mg_app_t *app, int serial_fd, mg_camera_t *camera);

#endif
