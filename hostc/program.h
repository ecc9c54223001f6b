/* The host program of one configuration as a caller holds it (the in-process program, the
 * calibration): its app (app.h, the default host configuration) over the program's detector
 * table (detectors.h) and the method's task state (task.h). */
#ifndef MOBIGRASP_HOSTC_PROGRAM_H
#define MOBIGRASP_HOSTC_PROGRAM_H

#include <stdint.h>

#include "app.h"
#include "config.h"
#include "detectors.h"
#include "task.h"

/* the program of configuration c (its method, camera f_px and task settings) in the caller's
 * app, d, table (of MG_MAX_DETECTORS) and task state (MG_TASK_STATE_BYTES): its number of
 * detectors, or -1 when the table has no such method */
int32_t mg_program_open(mg_app_t *app, mg_detectors_t *d, mg_detector_t *table,
                        uint64_t *task_state, const mg_config_t *c);

#endif
