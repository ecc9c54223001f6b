/* The host program of one method as a caller holds it (the in-process program, the
 * calibration): its app (app.h) over the program's detector table (detectors.h) and the
 * method's task state (task.h), opened with the default configuration. */
#ifndef MOBIGRASP_HOSTC_PROGRAM_H
#define MOBIGRASP_HOSTC_PROGRAM_H

#include <stdint.h>

#include "app.h"
#include "detectors.h"
#include "task.h"

/* the program running method with a camera of f_px in the caller's app, d, table (of
 * MG_MAX_DETECTORS) and task state (MG_TASK_STATE_BYTES): its number of detectors, or -1 when
 * the table has no such method */
int32_t mg_program_open(mg_app_t *app, mg_detectors_t *d, mg_detector_t *table,
                        uint64_t *task_state, const char *method, int32_t f_px);

#endif
