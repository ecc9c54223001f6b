/* The host program as the calibration replays it (calib/program.py): one configuration's
 * program in a block of memory the caller gives (as main.c and inproc.c hold it), driven through app.h's
 * entry points with a recorded run's bytes and frames, and the figures read between the calls:
 * the modelled time per stage, the serial bytes due. */
#ifndef MOBIGRASP_HOSTC_CALIB_PROGRAM_H
#define MOBIGRASP_HOSTC_CALIB_PROGRAM_H

#include <stdint.h>

#include "app.h"
#include "detectors.h"
#include "program.h"
#include "task.h"

typedef struct {
    mg_app_t app; /* first: a pointer to the program is one to its app */
    mg_detectors_t detectors;
    mg_detector_t table[MG_MAX_DETECTORS];
    uint64_t task_state[MG_TASK_STATE_BYTES / 8];
} mg_calib_program_t;

/* the program of the configuration's JSON text (n bytes: what --config gives the program): its
 * number of detectors, or -1 when the text is refused or the program has no such method */
int32_t mg_calib_program_open(mg_calib_program_t *p, const char *config, int32_t n);
/* the program's detector table (the calibration reads its detect entries) */
const mg_detector_t *mg_calib_table(const mg_calib_program_t *p);
/* the modelled us the program's stage name has been busy so far (name NULL: every stage's) */
int64_t mg_calib_stage_us(const mg_app_t *app, const char *name);
/* the serial bytes due before before_us (mg_link_take_output), one after the other into out:
 * their count, or -1 when they do not fit cap (they are taken either way) */
int32_t mg_calib_take_output(mg_app_t *app, int64_t before_us, uint8_t *out, int32_t cap);

#endif
