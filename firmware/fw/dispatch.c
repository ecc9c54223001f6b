/* Frame dispatch: the switch (msg_type) of mcu_sim/firmware/dispatch.py. Nothing actuates
 * before HELLO; a payload that does not decode is NACKed and actuates nothing; reliable
 * commands are ACKed, a copy (same seq and CRC) is answered again but not executed twice, and
 * another command reusing a recent seq is NACKed SEQ_REUSED (docs/protocol.md 5.2). */
#include "../protocol/messages.h"
#include "params.h"
#include "program.h"

static const char firmware_id[] = "mobigrasp-avr";
#define CAPABILITIES 0x000Fu /* servos, wheels, sonars, params */

static void send_param_value(uint16_t id)
{
    int32_t value;
    if (!params_get(id, &value)) {
        return; /* an unknown id ACKed as the copy of another command with the same seq */
    }
    uint8_t *p = fw_tx_payload();
    put_u16(p, id);
    put_u32(p + 2, (uint32_t)value);
    fw_send_built(MSG_PARAM_VALUE, 6);
}

static void send_hello_ack(void)
{
    uint8_t *p = fw_tx_payload();
    p[0] = PROTOCOL_VERSION;
    put_u16(p + 1, CAPABILITIES);
    uint8_t n = 0;
    while (firmware_id[n]) {
        p[3 + n] = (uint8_t)firmware_id[n];
        n++;
    }
    fw_send_built(MSG_HELLO_ACK, (uint8_t)(3 + n));
}

/* A new reliable command: 0 or a NACK reason. */
static uint8_t execute(uint8_t type, const uint8_t *p)
{
    switch (type) {
    case MSG_SET_SERVOS: {
        uint8_t mrad = p[0] == SERVO_MODE_MRAD;
        int32_t slew = get_u16(p + 13);
        int32_t slew_us = mrad ? mrad_slew_to_us(slew) : slew;
        for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
            int32_t v = get_i16(p + 1 + 2 * ch);
            int32_t pulse = mrad ? mrad_to_us(ch, v) : v;
            if (servo_set_target_us(&fw_servos, ch, pulse, slew_us)) {
                fw_count_limit();
            }
        }
        fw_write_all_ocrs();
        fw_flags.stopped = 0;
        return 0;
    }
    case MSG_GRIPPER:
        if (servo_set_target_us(&fw_servos, 0, GRIPPER_OPEN_US + (int32_t)get_u16(p), 0)) {
            fw_count_limit();
        }
        fw_write_ocr(0);
        return 0;
    case MSG_STOP:
        fw_stop_wheels();
        fw_hold_arm();
        fw_flags.stopped = 1;
        return 0;
    case MSG_PARAM_GET: {
        int32_t v;
        return params_get(get_u16(p), &v) ? 0 : NACK_BAD_PARAM;
    }
    case MSG_PARAM_SET: {
        uint16_t id = get_u16(p);
        int32_t value = get_i32(p + 2);
        uint8_t reason = params_check(id, value);
        if (reason == 0) {
            params_set(id, value);
            fw_apply_servo_limits();
        }
        return reason;
    }
    default:
        return NACK_BAD_PARAM; /* a reliable type this firmware does not execute */
    }
}

void fw_handle_frame(const frame_parser_t *fp, uint8_t n, uint32_t now)
{
    uint8_t type = frame_type(fp);
    uint8_t seq = frame_seq(fp);
    const uint8_t *p = frame_data(fp);
    uint8_t reason = msg_check(type, p, n);
    if (reason) {
        fw_counters.bad_frames++;
        fw_send_nack(seq, reason);
        return;
    }
    fw_last_valid_us = now;
    fw_flags.watchdog_tripped = 0;
    if (type == MSG_HELLO) {
        if (p[0] != PROTOCOL_VERSION) {
            fw_send_nack(seq, NACK_BAD_VERSION);
            return;
        }
        dup_reset(&fw_dup); /* a (re)started host counts from 0 again */
        dup_observe(&fw_dup, seq);
        dup_remember(&fw_dup, seq, frame_crc(fp, n), 0);
        /* a new session starts from the power-on safety PARAMs */
        if (params_restore_safety()) {
            fw_apply_servo_limits();
        }
        fw_flags.handshake = 1;
        fw_send_ack(seq);
        send_hello_ack();
        return;
    }
    dup_observe(&fw_dup, seq);
    if (type == MSG_SET_WHEELS) {
        if (!fw_flags.handshake) {
            fw_counters.not_ready++;
            return;
        }
        fw_set_wheels(get_i16(p), get_i16(p + 2));
        return;
    }
    if (!msg_is_reliable(type)) {
        if (type != MSG_HEARTBEAT) { /* replies and logs are not for the MCU */
            fw_counters.unexpected++;
        }
        return;
    }
    if (!fw_flags.handshake) {
        fw_counters.not_ready++;
        fw_send_nack(seq, NACK_NOT_READY);
        return;
    }
    uint16_t crc = frame_crc(fp, n);
    uint8_t kind = dup_classify(&fw_dup, seq, crc);
    if (kind == DUP_NEW) {
        reason = execute(type, p);
        dup_remember(&fw_dup, seq, crc, reason);
    } else if (kind == DUP_COPY) { /* a retransmission: the same answer, not executed again */
        reason = dup_result(&fw_dup, seq);
    } else { /* another command with a recent seq: refused, the slot keeps the first one */
        reason = NACK_SEQ_REUSED;
    }
    if (reason) {
        fw_send_nack(seq, reason);
    } else {
        fw_send_ack(seq);
    }
    if (!reason && (type == MSG_PARAM_GET || type == MSG_PARAM_SET)) {
        send_param_value(get_u16(p));
    }
}
