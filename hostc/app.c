/* The host program's main loop and its ARM9 time budget (host/app.py). */
#include "app.h"

#include <string.h>

#include "json.h"

#define FCLK_MHZ 400 /* cycles -> us: cycles * 10^6 / 400 MHz */

void mg_host_config_default(mg_host_config_t *c)
{
    c->control_period_us = 20000;
    c->heartbeat_period_us = 100000;
    c->hello_wait_us = 100000;
    c->wheels_repeat_us = 100000;
    c->load_window_us = 500000;
    c->control_base_cycles = 22000;
    c->handover_cycles = 12000;
    c->protocol_cycles_per_byte = 40;
    c->frame_overhead_cycles = 20000;
    c->servo_slew_mrad_s = 0;
}

void mg_app_init(mg_app_t *app, const mg_host_config_t *config, const mg_task_if_t *task,
                 const mg_detector_t *detectors, int32_t n_detectors)
{
    memset(app, 0, sizeof *app);
    app->config = *config;
    app->first_tick_us = -1;
    mg_link_init(&app->link, 40000, 10);
    app->task = *task;
    app->n_detectors = n_detectors < MG_MAX_DETECTORS ? n_detectors : MG_MAX_DETECTORS;
    memcpy(app->detectors, detectors, (size_t)app->n_detectors * sizeof detectors[0]);
    memcpy(app->state, "INIT", 5);
    app->last_wheels_us = app->last_heartbeat_us = -1000000000000LL;
}

void mg_app_on_uart(mg_app_t *app, const uint8_t *data, size_t n, int64_t arrival_us)
{
    mg_link_receive(&app->link, data, n, arrival_us);
}

/* ---- events: JSON objects with their keys in sorted order, as the DONE's encoder sorts ---- */

/* an event is written in place, after the events already taken in (and the comma before it),
 * and kept only when it fits whole */
typedef struct {
    mg_json_t j;
    size_t at;
} event_t;

static void event_begin(mg_app_t *app, event_t *e)
{
    e->at = app->events_len + (app->n_events > 0);
    const size_t room = e->at < sizeof app->events ? sizeof app->events - e->at : 0;
    mg_json_init(&e->j, app->events + (e->at < sizeof app->events ? e->at : 0), room);
    e->j.overflow = room == 0;
    mg_json_begin_object(&e->j);
}

static void event_end(mg_app_t *app, event_t *e)
{
    mg_json_end_object(&e->j);
    if (e->j.overflow) {
        app->events_lost++;
        return;
    }
    if (app->n_events > 0)
        app->events[app->events_len] = ',';
    app->events_len = e->at + e->j.len;
    app->n_events++;
}

static void key_int(event_t *e, const char *k, int64_t v)
{
    mg_json_key(&e->j, k);
    mg_json_int(&e->j, v);
}

static void key_str(event_t *e, const char *k, const char *v)
{
    mg_json_key(&e->j, k);
    mg_json_string(&e->j, v, strlen(v));
}

static void key_ev(event_t *e, const char *name)
{
    key_str(e, "ev", name);
}

/* ---- the ARM9 time ---- */

static mg_stage_t *stage(mg_app_t *app, const char *name)
{
    for (int32_t i = 0; i < app->n_stages; i++)
        if (strcmp(app->stages[i].name, name) == 0)
            return &app->stages[i];
    if (app->n_stages >= (int32_t)(sizeof app->stages / sizeof app->stages[0]))
        return NULL;
    mg_stage_t *s = &app->stages[app->n_stages++];
    s->name = name;
    return s;
}

/* the windows before the MG_LOAD_WINDOWS_KEPT up to window newest are folded into the running
 * count, sum and maximum, in window order (at most MG_LOAD_WINDOWS_KEPT are kept) */
static void fold_old_loads(mg_app_t *app, int64_t newest)
{
    const int64_t limit = newest - MG_LOAD_WINDOWS_KEPT + 1;
    int32_t kept = 0;
    for (int32_t i = 0; i < app->n_loads; i++) {
        if (app->load_index[i] < limit) {
            app->folded_n++;
            app->folded_busy += app->load_busy[i];
            if (app->load_busy[i] > app->folded_peak_busy)
                app->folded_peak_busy = app->load_busy[i];
        } else {
            app->load_index[kept] = app->load_index[i];
            app->load_busy[kept++] = app->load_busy[i];
        }
    }
    app->n_loads = kept;
}

