/* The program's detector table (host/app_factory.py _detectors over host/vision/registry.py):
 * one mg_detector_t per detector the task names, in its order (task_method.h MG_DET_*), each
 * running its C kernel on the frame, charging the operation counts the Python detector charges
 * (kernels.h), its out words for the task and its result's JSON for the detect event
 * (app_factory.h). The double cross reads the camera's yaw and pitch from the joints of the
 * newest telemetry when its frame arrives. The kernels not ported to the program yet (the
 * dual "+", the radial symbol, the spoke) find nothing and charge nothing. */
#ifndef MOBIGRASP_HOSTC_DETECTORS_H
#define MOBIGRASP_HOSTC_DETECTORS_H

#include <stdint.h>

#include "app.h"

/* the largest frame the detectors look at (their scratch is static); a larger one is counted
 * (mg_detectors_t.too_big) and its detectors find nothing */
#define MG_DETECT_MAX_W 640
#define MG_DETECT_MAX_H 480

typedef struct {
    const mg_app_t *app; /* whose newest telemetry gives the pose */
    int32_t f_px;        /* the camera's focal length (px) */
    int64_t too_big;
} mg_detectors_t;

/* the table (MG_DET_* order) over d, for the program app with a camera of f_px: its length */
int32_t mg_detectors_table(mg_detectors_t *d, const mg_app_t *app, int32_t f_px,
                           mg_detector_t *table, int32_t cap);

#endif
