/* What protocol.messages' decode() accepts, as length and range checks on the raw payload. */
#include "messages.h"

uint8_t msg_is_reliable(uint8_t type)
{
    switch (type) {
    case MSG_HELLO: case MSG_SET_SERVOS: case MSG_GRIPPER: case MSG_STOP:
    case MSG_PARAM_GET: case MSG_PARAM_SET:
        return 1;
    default:
        return 0;
    }
}

static uint8_t text_ok(const uint8_t *p, uint8_t n)
{
    for (uint8_t i = 0; i < n; i++) {
        if (p[i] < 0x20u || p[i] > 0x7Eu) {
            return 0;
        }
    }
    return 1;
}

static uint8_t in_range(int32_t v, int32_t lo, int32_t hi) { return lo <= v && v <= hi; }

uint8_t msg_check(uint8_t type, const uint8_t *p, uint8_t n)
{
    switch (type) {
    case MSG_HELLO: case MSG_HELLO_ACK: /* version u8, capabilities u16, id text */
        if (n < 3u || n > 3u + MSG_ID_MAX_CHARS) return NACK_BAD_LENGTH;
        return text_ok(p + 3, (uint8_t)(n - 3u)) ? 0 : NACK_OUT_OF_RANGE;
    case MSG_HEARTBEAT:
        return n == 4u ? 0 : NACK_BAD_LENGTH;
    case MSG_SET_SERVOS: { /* mode u8, 6 x i16 targets, slew u16 */
        if (n != 15u) return NACK_BAD_LENGTH;
        if (p[0] > SERVO_MODE_MRAD) return NACK_OUT_OF_RANGE;
        int32_t lo = p[0] == SERVO_MODE_PULSE_US ? MSG_PULSE_MIN_US : -MSG_MRAD_LIMIT;
        int32_t hi = p[0] == SERVO_MODE_PULSE_US ? MSG_PULSE_MAX_US : MSG_MRAD_LIMIT;
        for (uint8_t ch = 0; ch < MSG_SERVO_COUNT; ch++) {
            if (!in_range(get_i16(p + 1 + 2 * ch), lo, hi)) return NACK_OUT_OF_RANGE;
        }
        return 0;
    }
    case MSG_GRIPPER:
        if (n != 2u) return NACK_BAD_LENGTH;
        return get_u16(p) <= MSG_GRIPPER_MAX ? 0 : NACK_OUT_OF_RANGE;
    case MSG_SET_WHEELS:
        if (n != 4u) return NACK_BAD_LENGTH;
        return in_range(get_i16(p), -MSG_WHEEL_LIMIT_MMPS, MSG_WHEEL_LIMIT_MMPS)
                       && in_range(get_i16(p + 2), -MSG_WHEEL_LIMIT_MMPS, MSG_WHEEL_LIMIT_MMPS)
                   ? 0 : NACK_OUT_OF_RANGE;
    case MSG_STOP:
        return n == 0u ? 0 : NACK_BAD_LENGTH;
    case MSG_TELEMETRY:
        return n == MSG_TELEMETRY_LEN ? 0 : NACK_BAD_LENGTH;
    case MSG_PARAM_GET:
        return n == 2u ? 0 : NACK_BAD_LENGTH;
    case MSG_PARAM_SET: case MSG_PARAM_VALUE:
        return n == 6u ? 0 : NACK_BAD_LENGTH;
    case MSG_ACK:
        return n == 1u ? 0 : NACK_BAD_LENGTH;
    case MSG_NACK:
        return n == 2u ? 0 : NACK_BAD_LENGTH;
    case MSG_LOG:
        if (n < 2u || n > 2u + MSG_LOG_MAX_CHARS) return NACK_BAD_LENGTH;
        return text_ok(p + 2, (uint8_t)(n - 2u)) ? 0 : NACK_OUT_OF_RANGE;
    default:
        return NACK_UNKNOWN_TYPE;
    }
}