/* the histogram bucket of us (host/stage_stats.py bucket_of): itself below 2048, else its 11
 * leading bits, 1024 buckets per power of two */
static int32_t bucket_index(int64_t us)
{
    if (us < MG_STAGE_EXACT_US)
        return us < 0 ? 0 : (int32_t)us;
    int32_t bits = 0;
    for (int64_t v = us; v != 0; v >>= 1)
        bits++;
    const int32_t octave = bits - 12; /* 2048 has 12 bits */
    if (octave >= MG_STAGE_OCTAVES)
        return MG_STAGE_BUCKETS - 1;
    return MG_STAGE_EXACT_US + octave * 1024 + (int32_t)((us >> (octave + 1)) - 1024);
}

static int64_t bucket_us(int32_t index)
{
    if (index < MG_STAGE_EXACT_US)
        return index;
    const int32_t octave = (index - MG_STAGE_EXACT_US) / 1024;
    return (int64_t)(1024 + (index - MG_STAGE_EXACT_US) % 1024) << (octave + 1);
}

/* the nearest-rank 95th percentile, its bucket's value (StageStats.p95_us) */
static int64_t stage_p95_us(const mg_stage_t *s)
{
    const int64_t rank = (95 * s->calls + 99) / 100; /* ceil(0.95 calls), calls > 0 */
    int64_t seen = 0;
    for (int32_t i = 0; i < MG_STAGE_BUCKETS; i++) {
        seen += s->counts[i];
        if (seen >= (rank > 1 ? rank : 1))
            return bucket_us(i);
    }
    return s->max_us;
}

/* num / den to the millionth, rounded half up (host/stage_stats.py micro_ratio) */
static int64_t micro_ratio(int64_t num, int64_t den)
{
    return (2 * num * 1000000 + den) / (2 * den);
}

static void busy(mg_app_t *app, int64_t start_us, int64_t dur_us, const char *name)
{
    mg_stage_t *s = stage(app, name);
    if (s != NULL) {
        s->calls++;
        s->total_us += dur_us;
        if (dur_us > s->max_us)
            s->max_us = dur_us;
        s->counts[bucket_index(dur_us)]++;
        if (dur_us >= (int64_t)1 << (MG_STAGE_OCTAVES + 11))
            app->stage_overflow++;
    }
    const int64_t w = app->config.load_window_us;
    for (int64_t t = start_us, end = start_us + dur_us; t < end;) {
        const int64_t k = t / w;
        const int64_t seg = ((k + 1) * w < end ? (k + 1) * w : end) - t;
        int32_t i = 0;
        while (i < app->n_loads && app->load_index[i] != k)
            i++;
        if (i < app->n_loads) {
            app->load_busy[i] += seg;
        } else { /* a new window (windows come in time order: kept sorted) */
            app->load_index[app->n_loads] = k;
            app->load_busy[app->n_loads++] = seg;
            if (app->n_loads > MG_LOAD_WINDOWS_KEPT)
                fold_old_loads(app, k);
        }
        t += seg;
    }
}

static int64_t cycles_us(int64_t cycles)
{
    return cycles / FCLK_MHZ; /* cycles * 10^6 / 400 MHz, floored */
}

/* ---- vision ---- */

static uint32_t needed_detectors(const mg_app_t *app)
{
    const uint32_t all = app->n_detectors >= 32 ? 0xFFFFFFFFu : (1u << app->n_detectors) - 1u;
    return app->task.detectors_needed(app->task.ctx) & all;
}

