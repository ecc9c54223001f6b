/* The host's protocol client (host/app_link.py) on the firmware's frame codec. */
#include "app_link.h"

#include <string.h>

#include "arm_calib.h"

void mg_link_init(mg_host_link_t *l, int64_t retransmit_timeout_us, int32_t max_retries)
{
    static const uint16_t power_on_us[MSG_SERVO_COUNT] = {1000, 1500, 1500, 1500, 1500, 1500};
    memset(l, 0, sizeof *l);
    frame_parser_reset(&l->parser);
    mg_rt_init(&l->reliable, retransmit_timeout_us, max_retries);
    l->telemetry_us = -1;
    l->hello_seq = -1;
    mg_watch_init(&l->watch);
    l->latest_servos_seq = l->latest_gripper_seq = -1;
    /* the MCU's power-on pose (docs/firmware.md "Reset") until a readable pulse is seen */
    memcpy(l->readable_pulses_us, power_on_us, sizeof power_on_us);
}

static mg_link_event_t *event(mg_host_link_t *l, int32_t kind, int64_t t_us)
{
    static mg_link_event_t lost;
    if (l->n_events >= MG_LINK_EVENTS) {
        l->events_dropped++;
        return &lost;
    }
    mg_link_event_t *e = &l->events[l->n_events++];
    memset(e, 0, sizeof *e);
    e->kind = kind;
    e->t_us = t_us;
    return e;
}

static void set_text(mg_link_event_t *e, const uint8_t *p, size_t n)
{
    n = n < sizeof e->text - 1 ? n : sizeof e->text - 1;
    memcpy(e->text, p, n);
    e->text[n] = 0;
}

/* every servo pulse the joint table can read (500..2500 us); another keeps the newest readable
 * one and the frame is counted in odd_telemetry (host/app_link.py _readable) */
static void readable(mg_host_link_t *l, mg_telemetry_t *t)
{
    int odd = 0;
    for (unsigned ch = 0; ch < MSG_SERVO_COUNT; ch++)
        if (t->servo_us[ch] < MSG_PULSE_MIN_US || t->servo_us[ch] > MSG_PULSE_MAX_US)
            odd = 1;
    if (odd) {
        l->counters.odd_telemetry++;
        for (unsigned ch = 0; ch < MSG_SERVO_COUNT; ch++)
            if (t->servo_us[ch] < MSG_PULSE_MIN_US || t->servo_us[ch] > MSG_PULSE_MAX_US)
                t->servo_us[ch] = l->readable_pulses_us[ch];
    }
    memcpy(l->readable_pulses_us, t->servo_us, sizeof t->servo_us);
}

static void telemetry(mg_host_link_t *l, const uint8_t *p, int64_t t_us)
{
    mg_telemetry_t t;
    t.time_us = get_u32(p);
    t.enc_left = get_i32(p + 4);
    t.enc_right = get_i32(p + 8);
    for (unsigned ch = 0; ch < MSG_SERVO_COUNT; ch++)
        t.servo_us[ch] = get_u16(p + 12 + 2 * ch);
    for (unsigned k = 0; k < MSG_SONAR_COUNT; k++)
        t.sonar_mm[k] = get_u16(p + 24 + 2 * k);
    t.flags = get_u16(p + 34);
    t.crc_errors = get_u16(p + 36);
    t.overruns = get_u16(p + 38);
    t.limit_hits = get_u16(p + 40);
    t.watchdog_trips = get_u16(p + 42);
    readable(l, &t);
    l->telemetry = t;
    l->has_telemetry = 1;
    l->telemetry_us = t_us;
    l->counters.telemetry++;
    const int32_t why = mg_watch_feed(&l->watch, t.time_us, t.flags);
    if (why != MG_WATCH_OK) { /* the MCU reset and forgot the session: HELLO again */
        l->mcu_resets++;
        l->handshake_ok = 0;
        mg_rt_clear(&l->reliable);
        l->latest_servos_seq = l->latest_gripper_seq = -1;
        const char *name = mg_watch_reason_name(why);
        set_text(event(l, MG_EV_MCU_RESET_SEEN, t_us), (const uint8_t *)name, strlen(name));
    }
}

static void dispatch(mg_host_link_t *l, uint8_t type, const uint8_t *p, uint8_t n, int64_t t_us)
{
    switch (type) {
    case MSG_TELEMETRY:
        telemetry(l, p, t_us);
        break;
    case MSG_ACK:
        /* only HELLO_ACK opens the session: the ACK of a HELLO leaves it to be retransmitted
         * until then (a lost HELLO_ACK) */
        if ((int32_t)p[0] != l->hello_seq || l->handshake_ok)
            mg_rt_ack(&l->reliable, p[0]);
        break;
    case MSG_NACK:
        if (mg_rt_ack(&l->reliable, p[0])) {
            l->counters.nacks++;
            mg_link_event_t *e = event(l, MG_EV_NACK, t_us);
            e->seq = p[0];
            e->code = p[1];
        }
        break;
    case MSG_HELLO_ACK: {
        if (l->hello_seq >= 0)
            mg_rt_ack(&l->reliable, (uint8_t)l->hello_seq);
        l->handshake_ok = p[0] == PROTOCOL_VERSION;
        if (l->handshake_ok)
            mg_watch_handshake_done(&l->watch);
        mg_link_event_t *e = event(l, MG_EV_HELLO_ACK, t_us);
        set_text(e, p + 3, (size_t)(n - 3));
        e->ok = l->handshake_ok;
        break;
    }
    case MSG_LOG: {
        mg_link_event_t *e = event(l, MG_EV_MCU_LOG, t_us);
        e->code = get_u16(p);
        set_text(e, p + 2, (size_t)(n - 2));
        break;
    }
    default:
        break;
    }
}

