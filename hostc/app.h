/* The S3C2440 host program's main loop (host/app.py): the 20 ms control step (telemetry in,
 * one task step, commands out, heartbeat), camera frames handed to the detectors the task needs
 * when vision is idle (a frame arriving while it is busy is dropped), and the modelled ARM920T
 * time of both activities (budget.h): control preempts vision, a step finishing after the next
 * tick is a deadline miss, the busy time is summed per load window. Time moves only through
 * mg_app_advance_to and the arrival times given with data; no wall clock is read here. */
#ifndef MOBIGRASP_HOSTC_APP_H
#define MOBIGRASP_HOSTC_APP_H

#include <stddef.h>
#include <stdint.h>

#include "app_link.h"
#include "budget.h"

typedef struct {
    int64_t control_period_us;     /* 20 000 */
    int64_t heartbeat_period_us;   /* 100 000 */
    int64_t hello_wait_us;         /* 100 000: the first HELLO waits until the MCU is heard */
    int64_t wheels_repeat_us;      /* 100 000: SetWheels is unreliable, repeated this often */
    int64_t load_window_us;        /* 500 000 (must divide 10^6: the loads are exact then) */
    int64_t control_base_cycles;   /* 22 000: a step with nothing new (host/app.py) */
    int64_t handover_cycles;       /* 12 000: a step handed a vision job's results */
    int64_t protocol_cycles_per_byte; /* 40: COBS, CRC-16 and copy, both directions */
    int64_t frame_overhead_cycles; /* 20 000: CAMIF hand-over, cache maintenance */
    uint16_t servo_slew_mrad_s;
} mg_host_config_t;

void mg_host_config_default(mg_host_config_t *c);

#define MG_MAX_DETECTORS 8
#define MG_DETAIL_MEMBERS 16
#define MG_TASK_TRANSITIONS 4

/* One member of a task's detail: a key and its value already in JSON (sorted JSON). */
typedef struct {
    const char *key;
    const char *json;
} mg_json_member_t;

/* What one task step gives the host program (host/task's TaskOutputs). */
typedef struct {
    int32_t has_servos, servo_mrad[6];
    int32_t has_gripper, gripper_permille;
    int32_t has_wheels, wheels_mmps[2];
    const char *state; /* the task's state name (NULL: unchanged) */
    mg_ops_t ops;      /* what the step cost */
    int32_t n_transitions;
    struct {
        int64_t t_us;
        const char *from, *to, *why;
    } transitions[MG_TASK_TRANSITIONS];
    int32_t n_detail; /* 0: no detail event */
    int32_t detail_has_plan; /* the detail carries a plan (counted: plans, replans) */
    mg_json_member_t detail[MG_DETAIL_MEMBERS];
} mg_task_output_t;

/* A detector's result: found or not, what it cost, its JSON for the detect event. */
typedef struct {
    int32_t found;
    mg_ops_t ops;
    char json[512]; /* "null" when not found */
    int32_t words[32]; /* the numbers the task reads */
} mg_detection_t;

typedef struct {
    const char *name;
    void *ctx;
    /* the pose a pose-reading detector takes when its frame arrives (may be NULL) */
    void (*snapshot)(void *ctx, int32_t snap[8]);
    /* front_end_ready: 1 when a detector with the same front end (same id and ctx) ran
     * before it on this frame, so ctx holds the front end's result: it is reused, not
     * computed again */
    void (*detect)(void *ctx, const uint8_t *rgb, int32_t w, int32_t h, const int32_t snap[8],
                   int32_t front_end_ready, mg_detection_t *out);
    /* the front end it starts from (0: none; detectors of one frame with the same id share
     * it: the first computes it and pays, the others reuse it and are charged less its time,
     * front_end_us on h x w) */
    int32_t front_end;
    int64_t (*front_end_us)(int32_t h, int32_t w);
} mg_detector_t;

typedef struct mg_app mg_app_t;

#define MG_APP_FRAMES 8 /* frames given and not yet passed by advance_to */
typedef struct {
    int64_t seq, capture_us, arrival_us;
    const uint8_t *rgb;
    int32_t w, h;
} mg_app_frame_t;

/* The task as the host program steps it; the detections of the last finished vision job are
 * handed over once (present[i] for detector i). */
typedef struct {
    void *ctx;
    void (*step)(void *ctx, mg_app_t *app, int64_t now_us, const mg_detection_t *detections,
                 const int32_t *present, mg_task_output_t *out);
    uint32_t (*detectors_needed)(void *ctx); /* a bit per detector index */
    /* the detector that detector det stands in for on the same frame (it runs only when that
     * one, run before it, found nothing): its index, or -1; NULL: no fallbacks */
    int32_t (*fallback_of)(void *ctx, int32_t det);
} mg_task_if_t;