static void finish_vision(mg_app_t *app, int64_t now_us)
{
    if (!app->vision_busy || app->job_done_us > now_us)
        return;
    app->vision_busy = 0;
    app->has_detections = 1;
    app->detections_of = app->job_detectors;
    /* the task reads the slots of the detectors that ran (present), before the next job
     * writes job_results again: only those are handed over */
    for (int32_t i = 0; i < app->n_detectors; i++)
        if (app->job_detectors >> i & 1u)
            memcpy(&app->detections[i], &app->job_results[i], sizeof app->detections[i]);
    event_t e;
    event_begin(app, &e);
    key_int(&e, "arm9_us", app->job_arm9_us);
    key_int(&e, "capture_us", app->job_capture_us);
    key_ev(&e, "detect");
    mg_json_key(&e.j, "results");
    mg_json_begin_object(&e.j);
    /* the results by detector name, in sorted order */
    uint32_t left = app->job_detectors;
    while (left) {
        int32_t pick = -1;
        for (int32_t i = 0; i < app->n_detectors; i++)
            if ((left >> i & 1u)
                && (pick < 0 || strcmp(app->detectors[i].name, app->detectors[pick].name) < 0))
                pick = i;
        left &= ~(1u << pick);
        mg_json_key(&e.j, app->detectors[pick].name);
        const char *r = app->job_results[pick].found ? app->job_results[pick].json : "null";
        mg_json_raw(&e.j, r, strlen(r));
    }
    mg_json_end_object(&e.j);
    key_int(&e, "seq", app->job_seq);
    key_int(&e, "t_us", app->job_done_us);
    event_end(app, &e);
}

static void frame(mg_app_t *app, int64_t seq, int64_t capture_us, int64_t arrival_us,
                  const uint8_t *rgb, int32_t w, int32_t h)
{
    app->frames_received++;
    if (app->vision_busy && app->job_done_us > arrival_us) {
        app->frames_dropped++; /* vision still busy: the frame is dropped, as on the board */
        event_t e;
        event_begin(app, &e);
        key_int(&e, "busy_until_us", app->job_done_us);
        key_ev(&e, "frame_dropped");
        key_int(&e, "seq", seq);
        key_int(&e, "t_us", arrival_us);
        event_end(app, &e);
        return;
    }
    finish_vision(app, arrival_us);
    const uint32_t needed = needed_detectors(app);
    if (!needed || rgb == NULL) { /* nothing to look for, or the camera was off */
        app->frames_idle++;
        return;
    }
    const int64_t start = arrival_us > app->ctrl_free_us ? arrival_us : app->ctrl_free_us;
    int64_t total = cycles_us(app->config.frame_overhead_cycles);
    busy(app, start, total, "frame");
    app->frames_processed++;
    /* the detectors run now: the pose they read is the one the frame arrived with, so when
     * they run changes nothing that is modelled; a fallback runs only when what it stands in
     * for found nothing on this frame; a front end computed already is reused, not
     * computed or paid again */
    uint32_t ran = 0, front_ends_done = 0;
    for (int32_t i = 0; i < app->n_detectors; i++) {
        if (!(needed >> i & 1u))
            continue;
        const int32_t primary = app->task.fallback_of ? app->task.fallback_of(app->task.ctx, i)
                                                      : -1;
        if (primary >= 0 && primary < app->n_detectors && (ran >> primary & 1u)
            && app->job_results[primary].found)
            continue;
        const mg_detector_t *d = &app->detectors[i];
        int32_t snap[8] = {0};
        if (d->snapshot != NULL)
            d->snapshot(d->ctx, snap);
        mg_detection_t *r = &app->job_results[i];
        memset(r, 0, sizeof *r);
        const int32_t shared = d->front_end > 0 && d->front_end < 32;
        const int32_t ready = shared && (front_ends_done >> d->front_end & 1u);
        d->detect(d->ctx, rgb, w, h, snap, ready, r);
        int64_t dur = mg_ops_time_us(&r->ops);
        if (ready) {
            dur -= d->front_end_us(h, w);
            dur = dur > 0 ? dur : 0;
        } else if (shared) {
            front_ends_done |= 1u << d->front_end;
        }
        busy(app, start + total, dur, d->name);
        total += dur;
        ran |= 1u << i;
    }
    app->vision_busy = 1;
    app->job_seq = seq;
    app->job_capture_us = capture_us;
    app->job_start_us = start;
    app->job_arm9_us = total;
    app->job_done_us = start + total;
    app->job_detectors = ran;
}

