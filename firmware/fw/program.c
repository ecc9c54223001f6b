/* Start-up, interrupt work and the event-driven main loop (mcu_sim/firmware/program.py).
 * Interrupt handlers only store what happened (a byte, an edge, a time, a flag); a main-loop
 * pass, run when a handler left work or something fell due, drains the RX ring into the parser,
 * dispatches frames and runs only what is due: the servo period's OCR writes, wheel PI
 * (100 Hz), watchdog, sonar slot, telemetry. Between passes the core sleeps (hal_avr.c). */
#include "program.h"

#include "../hal.h"
#include "../protocol/messages.h"
#include "params.h"

#define ICR_20MS 39999u            /* TOP for 20 ms at 0.5 us ticks */
#define TCCRA_SERVO 0xAAu          /* COMnA/B/C = 10 (non-inverting), WGMn1:0 = 10 */
#define TCCRB_SERVO 0x1Au          /* WGMn3:2 = 11 (mode 14), CSn = 010 (clk/8) */

byte_ring_t fw_rx FW_STATE;
frame_parser_t fw_parser FW_STATE;
dup_filter_t fw_dup FW_STATE;
servo_bank_t fw_servos FW_STATE;
wheel_pi_t fw_wheels[2] FW_STATE;
sonar_task_t fw_sonar FW_STATE;
volatile int32_t fw_enc_count[2] FW_STATE;
int16_t fw_duty_out[2] FW_STATE;
fw_flags_t fw_flags FW_STATE;
fw_counters_t fw_counters FW_STATE;
uint8_t fw_tx_seq FW_STATE;
uint32_t fw_last_valid_us FW_STATE;
static uint32_t next_control_us FW_STATE;
static uint32_t next_telemetry_us FW_STATE;
static volatile uint8_t servo_period_due FW_STATE; /* set by the Timer1 overflow */
static volatile uint8_t rx_frame_due FW_STATE;     /* set by the RX handler: a frame ended */
/* The RX handler also wakes the loop once this many bytes wait without a delimiter, so a
 * stream of garbage cannot fill the ring (127 bytes) before the loop drains it. */
#define RX_WAKE_BYTES 64u
static uint8_t tx_buf[FRAME_MAX_WIRE] FW_STATE;

static uint8_t due(uint32_t now, uint32_t t) { return (int32_t)(now - t) >= 0; }

static int32_t enc_count(uint8_t side)
{
    uint8_t irq = hal_irq_save();
    int32_t c = fw_enc_count[side];
    hal_irq_restore(irq);
    return c;
}

/* -- start-up ---------------------------------------------------------------------------- */
/* The receiving side, first of all: from here on the RX handler can take bytes while the
 * rest of the start-up runs with interrupts on. */
void fw_setup_rx(void)
{
    ring_clear(&fw_rx);
    fw_rx.overruns = 0;
    frame_parser_reset(&fw_parser);
    rx_frame_due = 0;
}

void fw_setup(void)
{
    fw_dup.duplicates = 0;
    fw_dup.reused = 0;
    dup_reset(&fw_dup);
    fw_tx_seq = 0;
    params_reset();
    servo_reset(&fw_servos);
    fw_apply_servo_limits();
    fw_enc_count[0] = fw_enc_count[1] = 0;
    fw_duty_out[0] = fw_duty_out[1] = 0;
    wheel_reset(&fw_wheels[0], 0);
    wheel_reset(&fw_wheels[1], 0);
    fw_flags = (fw_flags_t){0, 0, 0, 0, 1, 0}; /* reset_flag for the first telemetry */
    fw_counters = (fw_counters_t){0, 0, 0, 0, 0, 0, 0};
    servo_period_due = 0;
    hal_servo_timers_config(TCCRA_SERVO, ICR_20MS);
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        fw_write_ocr(ch);
    }
    servo_latch(&fw_servos);
    hal_servo_timers_start(TCCRB_SERVO);
    for (uint8_t side = 0; side < 2; side++) {
        hal_wheel_start(side);
        hal_wheel_direction(side, 0);
        hal_wheel_ocr(side, 0);
    }
    uint32_t now = hal_micros();
    fw_last_valid_us = now;
    next_control_us = now + CONTROL_PERIOD_US;
    /* the first telemetry at once (it carries the reset flag), the later ones on the clock's
     * multiples of their period: at 50 Hz the AVR's Timer1 overflows, whose handler wakes the
     * loop then (due work otherwise waits for a Timer0 tick, up to 1 ms). The models' start-up
     * takes no time (now is 0), so theirs are at those times already. */
    uint32_t hz = (uint32_t)params_values[I_TELEMETRY_HZ];
    next_telemetry_us = hz ? now - now % (1000000ul / hz) : now;
    sonar_reset(&fw_sonar, now);
}

