/* The host program's side of the serial protocol (host/app_link.py): handshake, heartbeat,
 * reliable commands with retransmission, telemetry. No I/O and no clock: bytes come in with
 * their arrival time, outgoing wire chunks are queued with the time the host finished producing
 * them, and the driver moves them between this and the serial port. The frame parser and the
 * message checks are the firmware's (firmware/protocol/): one codec for both boards.
 *
 * Every command is clamped to its limits before it is encoded (servo targets to the joint
 * table, wheels to +-1000 mm/s, the gripper to 0..1000 per mille) and counted when clamped; the
 * Python host's refusals of NaN, infinity and non-integers (host/outgoing_guard.py) have no
 * counterpart here, where every value is an integer by type. */
#ifndef MOBIGRASP_HOSTC_APP_LINK_H
#define MOBIGRASP_HOSTC_APP_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "frame.h"
#include "mcu_watch.h"
#include "messages.h"
#include "retransmit.h"

#define MG_HOST_ID "mobigrasp-2440" /* at most 16 ASCII chars */
#define MG_OUTBOX_CHUNKS 48         /* wire chunks queued and not yet taken */
#define MG_LINK_EVENTS 32           /* events not yet taken; more are counted in dropped */

typedef struct {
    uint32_t time_us;
    int32_t enc_left, enc_right;
    uint16_t servo_us[MSG_SERVO_COUNT];
    uint16_t sonar_mm[MSG_SONAR_COUNT];
    uint16_t flags, crc_errors, overruns, limit_hits, watchdog_trips;
} mg_telemetry_t;

/* host/app_link.py LinkCounters, in its order */
typedef struct {
    uint32_t tx_frames, tx_bytes, rx_frames, rx_bytes, decode_errors, retransmits,
        reliable_failed, nacks, rejected_outputs, clamped_outputs, telemetry, odd_telemetry;
} mg_link_counters_t;

enum {
    MG_EV_MCU_RESET_SEEN = 1, /* text: why (mcu_watch.h) */
    MG_EV_NACK = 2,           /* seq, code: the reason */
    MG_EV_HELLO_ACK = 3,      /* text: firmware id, ok */
    MG_EV_MCU_LOG = 4,        /* code, text */
    MG_EV_RELIABLE_FAILED = 5 /* seq */
};

typedef struct {
    int32_t kind;
    int64_t t_us;
    int32_t seq, code, ok;
    char text[MSG_LOG_MAX_CHARS + 1];
} mg_link_event_t;

typedef struct {
    int64_t at_us;
    uint8_t len;
    uint8_t wire[FRAME_MAX_WIRE];
} mg_wire_chunk_t;

typedef struct {
    frame_parser_t parser;
    uint8_t next_seq;
    mg_retransmit_t reliable;
    mg_link_counters_t counters;
    int32_t has_telemetry;
    mg_telemetry_t telemetry;
    int64_t telemetry_us; /* -1 before the first */
    int32_t handshake_ok;
    int32_t hello_seq; /* -1: no HELLO sent */
    int32_t n_out;
    mg_wire_chunk_t outbox[MG_OUTBOX_CHUNKS];
    uint32_t outbox_dropped; /* chunks refused by a full outbox */
    int32_t n_events;
    mg_link_event_t events[MG_LINK_EVENTS];
    uint32_t events_dropped;
    uint32_t rx_bytes_since_take;
    int32_t gripper_permille;
    mg_mcu_watch_t watch;
    int32_t mcu_resets;
    int32_t latest_servos_seq, latest_gripper_seq; /* -1: none; newest superseding commands */
    int32_t has_last_servos;
    int16_t last_servos[MSG_SERVO_COUNT]; /* the newest SetServos (mrad) and its slew */
    uint16_t last_slew;
    uint16_t readable_pulses_us[MSG_SERVO_COUNT]; /* newest readable pulse per channel */
} mg_host_link_t;

void mg_link_init(mg_host_link_t *l, int64_t retransmit_timeout_us, int32_t max_retries);
/* bytes read from the serial port that arrived at arrival_us */
void mg_link_receive(mg_host_link_t *l, const uint8_t *data, size_t n, int64_t arrival_us);
/* queue a message of type with its n payload bytes to leave at at_us (reliable ones tracked):
 * its seq, or -1 when the retransmit queue or the outbox is full */
int32_t mg_link_send(mg_host_link_t *l, uint8_t type, const uint8_t *payload, uint8_t n,
                     int64_t at_us);
int mg_link_needs_hello(const mg_host_link_t *l);
void mg_link_hello(mg_host_link_t *l, int64_t at_us);
void mg_link_service(mg_host_link_t *l, int64_t now_us);
/* the chunks to leave before before_us, in time order (removed): their count, at most max */
int32_t mg_link_take_output(mg_host_link_t *l, int64_t before_us, mg_wire_chunk_t *out,
                            int32_t max);
int64_t mg_link_next_send_us(const mg_host_link_t *l); /* -1: the outbox is empty */
/* the events since the last call (removed): their count, at most max */
int32_t mg_link_take_events(mg_host_link_t *l, mg_link_event_t *out, int32_t max);

/* SetServos in mrad, channels 1..5 clamped to the joint limits, channel 0 the last gripper
 * command; 1 when queued */
int mg_link_send_servos_mrad(mg_host_link_t *l, const int32_t joints_mrad[MSG_SERVO_COUNT],
                             int64_t at_us, uint16_t slew_mrad_s);
int mg_link_send_wheels(mg_host_link_t *l, int32_t left_mmps, int32_t right_mmps,
                        int64_t at_us);
int mg_link_send_gripper(mg_host_link_t *l, int32_t close_permille, int64_t at_us);
void mg_link_send_heartbeat(mg_host_link_t *l, int64_t at_us);
void mg_link_send_stop(mg_host_link_t *l, int64_t at_us);

#endif