/* ---- control ---- */

static int same6(const int32_t *a, const int32_t *b)
{
    return memcmp(a, b, 6 * sizeof a[0]) == 0;
}

/* the arrival's error_mm in 001's grasp_circle detail (an object; host/app.py keeps the first
 * one's): 1 and its value, or 0 */
static int circle_error(const char *json, size_t n, int32_t *error_mm)
{
    mg_json_in_t in;
    char key[32];
    int first = 1;
    mg_json_in_init(&in, json, n);
    if (!mg_json_begin_object_in(&in))
        return 0;
    while (mg_json_next_member(&in, &first, key, sizeof key) == 1) {
        if (strcmp(key, "error_mm") != 0) {
            if (!mg_json_skip_value(&in))
                return 0;
            continue;
        }
        int64_t v;
        if (!mg_json_read_int(&in, &v) || v < INT32_MIN || v > INT32_MAX)
            return 0;
        *error_mm = (int32_t)v;
        return 1;
    }
    return 0;
}

static void apply(mg_app_t *app, const mg_task_output_t *out, int64_t at_us)
{
    mg_host_link_t *link = &app->link;
    for (int32_t i = 0; i < out->n_transitions && i < MG_TASK_TRANSITIONS; i++) {
        event_t e;
        event_begin(app, &e);
        key_ev(&e, "state");
        key_str(&e, "from", out->transitions[i].from);
        key_int(&e, "t_us", out->transitions[i].t_us);
        key_str(&e, "to", out->transitions[i].to);
        key_str(&e, "why", out->transitions[i].why);
        event_end(app, &e);
    }
    if (out->state != NULL && strcmp(out->state, app->state) != 0) {
        const size_t n = strlen(out->state);
        const size_t m = n < sizeof app->state - 1 ? n : sizeof app->state - 1;
        memcpy(app->state, out->state, m);
        app->state[m] = 0;
    }
    if (out->n_detail > 0) {
        if (out->detail_has_plan) { /* every plan after the first is a replan (001 III.E) */
            app->plans++;
            app->replans = app->plans - 1 > 0 ? app->plans - 1 : 0;
        }
        for (int32_t i = 0; i < out->n_detail && i < MG_DETAIL_MEMBERS; i++) {
            const mg_json_member_t *d = &out->detail[i];
            if (strcmp(d->json, "null") == 0)
                continue; /* Python's "is not None" */
            if (out->detail_has_plan && strcmp(d->key, "replan") == 0)
                app->path_updates++;
            const size_t len = strlen(d->json);
            if (strcmp(d->key, "grasp_close") == 0 && len < sizeof app->close_reason)
                memcpy(app->close_reason, d->json, len + 1); /* a short name: fits */
            if (strcmp(d->key, "grasp_circle") == 0 && !app->has_circle_error)
                app->has_circle_error = circle_error(d->json, len, &app->circle_error_mm);
        }
        /* ev, state, t_us and the detail's members, all in sorted key order */
        mg_json_member_t m[MG_DETAIL_MEMBERS + 3];
        char t[24];
        mg_json_t jt;
        mg_json_init(&jt, t, sizeof t - 1);
        mg_json_int(&jt, at_us);
        t[jt.len] = 0;
        int32_t n = 0;
        m[n++] = (mg_json_member_t){"ev", "\"detail\""};
        m[n++] = (mg_json_member_t){"t_us", t};
        for (int32_t i = 0; i < out->n_detail && i < MG_DETAIL_MEMBERS; i++)
            m[n++] = out->detail[i];
        event_t e;
        event_begin(app, &e);
        int state_done = 0;
        for (int32_t k = 0; k <= n; k++) {
            int32_t pick = -1;
            for (int32_t i = 0; i < n; i++)
                if (m[i].key != NULL && (pick < 0 || strcmp(m[i].key, m[pick].key) < 0))
                    pick = i;
            if (!state_done && (pick < 0 || strcmp("state", m[pick].key) < 0)) {
                key_str(&e, "state", app->state);
                state_done = 1;
                k--;
                continue;
            }
            if (pick < 0)
                break;
            mg_json_key(&e.j, m[pick].key);
            mg_json_raw(&e.j, m[pick].json, strlen(m[pick].json));
            m[pick].key = NULL;
        }
        event_end(app, &e);
    }
    if (out->has_servos && (!app->last_has_servos || !same6(out->servo_mrad, app->last_servos))) {
        if (mg_link_send_servos_mrad(link, out->servo_mrad, at_us,
                                     app->config.servo_slew_mrad_s)) {
            memcpy(app->last_servos, out->servo_mrad, sizeof app->last_servos);
            app->last_has_servos = 1;
        }
    }
    if (out->has_gripper
        && (!app->last_has_gripper || out->gripper_permille != app->last_gripper)) {
        if (mg_link_send_gripper(link, out->gripper_permille, at_us)) {
            app->last_gripper = out->gripper_permille;
            app->last_has_gripper = 1;
        }
    }
    int32_t wheels[2];
    int has_wheels = out->has_wheels || app->last_has_wheels;
    if (out->has_wheels)
        wheels[0] = out->wheels_mmps[0], wheels[1] = out->wheels_mmps[1];
    else
        wheels[0] = app->last_wheels[0], wheels[1] = app->last_wheels[1];
    if (has_wheels) {
        const int changed = !app->last_has_wheels || wheels[0] != app->last_wheels[0]
                            || wheels[1] != app->last_wheels[1];
        if ((changed || at_us - app->last_wheels_us >= app->config.wheels_repeat_us)
            && mg_link_send_wheels(link, wheels[0], wheels[1], at_us)) {
            if (changed) {
                event_t e;
                event_begin(app, &e);
                key_ev(&e, "wheels");
                mg_json_key(&e.j, "mmps");
                mg_json_begin_array(&e.j);
                mg_json_int(&e.j, wheels[0]);
                mg_json_int(&e.j, wheels[1]);
                mg_json_end_array(&e.j);
                key_int(&e, "t_us", at_us);
                event_end(app, &e);
            }
            app->last_wheels[0] = wheels[0], app->last_wheels[1] = wheels[1];
            app->last_has_wheels = 1;
            app->last_wheels_us = at_us;
        }
    }
    if (strcmp(app->state, "DONE") == 0 || strcmp(app->state, "FAILED") == 0)
        app->finished = 1;
}