void mg_link_receive(mg_host_link_t *l, const uint8_t *data, size_t n, int64_t arrival_us)
{
    l->counters.rx_bytes += (uint32_t)n;
    l->rx_bytes_since_take += (uint32_t)n;
    for (size_t i = 0; i < n; i++) {
        const uint8_t got = frame_parser_feed(&l->parser, data[i]);
        if (!got)
            continue;
        const uint8_t len = (uint8_t)(got - 1), type = frame_type(&l->parser);
        if (msg_check(type, frame_data(&l->parser), len) != 0) {
            l->counters.decode_errors++;
            continue;
        }
        l->counters.rx_frames++;
        dispatch(l, type, frame_data(&l->parser), len, arrival_us);
    }
}

static int queue(mg_host_link_t *l, const uint8_t *wire, uint8_t len, int64_t at_us)
{
    if (l->n_out >= MG_OUTBOX_CHUNKS) {
        l->outbox_dropped++;
        return 0;
    }
    mg_wire_chunk_t *c = &l->outbox[l->n_out++];
    c->at_us = at_us;
    c->len = len;
    memcpy(c->wire, wire, len);
    l->counters.tx_frames++;
    l->counters.tx_bytes += len;
    return 1;
}

int32_t mg_link_send(mg_host_link_t *l, uint8_t type, const uint8_t *payload, uint8_t n,
                     int64_t at_us)
{
    const int reliable = msg_is_reliable(type);
    if (l->n_out >= MG_OUTBOX_CHUNKS || (reliable && l->reliable.n >= MG_RT_SLOTS)) {
        l->outbox_dropped++;
        return -1;
    }
    uint8_t seq = l->next_seq++;
    while (reliable && mg_rt_contains(&l->reliable, seq))
        seq = l->next_seq++; /* never reuse a seq still waiting for its answer */
    uint8_t wire[FRAME_MAX_WIRE];
    if (n > 0)
        memcpy(frame_payload(wire), payload, n);
    const uint8_t len = frame_finish(wire, seq, type, n);
    if (reliable) {
        /* a newer SetServos / Gripper supersedes an unanswered older one: a late retransmission
         * of the old command must never execute after the new one */
        int32_t *latest = type == MSG_SET_SERVOS ? &l->latest_servos_seq
                          : type == MSG_GRIPPER  ? &l->latest_gripper_seq
                                                 : NULL;
        if (latest) {
            if (*latest >= 0)
                mg_rt_cancel(&l->reliable, (uint8_t)*latest);
            *latest = seq;
        }
        mg_rt_track(&l->reliable, seq, wire, len, at_us);
    }
    queue(l, wire, len, at_us);
    return seq;
}

int mg_link_needs_hello(const mg_host_link_t *l)
{
    return !l->handshake_ok
           && (l->hello_seq < 0 || !mg_rt_contains(&l->reliable, (uint8_t)l->hello_seq));
}

void mg_link_hello(mg_host_link_t *l, int64_t at_us)
{
    uint8_t p[3 + MSG_ID_MAX_CHARS];
    const size_t id = strlen(MG_HOST_ID);
    p[0] = PROTOCOL_VERSION;
    put_u16(p + 1, 0); /* capabilities */
    memcpy(p + 3, MG_HOST_ID, id);
    l->hello_seq = mg_link_send(l, MSG_HELLO, p, (uint8_t)(3 + id), at_us);
}

void mg_link_service(mg_host_link_t *l, int64_t now_us)
{
    int32_t due[MG_RT_SLOTS];
    const int32_t n = mg_rt_due(&l->reliable, now_us, due);
    for (int32_t i = 0; i < n; i++) {
        const mg_rt_slot_t *s = &l->reliable.slot[due[i]];
        l->counters.retransmits++;
        queue(l, s->wire, s->len, now_us);
    }
    uint8_t failed[MG_RT_SLOTS];
    const int32_t n_failed = mg_rt_failed(&l->reliable, failed);
    for (int32_t i = 0; i < n_failed; i++) {
        l->counters.reliable_failed++;
        event(l, MG_EV_RELIABLE_FAILED, now_us)->seq = failed[i];
    }
}

