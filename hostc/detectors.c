/* The program's detector table (detectors.h). */
#include "detectors.h"

#include <string.h>

#include "app_factory.h"
#include "arm_calib.h"
#include "held_fill.h"
#include "kernels.h"
#include "task_method.h"

/* the kernels' scratch, the grey image of the double cross (one detector runs at a time) */
static union {
    uint64_t align;
    uint8_t bytes[2400000];
} scratch;
static uint8_t grey[MG_DETECT_MAX_W * MG_DETECT_MAX_H];

/* 1 when the frame fits the static buffers (else counted, nothing found) */
static int fits(mg_detectors_t *d, int32_t w, int32_t h)
{
    const int ok = w > 0 && h > 0 && w <= MG_DETECT_MAX_W && h <= MG_DETECT_MAX_H
                   && mg_double_cross_scratch_bytes(w, h) <= (int32_t)sizeof scratch.bytes
                   && mg_red_scratch_bytes(w, h) <= (int32_t)sizeof scratch.bytes;
    d->too_big += !ok;
    return ok;
}

/* the found result's JSON (the words already out), "null" when it did not fit */
static void finish(mg_detection_t *out, size_t (*json)(const int32_t *, char *, size_t))
{
    if (out->found && json(out->words, out->json, sizeof out->json) == 0)
        memcpy(out->json, "null", 5);
    if (!out->found)
        memcpy(out->json, "null", 5);
}

/* the joint angles of the newest telemetry, as the double cross's pose; the arm's rest pose
 * before any (host/app_factory.py _detectors joints) */
static void pose_snapshot(void *ctx, int32_t snap[8])
{
    const mg_detectors_t *d = (const mg_detectors_t *)ctx;
    static const int32_t rest[MG_N_CHANNELS] = {0, 0, -1571, 0, 0, 0};
    int32_t q[MG_N_CHANNELS], pulses[MG_N_CHANNELS];
    memcpy(q, rest, sizeof q);
    if (d->app->link.has_telemetry) {
        for (int32_t ch = 0; ch < MG_N_CHANNELS; ch++)
            pulses[ch] = d->app->link.telemetry.servo_us[ch];
        if (!mg_pulses_to_joints_mrad(pulses, q))
            memcpy(q, rest, sizeof q);
    }
    memcpy(snap, q, sizeof q);
}

static void double_cross(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                         const int32_t snap[8], mg_detection_t *out)
{
    mg_detectors_t *d = (mg_detectors_t *)ctx;
    if (!fits(d, w, h))
    {
        finish(out, mg_double_cross_json);
        return;
    }
    /* the camera's yaw theta5 and pitch theta2 + theta3 + theta4 (double_cross.py
     * detect_at_pose), the grey image first */
    mg_grey(rgb, grey, w * h);
    out->found = mg_double_cross(grey, w, h, snap[5], snap[2] + snap[3] + snap[4], d->f_px,
                                 scratch.bytes, out->words, &out->ops);
    mg_grey_ops(&out->ops, h, w);
    finish(out, mg_double_cross_json);
}

static void red_cylinder(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                         const int32_t snap[8], mg_detection_t *out)
{
    (void)snap;
    if (fits((mg_detectors_t *)ctx, w, h))
        out->found = mg_red_cylinder(rgb, w, h, scratch.bytes, out->words, &out->ops);
    finish(out, mg_red_cylinder_json);
}

static void red_roi(void *ctx, const uint8_t *rgb, int32_t w, int32_t h, const int32_t snap[8],
                    mg_detection_t *out)
{
    (void)snap;
    if (fits((mg_detectors_t *)ctx, w, h))
        out->found = mg_red_roi(rgb, w, h, scratch.bytes, out->words, &out->ops);
    finish(out, mg_red_roi_json);
}

static void held_fill(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                      const int32_t snap[8], mg_detection_t *out)
{
    (void)ctx, (void)snap;
    out->found = mg_held_fill(rgb, w, h, (uint32_t *)scratch.bytes, out->words);
    out->ops = mg_held_fill_ops(h, w);
    finish(out, mg_held_fill_json);
}

/* a detector not in the program yet: nothing found, nothing charged */
static void not_ported(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                       const int32_t snap[8], mg_detection_t *out)
{
    (void)ctx, (void)rgb, (void)w, (void)h, (void)snap;
    memcpy(out->json, "null", 5);
}

int32_t mg_detectors_table(mg_detectors_t *d, const mg_app_t *app, int32_t f_px,
                           mg_detector_t *table, int32_t cap)
{
    memset(d, 0, sizeof *d);
    d->app = app;
    d->f_px = f_px;
    if (cap < MG_N_DETECTORS)
        return 0;
    for (int32_t i = 0; i < MG_N_DETECTORS; i++) {
        mg_detector_t *t = &table[i];
        memset(t, 0, sizeof *t);
        t->name = mg_detector_names[i];
        t->ctx = d;
        t->detect = i == MG_DET_DOUBLE_CROSS    ? double_cross
                    : i == MG_DET_RED_CYLINDER ? red_cylinder
                    : i == MG_DET_RED_ROI      ? red_roi
                    : i == MG_DET_HELD_FILL    ? held_fill
                                               : not_ported;
        if (i == MG_DET_DOUBLE_CROSS)
            t->snapshot = pose_snapshot;
    }
    return MG_N_DETECTORS;
}
