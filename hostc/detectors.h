/* The program's detector table (host/app_factory.py _detectors over host/vision/registry.py):
 * one mg_detector_t per detector the task names, in its order (task_method.h MG_DET_*), each
 * running its C kernel on the frame, charging the operation counts the Python detector charges
 * (kernels.h), its out words for the task and its result's JSON for the detect event
 * (app_factory.h). The double cross and the dual "+" read the camera's pose from the joints of
 * the newest telemetry when their frame arrives. The 000 detectors (the radial symbol, the
 * dual "+", the spoke, the cut symbol) start from one front end (grey, dark mask, components:
 * their counts include it; the first of a frame computes it, the others reuse it, and the
 * program charges it once a frame, mg_detector_t.front_end) and refuse frames under 16 px a
 * side as the Python ones do (nothing found, nothing charged). */
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
    int32_t u0_px, v0_px; /* its principal point (px): 160, 120 unless the caller sets them */
    int64_t too_big;
} mg_detectors_t;

/* the table (MG_DET_* order) over d, for the program app with a camera of f_px: its length */
int32_t mg_detectors_table(mg_detectors_t *d, const mg_app_t *app, int32_t f_px,
                           mg_detector_t *table, int32_t cap);

#endif
