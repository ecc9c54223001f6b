/* The simavr harness's interface (harness.c); mcu_sim/simavr/build.py hands it to cffi as it is. */
#ifndef MOBIGRASP_SIMAVR_HARNESS_H
#define MOBIGRASP_SIMAVR_HARNESS_H

#include <stdint.h>

#define SH_PERIOD_REGS 9 /* OCR1A..C, OCR3A..C, ICR1, ICR3, TCCR1A | TCCR3A << 8 */
#define SH_VECTORS 35
#define SH_VECTOR_TIMER1_OVF 14
#define SH_INSTANT_EDGE_CYCLES 160 /* 10 us: the closest two edges of one wheel are put */

enum { SH_REACHED = 0, SH_STOPPED = 1, SH_CRASHED = -1 };

typedef struct {
    uint32_t isr_max_cycles[SH_VECTORS];
    uint32_t isr_count[SH_VECTORS];
    uint32_t irq_off_max_cycles;
    uint32_t irq_off_max_from_pc; /* byte addresses: the instruction that cleared I (or the */
    uint32_t irq_off_max_to_pc;   /* vector taken) and the one that set it again */
    uint32_t rx_latency_max_cycles;
    uint64_t sleep_cycles;
    uint32_t stack_depth_bytes;
    uint16_t sp_min;
    uint32_t tx_overflow;
    uint32_t resets;
    uint32_t loop_max_cycles;
    uint32_t loop_count;
} sh_profile_t;

/* What the rig reads after each sh_advance_to: the wheels' signed duties (sh_wheel_duty),
 * the Timer1 period starts and the sent bytes (their stop bit gone) waiting to be taken. */
typedef struct {
    int16_t duty[2];
    uint32_t periods;
    uint32_t tx_due;
} sh_outputs_t;

typedef struct sh sh_t;

sh_t *sh_new(const char *elf_path, uint16_t rx_head_addr, uint16_t rx_over_addr,
             uint16_t bss_end);
void sh_free(sh_t *sh);
void sh_reset(sh_t *sh);
uint64_t sh_cycle(const sh_t *sh);
int sh_state(const sh_t *sh);
int sh_booted(const sh_t *sh);
void sh_set_byte_cycles(sh_t *sh, uint32_t cycles);
void sh_set_loop_addr(sh_t *sh, uint32_t addr);
void sh_set_idle_addrs(sh_t *sh, uint16_t rx_tail, uint16_t tx_head, uint16_t tx_tail,
                       uint16_t next_telemetry, uint16_t telemetry_hz);
int sh_tx_idle_through(const sh_t *sh, uint64_t *cycle);
int sh_run_to(sh_t *sh, uint64_t target);
int sh_advance(sh_t *sh, uint64_t limit);
int sh_advance_to(sh_t *sh, uint64_t target, sh_outputs_t *out);
int sh_pin_at(sh_t *sh, uint64_t cycle, uint8_t port, uint8_t bit, uint8_t level);
void sh_wheel_duty(const sh_t *sh, int16_t duty[2]);
int sh_line_init(sh_t *sh, uint32_t capacity);
uint32_t sh_line_put(sh_t *sh, uint64_t start, const uint8_t *bytes, uint32_t n);
uint32_t sh_line_pending(const sh_t *sh);
uint32_t sh_rx_bytes(const sh_t *sh);
void sh_enc_set(sh_t *sh, uint8_t side, uint64_t now, uint64_t span, int64_t count);
void sh_enc_apply(sh_t *sh, uint64_t until);
void sh_enc_show_all(sh_t *sh);
int64_t sh_enc_pos(const sh_t *sh, uint8_t side);
uint64_t sh_events(const sh_t *sh);
void sh_pin(sh_t *sh, uint8_t port, uint8_t bit, uint8_t level);
int sh_uart_in(sh_t *sh, uint8_t byte);
uint32_t sh_rx_line_lost(const sh_t *sh);
uint32_t sh_tx_take(sh_t *sh, uint8_t *bytes, uint64_t *cycles, uint32_t max);
uint32_t sh_tx_pending(const sh_t *sh);
uint64_t sh_tx_line_free(const sh_t *sh);
uint32_t sh_triggers_take(sh_t *sh, uint8_t *idx, uint64_t *cycles, uint32_t max);
uint32_t sh_periods_take(sh_t *sh, uint64_t *cycles, uint16_t *regs, uint32_t max);
void sh_read(const sh_t *sh, uint16_t addr, uint8_t *dst, uint16_t n);
void sh_profile(const sh_t *sh, sh_profile_t *out);
uint32_t sh_pc(const sh_t *sh);
uint32_t sh_rx_unread(const sh_t *sh);
uint32_t sh_oc1_pin_high_cycles(const sh_t *sh, uint8_t ch);

#endif