static void tick(mg_app_t *app, int64_t t_us)
{
    const mg_host_config_t *cfg = &app->config;
    if (app->ctrl_free_us >= t_us + cfg->control_period_us) {
        app->ticks_skipped++;
        app->deadline_misses++;
        event_t e;
        event_begin(app, &e);
        key_ev(&e, "deadline_miss");
        mg_json_key(&e.j, "skipped");
        mg_json_bool(&e.j, 1);
        key_int(&e, "t_us", t_us);
        event_end(app, &e);
        return;
    }
    const int64_t start = t_us > app->ctrl_free_us ? t_us : app->ctrl_free_us;
    finish_vision(app, start);
    mg_host_link_t *link = &app->link;
    const uint32_t tx_before = link->counters.tx_bytes;
    mg_link_service(link, start);
    if (app->first_tick_us < 0)
        app->first_tick_us = start;
    /* The first HELLO (and heartbeat) waits until the MCU has been heard (its telemetry: it is
     * listening), at most hello_wait_us: bytes sent into the MCU's start-up are lost
     * (docs/firmware.md, "simavr"). */
    const int first = !app->hello_sent && (link->has_telemetry
                                           || start - app->first_tick_us >= cfg->hello_wait_us);
    if (first || (app->hello_sent && link->mcu_resets > app->resets_handled
                  && mg_link_needs_hello(link))) {
        mg_link_hello(link, start); /* the first session, or again after the MCU reset */
        app->hello_sent = 1;
        app->resets_handled = link->mcu_resets;
        app->last_has_servos = app->last_has_gripper = app->last_has_wheels = 0; /* resend */
    }
    int64_t done;
    if (link->handshake_ok && link->has_telemetry && !app->finished) {
        static const int32_t none[MG_MAX_DETECTORS];
        int32_t present[MG_MAX_DETECTORS];
        for (int32_t i = 0; i < MG_MAX_DETECTORS; i++)
            present[i] = app->has_detections && (app->detections_of >> i & 1u);
        const int64_t handover = app->has_detections ? cfg->handover_cycles : 0;
        app->has_detections = 0;
        mg_task_output_t out;
        memset(&out, 0, sizeof out);
        app->task.step(app->task.ctx, app, start, app->detections,
                       app->n_detectors ? present : none, &out);
        app->control_steps++;
        done = start + cycles_us(cfg->control_base_cycles + handover) + mg_ops_time_us(&out.ops);
        apply(app, &out, done);
    } else {
        done = start + cycles_us(cfg->control_base_cycles);
    }
    if (app->hello_sent && done - app->last_heartbeat_us >= cfg->heartbeat_period_us) {
        mg_link_send_heartbeat(link, done);
        app->last_heartbeat_us = done;
    }
    const int64_t proto_bytes = (int64_t)link->rx_bytes_since_take
                                + (int64_t)(link->counters.tx_bytes - tx_before);
    link->rx_bytes_since_take = 0;
    const int64_t proto_us = cycles_us(proto_bytes * cfg->protocol_cycles_per_byte);
    busy(app, start, done - start, "control");
    busy(app, done, proto_us, "protocol");
    done += proto_us;
    if (done > t_us + cfg->control_period_us) {
        app->deadline_misses++;
        event_t e;
        event_begin(app, &e);
        key_int(&e, "done_us", done);
        key_ev(&e, "deadline_miss");
        key_int(&e, "t_us", t_us);
        event_end(app, &e);
    }
    if (app->vision_busy && app->job_start_us < done && app->job_done_us > start)
        app->job_done_us += done - start; /* control preempted vision for that long */
    app->ctrl_free_us = done;
}

