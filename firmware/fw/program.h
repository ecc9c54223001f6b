/* The ATmega128 program (mcu_sim/firmware/program.py): start-up, the interrupt handlers' work
 * and one pass of the main loop. The vectors (hal_avr.c) or the emulator (hal_native.c) call
 * the fw_isr_* functions; fw_loop() returns when (us since reset) something is next due, and
 * the caller runs it again when fw_work_pending() or at that time, sleeping in between. */
#ifndef MOBIGRASP_PROGRAM_H
#define MOBIGRASP_PROGRAM_H

#include <stdint.h>

#include "../protocol/frame.h"
#include "../protocol/reliable.h"
#include "ring.h"
#include "servo_table.h"
#include "sonar_task.h"
#include "wheel_pi.h"

/* Counters a debugger would read (Mcu.stats()). */
typedef struct {
    uint32_t bad_frames;
    uint32_t not_ready;
    uint32_t unexpected;
    uint32_t tx_dropped;
    uint32_t limit_hits;
    uint32_t watchdog_trips;
    uint32_t telemetry_sent;
} fw_counters_t;

typedef struct {
    uint8_t drive_enabled;
    uint8_t handshake;
    uint8_t stopped;
    uint8_t limit_flag;
    uint8_t reset_flag;
    uint8_t watchdog_tripped;
} fw_flags_t;

extern byte_ring_t fw_rx;
extern frame_parser_t fw_parser;
extern dup_filter_t fw_dup;
extern servo_bank_t fw_servos;
extern wheel_pi_t fw_wheels[2];
extern sonar_task_t fw_sonar;
extern volatile int32_t fw_enc_count[2];
extern int16_t fw_duty_out[2];
extern fw_flags_t fw_flags;
extern fw_counters_t fw_counters;
extern uint8_t fw_tx_seq;
extern uint32_t fw_last_valid_us;

/* Start-up: fw_setup_rx() (RX ring and parser) before the receiver and interrupts are
 * enabled, fw_setup() (everything else) after. */
void fw_setup_rx(void);
void fw_setup(void);
void fw_isr_usart_rx(uint8_t byte);
void fw_isr_timer1_ovf(void);
void fw_isr_encoder(uint8_t side, int8_t edge);
void fw_isr_echo(uint8_t index, uint8_t level);
uint32_t fw_loop(void);
/* 1 while an interrupt left work for the main loop (a frame's end in the RX ring, or 64
 * bytes without one; a servo period). */
uint8_t fw_work_pending(void);
/* Next telemetry time (us since reset); 0 and *off = 1 when telemetry is off. */
uint32_t fw_next_unprompted_send_us(uint8_t *off);
uint32_t fw_corrupt_frames(void);

/* what dispatch.c calls */
void fw_send_built(uint8_t type, uint8_t n); /* payload already in fw_tx_payload() */
uint8_t *fw_tx_payload(void);
void fw_send_ack(uint8_t acked_seq);
void fw_send_nack(uint8_t acked_seq, uint8_t reason);
void fw_count_limit(void);
void fw_apply_servo_limits(void);
void fw_set_wheels(int16_t left_mmps, int16_t right_mmps);
void fw_stop_wheels(void);
void fw_hold_arm(void);
void fw_write_ocr(uint8_t ch);
void fw_write_all_ocrs(void);

/* dispatch.c: one checked frame received at now_us */
void fw_handle_frame(const frame_parser_t *p, uint8_t payload_len, uint32_t now_us);

#endif