/* -- interrupt handlers' work ------------------------------------------------------------ */
void fw_isr_usart_rx(uint8_t byte)
{
    ring_put(&fw_rx, byte);
    if (byte == 0 || (uint8_t)(fw_rx.head - fw_rx.tail) % RX_RING_BYTES >= RX_WAKE_BYTES) {
        rx_frame_due = 1; /* a frame's delimiter (COBS: 0x00 nowhere else) */
    }
}

void fw_isr_timer1_ovf(void) { servo_period_due = 1; }

void fw_isr_encoder(uint8_t side, int8_t edge) { fw_enc_count[side] += edge; }

void fw_isr_echo(uint8_t index, uint8_t level) { sonar_on_echo(&fw_sonar, index, level, hal_micros()); }

/* Timer1 and 3 (started together) began a period: the pending widths are in force; step every
 * moving channel and write its OCR for the period after (latched at the next BOTTOM). */
static void servo_period(void)
{
    servo_latch(&fw_servos);
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        if (!servo_at_rest(&fw_servos, ch)) {
            fw_write_ocr(ch);
        }
    }
}

/* -- outputs ----------------------------------------------------------------------------- */
void fw_write_ocr(uint8_t ch) { hal_servo_ocr(ch, servo_next_pending(&fw_servos, ch)); }

void fw_write_all_ocrs(void)
{
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        fw_write_ocr(ch);
    }
}

static void set_duty(uint8_t side, int16_t duty)
{
    if (duty == fw_duty_out[side]) {
        return;
    }
    fw_duty_out[side] = duty;
    hal_wheel_direction(side, duty < 0);
    hal_wheel_ocr(side, (uint8_t)(duty < 0 ? -duty : duty));
}

void fw_stop_wheels(void)
{
    fw_flags.drive_enabled = 0;
    for (uint8_t side = 0; side < 2; side++) {
        wheel_reset(&fw_wheels[side], enc_count(side));
        set_duty(side, 0);
    }
}

void fw_hold_arm(void)
{
    servo_hold(&fw_servos);
    fw_write_all_ocrs();
}

static void trip_watchdog(void)
{
    fw_flags.watchdog_tripped = 1;
    fw_counters.watchdog_trips++;
    fw_stop_wheels();
    fw_hold_arm();
}

static void control(void)
{
    int32_t kp = params_values[I_WHEEL_KP];
    int32_t ki = params_values[I_WHEEL_KI];
    for (uint8_t side = 0; side < 2; side++) {
        int32_t count = enc_count(side);
        int16_t duty = 0;
        if (fw_flags.drive_enabled) {
            duty = wheel_update(&fw_wheels[side], count, kp, ki);
        } else {
            fw_wheels[side].last_count = count;
        }
        set_duty(side, duty);
    }
}

uint8_t *fw_tx_payload(void) { return frame_payload(tx_buf); }

void fw_send_built(uint8_t type, uint8_t n)
{
    uint8_t len = frame_finish(tx_buf, fw_tx_seq++, type, n);
    if (!hal_uart_send(tx_buf, len)) {
        fw_counters.tx_dropped++;
    }
}

void fw_send_ack(uint8_t acked_seq)
{
    fw_tx_payload()[0] = acked_seq;
    fw_send_built(MSG_ACK, 1);
}

void fw_send_nack(uint8_t acked_seq, uint8_t reason)
{
    uint8_t *p = fw_tx_payload();
    p[0] = acked_seq;
    p[1] = reason;
    fw_send_built(MSG_NACK, 2);
}

static uint16_t flags_word(void)
{
    uint16_t f = fw_flags.handshake ? FLAG_HANDSHAKE : 0;
    if (fw_flags.watchdog_tripped) f |= FLAG_WATCHDOG;
    if (fw_flags.limit_flag) f |= FLAG_LIMIT;
    if (fw_flags.stopped) f |= FLAG_STOPPED;
    if (fw_flags.reset_flag) f |= FLAG_RESET;
    if (fw_servos.target_q8[0] >= ((int32_t)(GRIPPER_OPEN_US + 500) << 8)) f |= FLAG_GRIPPER_CLOSED;
    return f;
}

uint32_t fw_corrupt_frames(void)
{
    const frame_stats_t *s = &fw_parser.stats;
    return s->crc_errors + s->cobs_errors + s->truncated + s->oversize + s->bad_version;
}

static void send_telemetry(uint32_t now)
{
    /* layout <Iii6H5H5H: time, encoders, servo widths, sonar ranges, flags, four counters */
    uint8_t *p = fw_tx_payload();
    put_u32(p, now);
    put_u32(p + 4, (uint32_t)enc_count(0));
    put_u32(p + 8, (uint32_t)enc_count(1));
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        put_u16(p + 12 + 2 * ch, servo_latched_us(&fw_servos, ch));
    }
    for (uint8_t i = 0; i < SONARS_MAX; i++) {
        put_u16(p + 24 + 2 * i, fw_sonar.range_mm[i]);
    }
    put_u16(p + 34, flags_word());
    put_u16(p + 36, (uint16_t)fw_corrupt_frames());
    put_u16(p + 38, (uint16_t)(fw_rx.overruns + hal_uart_rx_lost()));
    put_u16(p + 40, (uint16_t)fw_counters.limit_hits);
    put_u16(p + 42, (uint16_t)fw_counters.watchdog_trips);
    fw_send_built(MSG_TELEMETRY, MSG_TELEMETRY_LEN);
    fw_counters.telemetry_sent++;
    fw_flags.limit_flag = 0;
    fw_flags.reset_flag = 0;
}