void mg_app_on_frame(mg_app_t *app, int64_t seq, int64_t capture_us, int64_t arrival_us,
                     const uint8_t *rgb, int32_t w, int32_t h)
{
    if (app->n_frames >= MG_APP_FRAMES) {
        app->frames_lost++;
        return;
    }
    /* kept in (arrival, seq) order */
    int32_t i = app->n_frames++;
    while (i > 0 && (app->frames[i - 1].arrival_us > arrival_us
                     || (app->frames[i - 1].arrival_us == arrival_us
                         && app->frames[i - 1].seq > seq))) {
        app->frames[i] = app->frames[i - 1];
        i--;
    }
    app->frames[i] = (mg_app_frame_t){seq, capture_us, arrival_us, rgb, w, h};
}

void mg_app_advance_to(mg_app_t *app, int64_t until_us)
{
    for (;;) {
        const int has_frame = app->n_frames > 0;
        const int64_t t_frame = has_frame ? app->frames[0].arrival_us : 0;
        const int64_t t_tick = app->next_tick_us;
        if (t_tick < until_us && (!has_frame || t_tick <= t_frame)) {
            tick(app, t_tick);
            app->next_tick_us += app->config.control_period_us;
        } else if (has_frame && t_frame < until_us) {
            const mg_app_frame_t f = app->frames[0];
            memmove(app->frames, app->frames + 1, (size_t)--app->n_frames * sizeof f);
            frame(app, f.seq, f.capture_us, f.arrival_us, f.rgb, f.w, f.h);
        } else {
            break;
        }
    }
    if (until_us > app->now_us)
        app->now_us = until_us;
}

int mg_app_wants_frames(const mg_app_t *app)
{
    return needed_detectors(app) != 0;
}

int64_t mg_app_quiet_until_us(const mg_app_t *app)
{
    const int64_t nxt = mg_link_next_send_us(&app->link);
    return nxt < 0 || app->next_tick_us < nxt ? app->next_tick_us : nxt;
}

