/* The program's detector table (detectors.h). */
#include "detectors.h"

#include <string.h>

#include "app_factory.h"
#include "arm_calib.h"
#include "held_fill.h"
#include "kernels.h"
#include "task_method.h"

/* the kernels' scratch (the largest: mg_radial_scratch_bytes(640, 480) = 6 144 024 bytes) and
 * the grey image, the dark mask, labels, component stats and number of labels of the 000
 * detectors' front end (one detector runs at a time; the kernels only read the front end's
 * buffers, so the next 000 detector of the frame reuses them) */
#define N_PX (MG_DETECT_MAX_W * MG_DETECT_MAX_H)
#define N_BLOCKS (((MG_DETECT_MAX_W + 1) / 2) * ((MG_DETECT_MAX_H + 1) / 2))
static union {
    uint64_t align;
    uint8_t bytes[6144024];
} scratch;
static uint8_t grey[N_PX], mask[N_PX];
static int32_t labels[N_PX], block_lab[N_BLOCKS], parent[N_BLOCKS + 1],
    stats[5 * (N_BLOCKS + 1)];
static uint32_t hist[256];
static int32_t front_end_n_lab;

/* 1 when the frame fits the static buffers (else counted, nothing found) */
static int fits(mg_detectors_t *d, int32_t w, int32_t h)
{
    const int32_t cap = (int32_t)sizeof scratch.bytes;
    const int ok = w > 0 && h > 0 && w <= MG_DETECT_MAX_W && h <= MG_DETECT_MAX_H
                   && mg_double_cross_scratch_bytes(w, h) <= cap
                   && mg_red_scratch_bytes(w, h) <= cap && mg_radial_scratch_bytes(w, h) <= cap
                   && mg_dual_plus_scratch_bytes(w, h) <= cap;
    d->too_big += !ok;
    return ok;
}

/* The front end of the 000 detectors (host/vision/dark_blobs.py dark_components): grey, dark
 * mask, 8-connected components into the static buffers, or those of the detector before on
 * the same frame when ready; the number of labels, or 0 when the frame does not fit or is
 * under 16 px a side (the Python detectors refuse it: nothing found, nothing charged). */
static int32_t dark_front_end(mg_detectors_t *d, const uint8_t *rgb, int32_t w, int32_t h,
                              int32_t ready)
{
    if (!fits(d, w, h) || w < 16 || h < 16)
        return 0;
    if (!ready) {
        mg_grey(rgb, grey, w * h);
        mg_dark_mask(grey, mask, w * h, hist);
        front_end_n_lab = mg_label(mask, w, h, labels, block_lab, parent, stats);
    }
    return front_end_n_lab;
}

/* adds what the front end charges (dark_blobs.py front_end_min_ops) to *o */
static void dark_front_end_ops(mg_ops_t *o, int32_t w, int32_t h)
{
    mg_grey_ops(o, h, w);
    mg_dark_mask_ops(o, (int64_t)w * h);
    mg_components_ops(o, (int64_t)w * h);
}

/* the front end's modelled time, what a detector after the first of a frame is not charged */
static int64_t dark_front_end_us(int32_t h, int32_t w)
{
    mg_ops_t o;
    mg_ops_clear(&o);
    dark_front_end_ops(&o, w, h);
    return mg_ops_time_us(&o);
}

/* the found result's JSON (the words already out), "null" when it did not fit */
static void finish(mg_detection_t *out, size_t (*json)(const int32_t *, char *, size_t))
{
    if (out->found && json(out->words, out->json, sizeof out->json) == 0)
        memcpy(out->json, "null", 5);
    if (!out->found)
        memcpy(out->json, "null", 5);
}