#define MG_LOAD_WINDOWS_KEPT 64
#define MG_EVENTS_BYTES 32768
#define MG_STAGES (4 + MG_MAX_DETECTORS)

/* a stage's histogram of modelled us per call (host/stage_stats.py): exact below 2048 us, the
 * 11 leading bits above, up to 2^31 us (longer calls are counted in the top bucket and in
 * stage_overflow) */
#define MG_STAGE_EXACT_US 2048
#define MG_STAGE_OCTAVES 20
#define MG_STAGE_BUCKETS (MG_STAGE_EXACT_US + MG_STAGE_OCTAVES * 1024)
/* the BYE's figures (mg_app_stats_json) fit in this */
#define MG_APP_STATS_BYTES 4096

typedef struct {
    const char *name;
    int64_t calls, total_us, max_us;
    uint32_t counts[MG_STAGE_BUCKETS];
} mg_stage_t;

struct mg_app {
    mg_host_config_t config;
    mg_host_link_t link;
    mg_task_if_t task;
    int32_t n_detectors;
    mg_detector_t detectors[MG_MAX_DETECTORS];
    int64_t now_us;
    char state[32];
    int32_t finished;
    int64_t next_tick_us, ctrl_free_us;
    /* the vision job: start, end, the detectors' results, its ARM9 time */
    int32_t n_frames;
    mg_app_frame_t frames[MG_APP_FRAMES];
    int64_t frames_lost;
    int32_t vision_busy;
    int64_t job_seq, job_capture_us, job_start_us, job_done_us, job_arm9_us;
    uint32_t job_detectors;
    mg_detection_t job_results[MG_MAX_DETECTORS];
    int32_t has_detections;
    uint32_t detections_of;
    mg_detection_t detections[MG_MAX_DETECTORS];
    /* trace events since the last take, comma-separated JSON objects */
    char events[MG_EVENTS_BYTES];
    size_t events_len;
    int32_t n_events, events_lost;
    /* busy us per load window, the last MG_LOAD_WINDOWS_KEPT of them */
    int64_t load_index[MG_LOAD_WINDOWS_KEPT + 1], load_busy[MG_LOAD_WINDOWS_KEPT + 1];
    int32_t n_loads;
    int64_t folded_n, folded_busy, folded_peak_busy; /* windows folded: count, sum, max */
    int32_t last_has_servos, last_servos[6], last_has_gripper, last_gripper;
    int32_t last_has_wheels, last_wheels[2];
    int64_t last_wheels_us, last_heartbeat_us;
    int32_t hello_sent, resets_handled;
    int64_t first_tick_us; /* -1 before the first control tick */
    int32_t replans, plans;
    int32_t path_updates; /* a plan's detail with a replan: a new curve while one was followed */
    char close_reason[64]; /* the last grasp_close's JSON text ("" before any) */
    int32_t has_circle_error, circle_error_mm; /* 001: the first arrival on the grasp circle */
    int64_t frames_received, frames_processed, frames_dropped, frames_idle;
    int64_t control_steps, deadline_misses, ticks_skipped;
    int32_t n_stages;
    int64_t stage_overflow; /* calls past the histogram's top (2^31 us) */
    mg_stage_t stages[MG_STAGES];
};

void mg_app_init(mg_app_t *app, const mg_host_config_t *config, const mg_task_if_t *task,
                 const mg_detector_t *detectors, int32_t n_detectors);
void mg_app_on_uart(mg_app_t *app, const uint8_t *data, size_t n, int64_t arrival_us);
/* a frame the CAMIF delivered at arrival_us (rgb NULL: the camera was off); frames are given
 * in time order and before the advance_to that passes them */
void mg_app_on_frame(mg_app_t *app, int64_t seq, int64_t capture_us, int64_t arrival_us,
                     const uint8_t *rgb, int32_t w, int32_t h);
/* run everything due before until_us (the frames given so far included) */
void mg_app_advance_to(mg_app_t *app, int64_t until_us);
int mg_app_wants_frames(const mg_app_t *app);
int64_t mg_app_quiet_until_us(const mg_app_t *app);
/* the load windows finished before now and not reported yet since from_index: count */
int32_t mg_app_load_windows(const mg_app_t *app, int64_t from_index, int64_t *index,
                            int64_t *micro, int32_t max);
/* the trace events since the last take (comma-separated JSON objects): their count */
int32_t mg_app_take_events(mg_app_t *app, char *out, size_t cap, size_t *len);
/* the run's figures as a JSON object (host/app.py stats(): the counters, the ARM9 loads' maximum
 * and mean and the stages' calls, mean, 95th percentile, maximum and total, the means printed as
 * Python prints its integer ratios to the millionth): its length, 0 when cap is too small */
size_t mg_app_stats_json(const mg_app_t *app, char *out, size_t cap);

#endif