int32_t mg_app_load_windows(const mg_app_t *app, int64_t from_index, int64_t *index,
                            int64_t *micro, int32_t max)
{
    const int64_t w = app->config.load_window_us, done = app->now_us / w;
    int32_t n = 0;
    for (int32_t i = 0; i < app->n_loads && n < max; i++)
        if (app->load_index[i] >= from_index && app->load_index[i] < done) {
            index[n] = app->load_index[i];
            micro[n++] = app->load_busy[i] * (1000000 / w); /* busy / w in millionths */
        }
    return n;
}

/* the protocol client's events as JSON, after the program's (host/app.py take_events) */
static void link_event(mg_app_t *app, event_t *e, const mg_link_event_t *le)
{
    event_begin(app, e);
    switch (le->kind) {
    case MG_EV_MCU_RESET_SEEN:
        key_ev(e, "mcu_reset_seen");
        key_int(e, "t_us", le->t_us);
        key_str(e, "why", le->text);
        break;
    case MG_EV_NACK:
        key_ev(e, "nack");
        key_int(e, "reason", le->code);
        key_int(e, "seq", le->seq);
        key_int(e, "t_us", le->t_us);
        break;
    case MG_EV_HELLO_ACK:
        key_ev(e, "hello_ack");
        key_str(e, "firmware_id", le->text);
        mg_json_key(&e->j, "ok");
        mg_json_bool(&e->j, le->ok);
        key_int(e, "t_us", le->t_us);
        break;
    case MG_EV_MCU_LOG:
        key_int(e, "code", le->code);
        key_ev(e, "mcu_log");
        key_int(e, "t_us", le->t_us);
        key_str(e, "text", le->text);
        break;
    default:
        key_ev(e, "reliable_failed");
        key_int(e, "seq", le->seq);
        key_int(e, "t_us", le->t_us);
        break;
    }
}

int32_t mg_app_take_events(mg_app_t *app, char *out, size_t cap, size_t *len)
{
    mg_link_event_t le[MG_LINK_EVENTS];
    const int32_t n_link = mg_link_take_events(&app->link, le, MG_LINK_EVENTS);
    for (int32_t i = 0; i < n_link; i++) {
        event_t e;
        link_event(app, &e, &le[i]);
        event_end(app, &e);
    }
    const int32_t n = app->n_events;
    *len = 0;
    if (app->events_len <= cap) {
        memcpy(out, app->events, app->events_len);
        *len = app->events_len;
    } else {
        app->events_lost += n;
    }
    app->events_len = 0;
    app->n_events = 0;
    return *len ? n : 0;
}