/* -- main loop --------------------------------------------------------------------------- */
uint32_t fw_loop(void)
{
    uint32_t now = hal_micros();
    if (servo_period_due) {
        servo_period_due = 0;
        servo_period();
    }
    rx_frame_due = 0; /* a delimiter that comes while the ring drains is taken below too */
    while (!ring_empty(&fw_rx)) {
        uint8_t n = frame_parser_feed(&fw_parser, ring_get(&fw_rx));
        if (n) {
            fw_handle_frame(&fw_parser, (uint8_t)(n - 1u), now);
        }
    }
    if (due(now, next_control_us)) {
        control();
        next_control_us += CONTROL_PERIOD_US;
        if (due(now, next_control_us)) {
            next_control_us = now + CONTROL_PERIOD_US;
        }
    }
    uint32_t wd_us = (uint32_t)params_values[I_WATCHDOG_MS] * 1000u;
    if (wd_us && !fw_flags.watchdog_tripped && now - fw_last_valid_us >= wd_us) {
        trip_watchdog();
    }
    if (due(now, fw_sonar.next_slot_us)) {
        sonar_end_slot(&fw_sonar);
        int8_t index = sonar_start_slot(&fw_sonar, (uint8_t)params_values[I_SONAR_COUNT], now,
                                        (uint32_t)params_values[I_SONAR_SLOT_MS] * 1000u);
        if (index >= 0) {
            hal_sonar_trigger((uint8_t)index);
        }
    }
    uint32_t hz = (uint32_t)params_values[I_TELEMETRY_HZ];
    if (hz && due(now, next_telemetry_us)) {
        send_telemetry(now);
        uint32_t period = 1000000ul / hz;
        next_telemetry_us += period;
        if (due(now, next_telemetry_us)) {
            next_telemetry_us = now + period;
        }
    }
    uint32_t next = next_control_us;
    if ((int32_t)(fw_sonar.next_slot_us - next) < 0) next = fw_sonar.next_slot_us;
    if (hz && (int32_t)(next_telemetry_us - next) < 0) next = next_telemetry_us;
    if (wd_us && !fw_flags.watchdog_tripped && (int32_t)(fw_last_valid_us + wd_us - next) < 0) {
        next = fw_last_valid_us + wd_us;
    }
    return next;
}

uint8_t fw_work_pending(void) { return rx_frame_due || servo_period_due; }

uint32_t fw_next_unprompted_send_us(uint8_t *off)
{
    *off = params_values[I_TELEMETRY_HZ] == 0;
    return *off ? 0 : next_telemetry_us;
}

/* -- helpers the dispatch calls ---------------------------------------------------------- */
void fw_count_limit(void)
{
    fw_counters.limit_hits++;
    fw_flags.limit_flag = 1;
}

void fw_apply_servo_limits(void)
{
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        int32_t v;
        int16_t mech_lo, mech_hi;
        default_limits_us(ch, &mech_lo, &mech_hi);
        /* the PARAM checks keep these inside the mechanical limits; clamping again keeps the
         * servo bank inside them whatever reaches the PARAM array */
        params_get((uint16_t)(P_SERVO_MIN_BASE + ch), &v);
        v = v < mech_lo ? mech_lo : v > mech_hi ? mech_hi : v;
        fw_servos.min_us[ch] = (int16_t)v;
        params_get((uint16_t)(P_SERVO_MAX_BASE + ch), &v);
        v = v < fw_servos.min_us[ch] ? fw_servos.min_us[ch] : v > mech_hi ? mech_hi : v;
        fw_servos.max_us[ch] = (int16_t)v;
        fw_write_ocr(ch);
    }
}

void fw_set_wheels(int16_t left_mmps, int16_t right_mmps)
{
    int32_t limit = params_values[I_WHEEL_MAX_MMPS];
    int16_t req[2] = {left_mmps, right_mmps};
    for (uint8_t side = 0; side < 2; side++) {
        int32_t clamped = req[side] < -limit ? -limit : req[side] > limit ? limit : req[side];
        if (clamped != req[side]) {
            fw_count_limit();
        }
        if (!fw_flags.drive_enabled) {
            wheel_reset(&fw_wheels[side], enc_count(side));
        }
        wheel_set_target(&fw_wheels[side], (int16_t)clamped);
    }
    fw_flags.drive_enabled = 1;
    fw_flags.stopped = 0;
}