int32_t mg_link_take_output(mg_host_link_t *l, int64_t before_us, mg_wire_chunk_t *out,
                            int32_t max)
{
    /* stable insertion sort by send time (a few chunks), then the due prefix */
    for (int32_t i = 1; i < l->n_out; i++) {
        if (l->outbox[i].at_us >= l->outbox[i - 1].at_us)
            continue;
        mg_wire_chunk_t c = l->outbox[i];
        int32_t j = i;
        while (j > 0 && l->outbox[j - 1].at_us > c.at_us) {
            l->outbox[j] = l->outbox[j - 1];
            j--;
        }
        l->outbox[j] = c;
    }
    int32_t n = 0;
    while (n < l->n_out && n < max && l->outbox[n].at_us < before_us) {
        out[n] = l->outbox[n];
        n++;
    }
    memmove(l->outbox, l->outbox + n, (size_t)(l->n_out - n) * sizeof l->outbox[0]);
    l->n_out -= n;
    return n;
}

int64_t mg_link_next_send_us(const mg_host_link_t *l)
{
    int64_t best = -1;
    for (int32_t i = 0; i < l->n_out; i++)
        if (best < 0 || l->outbox[i].at_us < best)
            best = l->outbox[i].at_us;
    return best;
}

int32_t mg_link_take_events(mg_host_link_t *l, mg_link_event_t *out, int32_t max)
{
    const int32_t n = l->n_events < max ? l->n_events : max;
    memcpy(out, l->events, (size_t)n * sizeof out[0]);
    memmove(l->events, l->events + n, (size_t)(l->n_events - n) * sizeof out[0]);
    l->n_events -= n;
    return n;
}

static int32_t clamp(int32_t v, int32_t lo, int32_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static int send_servos(mg_host_link_t *l, const int16_t targets[MSG_SERVO_COUNT], uint16_t slew,
                       int64_t at_us)
{
    uint8_t p[15];
    p[0] = SERVO_MODE_MRAD;
    for (unsigned ch = 0; ch < MSG_SERVO_COUNT; ch++)
        put_u16(p + 1 + 2 * ch, (uint16_t)targets[ch]);
    put_u16(p + 13, slew);
    if (mg_link_send(l, MSG_SET_SERVOS, p, sizeof p, at_us) < 0)
        return 0;
    memcpy(l->last_servos, targets, sizeof l->last_servos);
    l->last_slew = slew;
    l->has_last_servos = 1;
    return 1;
}

int mg_link_send_servos_mrad(mg_host_link_t *l, const int32_t joints_mrad[MSG_SERVO_COUNT],
                             int64_t at_us, uint16_t slew_mrad_s)
{
    int16_t targets[MSG_SERVO_COUNT];
    int clamped = 0;
    targets[0] = (int16_t)l->gripper_permille; /* the gripper is not disturbed */
    for (int32_t ch = 1; ch < (int32_t)MSG_SERVO_COUNT; ch++) {
        const int32_t v = mg_clamp_mrad(ch, joints_mrad[ch]);
        clamped |= v != joints_mrad[ch];
        targets[ch] = (int16_t)v;
    }
    if (clamped)
        l->counters.clamped_outputs++;
    return send_servos(l, targets, slew_mrad_s, at_us);
}

int mg_link_send_wheels(mg_host_link_t *l, int32_t left_mmps, int32_t right_mmps,
                        int64_t at_us)
{
    const int32_t lim = MSG_WHEEL_LIMIT_MMPS;
    const int32_t cl = clamp(left_mmps, -lim, lim), cr = clamp(right_mmps, -lim, lim);
    if (cl != left_mmps || cr != right_mmps)
        l->counters.clamped_outputs++;
    uint8_t p[4];
    put_u16(p, (uint16_t)(int16_t)cl);
    put_u16(p + 2, (uint16_t)(int16_t)cr);
    return mg_link_send(l, MSG_SET_WHEELS, p, sizeof p, at_us) >= 0;
}

int mg_link_send_gripper(mg_host_link_t *l, int32_t close_permille, int64_t at_us)
{
    const int32_t value = clamp(close_permille, 0, (int32_t)MSG_GRIPPER_MAX);
    uint8_t p[2];
    put_u16(p, (uint16_t)value);
    l->gripper_permille = value;
    if (mg_link_send(l, MSG_GRIPPER, p, sizeof p, at_us) < 0)
        return 0;
    /* an unanswered SetServos carries the old gripper value on channel 0: a late
     * retransmission of it would open the gripper again, so it is sent again with the new
     * value (as the newer SetServos it cancels the old one) */
    if (l->has_last_servos && l->latest_servos_seq >= 0
        && mg_rt_contains(&l->reliable, (uint8_t)l->latest_servos_seq)
        && l->last_servos[0] != value) {
        int16_t targets[MSG_SERVO_COUNT];
        memcpy(targets, l->last_servos, sizeof targets);
        targets[0] = (int16_t)value;
        send_servos(l, targets, l->last_slew, at_us);
    }
    return 1;
}

void mg_link_send_heartbeat(mg_host_link_t *l, int64_t at_us)
{
    uint8_t p[4];
    put_u32(p, (uint32_t)at_us);
    mg_link_send(l, MSG_HEARTBEAT, p, sizeof p, at_us);
}

void mg_link_send_stop(mg_host_link_t *l, int64_t at_us)
{
    mg_link_send(l, MSG_STOP, NULL, 0, at_us);
}
