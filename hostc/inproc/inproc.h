/* The C host program in the simulator's process (`mobigrasp run --host c --transport inproc`,
 * through cffi): the program of main.c with its lockstep driver, served one GRANT at a time by
 * the caller instead of over the Unix socket and the serial port. The GRANT arrives encoded as
 * the rig writes it (its frames in the blob), the DONE and BYE leave encoded as the program
 * writes them, so both transports see the same bytes. The program's state is the caller's
 * mg_inproc_t: any number of hosts per process. Not part of the board's build. */
#ifndef MOBIGRASP_HOSTC_INPROC_H
#define MOBIGRASP_HOSTC_INPROC_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "detectors.h"
#include "lockstep.h"
#include "lockstep_driver.h"
#include "task.h"

typedef struct {
    mg_app_t app;
    mg_lockstep_t driver;
    mg_ls_grant_t grant;
    mg_detectors_t detectors;
    mg_detector_t table[MG_MAX_DETECTORS];
    uint64_t task_state[MG_TASK_STATE_BYTES / 8];
} mg_inproc_t;

/* the program of the configuration's JSON text (config.h: its method's row of task.c, its
 * parameters, the camera's f_px): 0, or -1 with why (a bad configuration: its key) when it is
 * refused or the table has no such row */
int mg_inproc_open(mg_inproc_t *h, const char *config, size_t n, char *why, size_t cap);
/* one encoded GRANT message (header, metadata, blob) of n bytes with the uart_n serial bytes it
 * announces: the encoded DONE into done (its length; 0 when the message is malformed, names a
 * shared frame, or the DONE does not fit), the serial bytes the program wrote into out
 * (*out_len; 0 when they do not fit, with the DONE's length 0 too) */
size_t mg_inproc_serve(mg_inproc_t *h, const uint8_t *msg, size_t n, const uint8_t *uart,
                       size_t uart_n, uint8_t *done, size_t cap, uint8_t *out, size_t out_cap,
                       size_t *out_len);
/* the encoded BYE with the program's statistics: its length, 0 when cap is too small */
size_t mg_inproc_bye(const mg_inproc_t *h, uint8_t *out, size_t cap);

#endif
