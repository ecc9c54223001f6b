/* Messages of the protocol: types, NACK reasons, flags, payload layouts (docs/protocol.md;
 * protocol/messages.py is the reference). Payloads are read and written in place with the
 * little-endian helpers below; msg_check() gives the NACK reason the Python decoder would. */
#ifndef MOBIGRASP_MESSAGES_H
#define MOBIGRASP_MESSAGES_H

#include <stdint.h>

enum {
    MSG_HELLO = 0x01, MSG_HELLO_ACK = 0x02, MSG_HEARTBEAT = 0x03,
    MSG_SET_SERVOS = 0x10, MSG_GRIPPER = 0x11, MSG_SET_WHEELS = 0x12, MSG_STOP = 0x13,
    MSG_TELEMETRY = 0x20,
    MSG_PARAM_GET = 0x30, MSG_PARAM_SET = 0x31, MSG_PARAM_VALUE = 0x32,
    MSG_ACK = 0x40, MSG_NACK = 0x41, MSG_LOG = 0x50
};

enum {
    NACK_OUT_OF_RANGE = 1, NACK_UNKNOWN_TYPE = 2, NACK_BAD_LENGTH = 3, NACK_NOT_READY = 4,
    NACK_BAD_PARAM = 5, NACK_BAD_VERSION = 6,
    NACK_SEQ_REUSED = 7 /* a reliable seq reused with other content inside the window */
};

enum {
    FLAG_WATCHDOG = 1u << 0, FLAG_LIMIT = 1u << 1, FLAG_HANDSHAKE = 1u << 2,
    FLAG_STOPPED = 1u << 3, FLAG_RESET = 1u << 4, FLAG_GRIPPER_CLOSED = 1u << 5
};

#define SERVO_MODE_PULSE_US 0u
#define SERVO_MODE_MRAD 1u
#define MSG_SERVO_COUNT 6u
#define MSG_SONAR_COUNT 5u
#define MSG_PULSE_MIN_US 500
#define MSG_PULSE_MAX_US 2500
#define MSG_MRAD_LIMIT 3142
#define MSG_WHEEL_LIMIT_MMPS 1000
#define MSG_GRIPPER_MAX 1000u
#define MSG_ID_MAX_CHARS 16u
#define MSG_LOG_MAX_CHARS 48u
#define MSG_TELEMETRY_LEN 44u

/* 1 for a type answered by ACK/NACK (HELLO, SET_SERVOS, GRIPPER, STOP, PARAM_GET/SET). */
uint8_t msg_is_reliable(uint8_t type);

/* 0 if ``n`` payload bytes decode as a message of ``type``, else the NACK reason:
 * NACK_UNKNOWN_TYPE, NACK_BAD_LENGTH, NACK_OUT_OF_RANGE (a field or the text). */
uint8_t msg_check(uint8_t type, const uint8_t *p, uint8_t n);

static inline uint16_t get_u16(const uint8_t *p) { return (uint16_t)(p[0] | ((uint16_t)p[1] << 8)); }
static inline int16_t get_i16(const uint8_t *p) { return (int16_t)get_u16(p); }
static inline uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline int32_t get_i32(const uint8_t *p) { return (int32_t)get_u32(p); }
static inline void put_u16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static inline void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24);
}

#endif