size_t mg_app_stats_json(const mg_app_t *app, char *out, size_t cap)
{
    /* the figures of host/app.py stats(), keys sorted; the loads in millionths */
    const int64_t w = app->config.load_window_us;
    int64_t n = app->folded_n, total = app->folded_busy, peak = app->folded_peak_busy;
    for (int32_t i = 0; i < app->n_loads; i++)
        if (app->load_index[i] < app->now_us / w) { /* the finished windows kept */
            n++;
            total += app->load_busy[i];
            if (app->load_busy[i] > peak)
                peak = app->load_busy[i];
        }
    mg_json_t j;
    mg_json_init(&j, out, cap);
    mg_json_begin_object(&j);
    mg_json_key(&j, "arm9_load_max");
    mg_json_micro(&j, micro_ratio(peak, w));
    mg_json_key(&j, "arm9_load_mean");
    mg_json_micro(&j, n ? micro_ratio(total, n * w) : 0);
    mg_json_key(&j, "circle_error_mm");
    if (app->has_circle_error)
        mg_json_int(&j, app->circle_error_mm);
    else
        mg_json_null(&j);
    mg_json_key(&j, "close_reason");
    if (app->close_reason[0])
        mg_json_raw(&j, app->close_reason, strlen(app->close_reason));
    else
        mg_json_null(&j);
    mg_json_key(&j, "control_steps");
    mg_json_int(&j, app->control_steps);
    mg_json_key(&j, "deadline_misses");
    mg_json_int(&j, app->deadline_misses);
    mg_json_key(&j, "frames_dropped");
    mg_json_int(&j, app->frames_dropped);
    mg_json_key(&j, "frames_idle");
    mg_json_int(&j, app->frames_idle);
    mg_json_key(&j, "frames_processed");
    mg_json_int(&j, app->frames_processed);
    mg_json_key(&j, "frames_received");
    mg_json_int(&j, app->frames_received);
    mg_json_key(&j, "mcu"); /* the MCU's counters in its newest telemetry */
    mg_json_begin_object(&j);
    if (app->link.has_telemetry) {
        const mg_telemetry_t *tel = &app->link.telemetry;
        mg_json_key(&j, "crc_errors");
        mg_json_int(&j, tel->crc_errors);
        mg_json_key(&j, "limit_hits");
        mg_json_int(&j, tel->limit_hits);
        mg_json_key(&j, "overruns");
        mg_json_int(&j, tel->overruns);
        mg_json_key(&j, "watchdog_trips");
        mg_json_int(&j, tel->watchdog_trips);
    }
    mg_json_end_object(&j);
    mg_json_key(&j, "mcu_resets_seen");
    mg_json_int(&j, app->link.mcu_resets);
    mg_json_key(&j, "path_updates");
    mg_json_int(&j, app->path_updates);
    /* host/app_link.py stats(): the link's counters and the parser's CRC errors (keys sorted) */
    const mg_link_counters_t *c = &app->link.counters;
    const struct {
        const char *key;
        int64_t value;
    } proto[] = {{"clamped_outputs", c->clamped_outputs},
                 {"crc_errors", app->link.parser.stats.crc_errors},
                 {"decode_errors", c->decode_errors}, {"nacks", c->nacks},
                 {"odd_telemetry", c->odd_telemetry}, {"rejected_outputs", c->rejected_outputs},
                 {"reliable_failed", c->reliable_failed}, {"retransmits", c->retransmits},
                 {"rx_bytes", c->rx_bytes}, {"rx_frames", c->rx_frames},
                 {"telemetry", c->telemetry}, {"tx_bytes", c->tx_bytes},
                 {"tx_frames", c->tx_frames}};
    mg_json_key(&j, "protocol");
    mg_json_begin_object(&j);
    for (size_t i = 0; i < sizeof proto / sizeof proto[0]; i++) {
        mg_json_key(&j, proto[i].key);
        mg_json_int(&j, proto[i].value);
    }
    mg_json_end_object(&j);
    mg_json_key(&j, "replans");
    mg_json_int(&j, app->replans);
    mg_json_key(&j, "stage_overflow");
    mg_json_int(&j, app->stage_overflow);
    /* the stages by name: calls, max, mean, p95 and total of their modelled us per call */
    int32_t order[MG_STAGES];
    for (int32_t i = 0; i < app->n_stages; i++) {
        int32_t k = i;
        while (k > 0 && strcmp(app->stages[order[k - 1]].name, app->stages[i].name) > 0) {
            order[k] = order[k - 1];
            k--;
        }
        order[k] = i;
    }
    mg_json_key(&j, "stages");
    mg_json_begin_object(&j);
    for (int32_t i = 0; i < app->n_stages; i++) {
        const mg_stage_t *s = &app->stages[order[i]];
        mg_json_key(&j, s->name);
        mg_json_begin_object(&j);
        mg_json_key(&j, "calls");
        mg_json_int(&j, s->calls);
        mg_json_key(&j, "max_us");
        mg_json_int(&j, s->max_us);
        mg_json_key(&j, "mean_us");
        mg_json_micro(&j, micro_ratio(s->total_us, s->calls)); /* calls > 0: made by a call */
        mg_json_key(&j, "p95_us");
        mg_json_int(&j, stage_p95_us(s));
        mg_json_key(&j, "total_us");
        mg_json_int(&j, s->total_us);
        mg_json_end_object(&j);
    }
    mg_json_end_object(&j);
    mg_json_key(&j, "state");
    mg_json_string(&j, app->state, strlen(app->state));
    mg_json_key(&j, "ticks_skipped");
    mg_json_int(&j, app->ticks_skipped);
    mg_json_end_object(&j);
    return j.overflow ? 0 : j.len;
}