/* the joint angles of the newest telemetry, as the double cross's and dual "+"'s pose; the arm's rest pose
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
                         const int32_t snap[8], int32_t ready, mg_detection_t *out)
{
    mg_detectors_t *d = (mg_detectors_t *)ctx;
    (void)ready;
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
                         const int32_t snap[8], int32_t ready, mg_detection_t *out)
{
    (void)snap, (void)ready;
    if (fits((mg_detectors_t *)ctx, w, h))
        out->found = mg_red_cylinder(rgb, w, h, scratch.bytes, out->words, &out->ops);
    finish(out, mg_red_cylinder_json);
}

static void red_roi(void *ctx, const uint8_t *rgb, int32_t w, int32_t h, const int32_t snap[8],
                    int32_t ready, mg_detection_t *out)
{
    (void)snap, (void)ready;
    if (fits((mg_detectors_t *)ctx, w, h))
        out->found = mg_red_roi(rgb, w, h, scratch.bytes, out->words, &out->ops);
    finish(out, mg_red_roi_json);
}

static void held_fill(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                      const int32_t snap[8], int32_t ready, mg_detection_t *out)
{
    (void)ctx, (void)snap, (void)ready;
    out->found = mg_held_fill(rgb, w, h, (uint32_t *)scratch.bytes, out->words);
    out->ops = mg_held_fill_ops(h, w);
    finish(out, mg_held_fill_json);
}

/* the 000 radial symbol with the camera's intrinsics (registry "camera" call) */
static void radial_symbol(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                          const int32_t snap[8], int32_t ready, mg_detection_t *out)
{
    mg_detectors_t *d = (mg_detectors_t *)ctx;
    (void)snap;
    const int32_t n_lab = dark_front_end(d, rgb, w, h, ready);
    if (n_lab > 0) {
        out->found = mg_radial_symbol(grey, w, h, stats, n_lab, d->f_px, d->u0_px, d->v0_px,
                                      scratch.bytes, out->words, &out->ops);
        dark_front_end_ops(&out->ops, w, h);
    }
    finish(out, mg_radial_symbol_json);
}

/* the 000 radial symbol cut by the frame's border (registry "frame" call) */
static void radial_cut(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                       const int32_t snap[8], int32_t ready, mg_detection_t *out)
{
    (void)snap;
    const int32_t n_lab = dark_front_end((mg_detectors_t *)ctx, rgb, w, h, ready);
    if (n_lab > 0) {
        out->found = mg_radial_cut(stats, n_lab, w, h, out->words, &out->ops);
        dark_front_end_ops(&out->ops, w, h);
    }
    finish(out, mg_radial_cut_json);
}

/* the 000 dual "+" at the camera's pitch theta2 + theta3 + theta4 (dual_plus.py
 * detect_at_pose) */
static void dual_plus(void *ctx, const uint8_t *rgb, int32_t w, int32_t h,
                      const int32_t snap[8], int32_t ready, mg_detection_t *out)
{
    mg_detectors_t *d = (mg_detectors_t *)ctx;
    const int32_t n_lab = dark_front_end(d, rgb, w, h, ready);
    if (n_lab > 0) {
        out->found = mg_dual_plus(grey, labels, w, h, stats, n_lab, snap[2] + snap[3] + snap[4],
                                  d->f_px, d->u0_px, scratch.bytes, out->words, &out->ops);
        dark_front_end_ops(&out->ops, w, h);
    }
    finish(out, mg_dual_plus_json);
}

/* the 000 spoke (registry "frame" call: no camera) */
static void spoke(void *ctx, const uint8_t *rgb, int32_t w, int32_t h, const int32_t snap[8],
                  int32_t ready, mg_detection_t *out)
{
    (void)snap;
    const int32_t n_lab = dark_front_end((mg_detectors_t *)ctx, rgb, w, h, ready);
    if (n_lab > 0) {
        out->found = mg_spoke(grey, labels, w, h, stats, n_lab, scratch.bytes, out->words,
                              &out->ops);
        dark_front_end_ops(&out->ops, w, h);
    }
    finish(out, mg_spoke_json);
}

int32_t mg_detectors_table(mg_detectors_t *d, const mg_app_t *app, int32_t f_px,
                           mg_detector_t *table, int32_t cap)
{
    memset(d, 0, sizeof *d);
    d->app = app;
    d->f_px = f_px;
    d->u0_px = 160; /* host/app_factory.py's defaults */
    d->v0_px = 120;
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
                    : i == MG_DET_RADIAL_SYMBOL ? radial_symbol
                    : i == MG_DET_DUAL_PLUS    ? dual_plus
                    : i == MG_DET_RADIAL_CUT   ? radial_cut
                                               : spoke;
        if (i == MG_DET_DOUBLE_CROSS || i == MG_DET_DUAL_PLUS)
            t->snapshot = pose_snapshot;
        if (i == MG_DET_RADIAL_SYMBOL || i == MG_DET_DUAL_PLUS || i == MG_DET_SPOKE
            || i == MG_DET_RADIAL_CUT) {
            t->front_end = 1; /* the dark front end, shared by the 000 detectors of a frame */
            t->front_end_us = dark_front_end_us;
        }
    }
    return MG_N_DETECTORS;
}
