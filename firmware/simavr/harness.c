/* A harness around libsimavr (Debian's simavr 1.6): the avr-gcc ELF of the firmware on an
 * instruction-accurate ATmega128 at 16 MHz, moved by the caller's clock.
 *
 * Built with the machine's gcc and loaded with cffi (mcu_sim/simavr/build.py). The caller
 * puts host bytes on USART0's RX line (sh_line_put) and quadrature counts on the encoder pins
 * (sh_enc_set), queues other input pin levels at the cycles it chooses (sh_pin_at), runs the
 * core to its next time (sh_advance_to: the line's bytes, the queued levels and the encoder
 * edges before it are handed over here, each at its cycle, one core run per event time; one
 * call per coupling step, the wheel duties and what waits to be taken reported at its end),
 * and takes what happened: bytes sent on TX (with
 * the cycle their stop bit left), sonar trigger pulses, Timer1 period starts with the
 * OCRnx/ICRn values latched there. No wall-clock pacing: a sleeping core goes straight to its next cycle timer
 * (a peripheral's next event, or the target, where a cycle timer wakes it), and the sleep
 * callback only counts the cycles skipped.
 *
 * Between instructions it keeps the profile that only an instruction-accurate core can give:
 * cycles of each interrupt (vector entry to the RETI that sets I again; ISRs do not nest),
 * longest stretch with I clear after the first sei, cycles asleep, the lowest stack pointer,
 * and the latency from a received byte's stop bit to the RX ring's head moving. */
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <simavr/avr_extint.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_core.h>
#include <simavr/sim_cycle_timers.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_interrupts.h>
#include <simavr/sim_irq.h>

#include "harness.h"

DEFINE_FIFO(uint16_t, uart_fifo);

#define TX_MAX 4096u
#define EV_MAX 256u
#define RXQ_MAX 256u
#define RX_RING_BYTES 128u /* the firmware's RX ring (fw/ring.h) */
#define PAINT 0xA5u
#define RAM_START 0x100u
#define VECTORS 35u
#define PINQ_MAX 256u

/* One wheel's quadrature edges still to come: edge k (1..n) at start + span*k/n when spread,
 * else start + SH_INSTANT_EDGE_CYCLES*k, the count then pos0 + dir*k. */
typedef struct {
    uint64_t start, span;
    int64_t pos0;
    uint32_t n, k;
    int dir, spread;
} enc_t;

typedef struct {
    uint64_t cycle;
    uint8_t port, bit, level;
} pin_level_t;

struct sh {
    avr_t *avr;
    enc_t enc[2];
    int64_t enc_pos[2]; /* the count whose A/B levels the pins show */
    uint64_t events;    /* runs of the core between two event times (sh_advance) */
    /* the RX line: host bytes with the cycle of their start bit, oldest first */
    uint64_t *line_cycle;
    uint8_t *line_byte;
    uint32_t line_cap, line_head, line_n;
    uint32_t rx_bytes; /* handed to USART0 (not lost at its input) */
    avr_uart_t *uart;
    avr_irq_t *pins[7][8]; /* ports A..G */
    uint64_t byte_cycles;
    /* TX: bytes and the cycle their stop bit leaves the pin */
    uint8_t tx_byte[TX_MAX];
    uint64_t tx_cycle[TX_MAX];
    uint32_t tx_n;
    uint64_t tx_line_free;
    /* sonar trigger rising edges on PORTC0..4 */
    uint8_t trig_idx[EV_MAX];
    uint64_t trig_cycle[EV_MAX];
    uint32_t trig_n;
    uint8_t portc_last;
    int stop;
    /* Timer1 period starts */
    uint64_t per_cycle[EV_MAX];
    uint16_t per_regs[EV_MAX][SH_PERIOD_REGS];
    uint32_t per_n;
    /* addresses the firmware's globals live at (data space), from the ELF's symbols */
    uint16_t rx_head_addr, rx_over_addr, bss_end;
    uint8_t rx_head_last;
    uint32_t rx_over_last;
    /* stop-bit cycles of bytes handed to the receiver, oldest first */
    uint64_t rxq[RXQ_MAX];
    uint32_t rxq_head, rxq_n;
    uint32_t rxq_untimed; /* accepted before the first sei, or queued behind such bytes:
                           * the start-up's wait, not the handler's latency */
    uint32_t rx_line_lost;
    sh_profile_t prof;
    int in_isr;
    uint8_t isr_vec;
    uint64_t isr_start;
    int seen_sei;
    int seen_loop; /* the main loop has begun: the start-up is over */
    uint64_t ioff_start;
    uint32_t ioff_pc;
    uint64_t oc1_rise[3];      /* OC1A..C pin (PB5..7): last rising edge */
    uint32_t oc1_high_cycles[3]; /* and the last high time the pin showed */
    uint8_t portb_last;
    uint32_t loop_addr; /* fw_loop's entry (byte address) */
    int in_loop;
    uint16_t loop_sp;
    uint64_t loop_start;
    uint64_t target_cycle;
    uint64_t timer_armed;
    /* when the firmware next sends (sh_tx_idle_through): Timer1 overflows since reset and the
     * cycle of the last (hal_micros counts 20 ms per overflow plus TCNT1's 0.5 us ticks), the
     * firmware's globals, and whether a received byte may still be unanswered */
    uint32_t t1_ovf_n;
    uint64_t t1_ovf_cycle;
    uint16_t rx_tail_addr, tx_head_addr, tx_tail_addr, next_tel_addr, tel_hz_addr;
    int rx_unanswered;
    /* input pin levels to come (sh_pin_at), by cycle, in the order given at one cycle */
    pin_level_t pinq[PINQ_MAX];
    uint32_t pinq_n;
};

/* simavr's messages (ELF sections loaded, UART settings) would go to the run's stdout. */
static void quiet_logger(avr_t *avr, const int level, const char *format, va_list ap)
{
    (void)avr;
    (void)level;
    (void)format;
    (void)ap;
}

/* simavr calls this when the core sleeps, with the cycles to its next cycle timer, then moves
 * the clock by 1 + how_long in the same avr_run call: the instruction that executed SLEEP
 * included, so the sleep is counted here rather than by the state before the call. */
static void count_sleep(avr_t *avr, avr_cycle_count_t how_long)
{
    ((sh_t *)avr->custom.data)->prof.sleep_cycles += 1u + how_long;
}

static void on_uart_out(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    sh_t *sh = param;
    uint64_t start = sh->avr->cycle > sh->tx_line_free ? sh->avr->cycle : sh->tx_line_free;
    sh->tx_line_free = start + sh->byte_cycles;
    if (sh->tx_n < TX_MAX) {
        sh->tx_byte[sh->tx_n] = (uint8_t)value;
        sh->tx_cycle[sh->tx_n] = sh->tx_line_free;
        sh->tx_n++;
    } else {
        sh->prof.tx_overflow++;
    }
}

static void on_portc(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    sh_t *sh = param;
    uint8_t now = (uint8_t)value, rose = (uint8_t)(now & ~sh->portc_last & 0x1Fu);
    sh->portc_last = now; /* pin IRQs may repeat a level: act on changes only */
    for (uint8_t i = 0; i < 5; i++) {
        if ((rose >> i) & 1u) {
            if (sh->trig_n < EV_MAX) {
                sh->trig_idx[sh->trig_n] = i;
                sh->trig_cycle[sh->trig_n] = sh->avr->cycle;
                sh->trig_n++;
            }
            sh->stop = 1;
        }
    }
}

/* Timer1 period start: its overflow flag rises at BOTTOM; the OCRnx/ICRn values in force for
 * the coming period are those in the registers now (data-space addresses of the ATmega128's
 * register summary). */
static void on_tov1(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    sh_t *sh = param;
    static const uint16_t regs[SH_PERIOD_REGS - 1] = {
        0x4A, 0x48, 0x78, /* OCR1A, OCR1B, OCR1C */
        0x86, 0x84, 0x82, /* OCR3A, OCR3B, OCR3C */
        0x46, 0x80,       /* ICR1, ICR3 */
    };
    const avr_t *avr = sh->avr;
    if (!value) {
        return;
    }
    sh->t1_ovf_n++;
    sh->t1_ovf_cycle = avr->cycle;
    if (sh->per_n >= EV_MAX) {
        return;
    }
    for (unsigned i = 0; i < SH_PERIOD_REGS - 1; i++) {
        sh->per_regs[sh->per_n][i] = (uint16_t)(avr->data[regs[i]] |
                                                (avr->data[regs[i] + 1u] << 8));
    }
    sh->per_regs[sh->per_n][SH_PERIOD_REGS - 1] = (uint16_t)(avr->data[0x4F] |
                                                             (avr->data[0x8B] << 8));
    sh->per_cycle[sh->per_n++] = avr->cycle;
}

/* What the OC1A..C pins show (simavr 1.6 keeps their boot widths in mode 14, see on_tov1). */
static void on_portb(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    sh_t *sh = param;
    uint8_t now = (uint8_t)value, changed = (uint8_t)(now ^ sh->portb_last);
    sh->portb_last = now;
    for (uint8_t ch = 0; ch < 3; ch++) {
        uint8_t bit = (uint8_t)(5u + ch);
        if (!((changed >> bit) & 1u)) {
            continue;
        }
        if ((now >> bit) & 1u) {
            sh->oc1_rise[ch] = sh->avr->cycle;
        } else if (sh->oc1_rise[ch]) {
            sh->oc1_high_cycles[ch] = (uint32_t)(sh->avr->cycle - sh->oc1_rise[ch]);
        }
    }
}

static void on_oc1_pin(struct avr_irq_t *irq, uint32_t value, void *param)
{
    sh_t *sh = param;
    uint8_t bit = (uint8_t)(irq->irq & 7u);
    uint8_t v = (uint8_t)(sh->portb_last & ~(1u << bit)) | (uint8_t)((value ? 1u : 0u) << bit);
    on_portb(irq, v, param);
}

uint32_t sh_oc1_pin_high_cycles(const sh_t *sh, uint8_t ch)
{
    return ch < 3 ? sh->oc1_high_cycles[ch] : 0u;
}

static avr_cycle_count_t wake_at_target(avr_t *avr, avr_cycle_count_t when, void *param)
{
    (void)avr;
    (void)when;
    ((sh_t *)param)->timer_armed = 0;
    return 0;
}

/* The stack's region (above the firmware's data and bss) painted, so the deepest stack can be
 * read back; data and bss stay as simavr left them (zero) until the C runtime sets them. */
static void paint(sh_t *sh)
{
    avr_t *avr = sh->avr;
    uint32_t from = sh->bss_end > RAM_START ? sh->bss_end : RAM_START;
    memset(avr->data + from, PAINT, (size_t)(avr->ramend + 1u - from));
}

/* Settings of the harness that simavr's avr_reset puts back to its defaults, applied after
 * avr_init and after every avr_reset: the external-interrupt reset turns strict level
 * triggering on again, and avr_reset empties the cycle-timer pool, the wake at the target
 * included. With strict triggering on, a pin held low (an encoder at rest: INT0..3 are
 * level-triggered until the firmware writes EICRA) arms a poll every cycle that raises INTn
 * again after each RETI, for good, since the poll does not look at EICRA; INT0..3 outrank
 * every other vector, so the firmware never left them and USART0's UDRE waited forever. */
static void apply_workarounds(sh_t *sh)
{
    for (int i = 0; i < 8; i++) {
        avr_extint_set_strict_lvl_trig(sh->avr, (uint8_t)i, 0); /* 1.6 polls INT0..7 otherwise */
    }
    sh->timer_armed = 0;
}

static void clear_run_state(sh_t *sh)
{
    sh->in_isr = 0;
    sh->in_loop = 0;
    sh->seen_sei = 0;
    sh->seen_loop = 0;
    sh->rx_head_last = 0;
    sh->rx_over_last = 0;
    sh->rxq_head = sh->rxq_n = sh->rxq_untimed = 0;
    sh->portc_last = 0;
    sh->t1_ovf_n = 0;
    sh->rx_unanswered = 0;
}

sh_t *sh_new(const char *elf_path, uint16_t rx_head_addr, uint16_t rx_over_addr,
             uint16_t bss_end)
{
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    avr_global_logger_set(quiet_logger);
    if (elf_read_firmware(elf_path, &fw) != 0) {
        return NULL;
    }
    avr_t *avr = avr_make_mcu_by_name("atmega128");
    if (!avr) {
        return NULL;
    }
    avr_init(avr);
    avr->frequency = 16000000u;
    avr->log = 0;
    avr_load_firmware(avr, &fw);
    avr->frequency = 16000000u;
    avr->sleep = count_sleep;
    avr->log = 0;
    sh_t *sh = calloc(1, sizeof *sh);
    if (!sh) {
        return NULL;
    }
    sh->avr = avr;
    avr->custom.data = sh;
    sh->rx_head_addr = rx_head_addr;
    sh->rx_over_addr = rx_over_addr;
    sh->bss_end = bss_end;
    apply_workarounds(sh);
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)AVR_UART_FLAG_STDIO;
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            on_uart_out, sh);
    for (avr_io_t *io = avr->io_port; io; io = io->next) {
        if (io->kind && strcmp(io->kind, "uart") == 0 && ((avr_uart_t *)io)->name == '0') {
            sh->uart = (avr_uart_t *)io;
        }
    }
    for (int p = 0; p < 7; p++) {
        for (int b = 0; b < 8; b++) {
            sh->pins[p][b] = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ('A' + p), b);
        }
    }
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ('C'), IOPORT_IRQ_PIN_ALL),
                            on_portc, sh);
    avr_irq_register_notify(avr_get_interrupt_irq(avr, SH_VECTOR_TIMER1_OVF), on_tov1, sh);
    for (int ch = 0; ch < 3; ch++) {
        avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ('B'), 5 + ch),
                                on_oc1_pin, sh);
    }
    sh->byte_cycles = 10u * 8u * 17u; /* 8N1 at UBRR 16, U2X 1 */
    paint(sh);
    return sh;
}

int sh_line_init(sh_t *sh, uint32_t capacity)
{
    free(sh->line_cycle);
    free(sh->line_byte);
    sh->line_cycle = calloc(capacity ? capacity : 1u, sizeof *sh->line_cycle);
    sh->line_byte = calloc(capacity ? capacity : 1u, 1);
    sh->line_cap = capacity;
    sh->line_head = sh->line_n = 0;
    return sh->line_cycle && sh->line_byte;
}

uint32_t sh_line_put(sh_t *sh, uint64_t start, const uint8_t *bytes, uint32_t n)
{
    uint32_t room = sh->line_cap - sh->line_n, take = n < room ? n : room;
    for (uint32_t i = 0; i < take; i++) {
        uint32_t at = (sh->line_head + sh->line_n + i) % sh->line_cap;
        sh->line_cycle[at] = start + i * sh->byte_cycles;
        sh->line_byte[at] = bytes[i];
    }
    sh->line_n += take;
    return take;
}

uint32_t sh_line_pending(const sh_t *sh) { return sh->line_n; }

uint32_t sh_rx_bytes(const sh_t *sh) { return sh->rx_bytes; }

void sh_free(sh_t *sh)
{
    if (sh) {
        free(sh->line_cycle);
        free(sh->line_byte);
        avr_terminate(sh->avr);
        free(sh->avr);
        free(sh);
    }
}

void sh_reset(sh_t *sh)
{
    avr_reset(sh->avr);
    apply_workarounds(sh);
    /* avr_reset clears the I/O space only: data and bss go back to the zeros a new core starts
     * with, so nothing of the old run (the handshake flag) is read before the C runtime runs */
    if (sh->bss_end > RAM_START) {
        memset(sh->avr->data + RAM_START, 0, (size_t)(sh->bss_end - RAM_START));
    }
    paint(sh);
    clear_run_state(sh);
    sh->prof.resets++;
}

uint64_t sh_cycle(const sh_t *sh) { return sh->avr->cycle; }

int sh_state(const sh_t *sh) { return sh->avr->state; }

/* 1 once the firmware's main loop has begun since the last reset (once it has enabled
 * interrupts when no loop address is set): its start-up is over */
int sh_booted(const sh_t *sh) { return sh->loop_addr ? sh->seen_loop : sh->seen_sei; }

void sh_set_byte_cycles(sh_t *sh, uint32_t cycles) { sh->byte_cycles = cycles; }

void sh_set_loop_addr(sh_t *sh, uint32_t addr) { sh->loop_addr = addr; }

void sh_set_idle_addrs(sh_t *sh, uint16_t rx_tail, uint16_t tx_head, uint16_t tx_tail,
                       uint16_t next_telemetry, uint16_t telemetry_hz)
{
    sh->rx_tail_addr = rx_tail;
    sh->tx_head_addr = tx_head;
    sh->tx_tail_addr = tx_tail;
    sh->next_tel_addr = next_telemetry;
    sh->tel_hz_addr = telemetry_hz;
}

/* The profile's bookkeeping after an instruction whose I flag, PC or SP may change what it
 * holds (sh_run_to takes the others on its fast path): interrupt entries and exits, the
 * interrupts-off stretches, main-loop passes and the lowest stack pointer. */
static void watch_core(sh_t *sh, uint64_t before, uint32_t pc_before, uint8_t ie, uint16_t sp)
{
    avr_t *avr = sh->avr;
    uint64_t now = avr->cycle;
    /* interrupt entry: the PC lands on a vector with I cleared */
    if (!sh->in_isr && !ie && avr->pc < VECTORS * 4u && avr->pc != 0) {
        sh->in_isr = 1;
        sh->isr_vec = (uint8_t)(avr->pc / 4u);
        sh->isr_start = before;
    } else if (sh->in_isr && ie) {
        uint64_t len = now - sh->isr_start;
        if (len > sh->prof.isr_max_cycles[sh->isr_vec]) {
            sh->prof.isr_max_cycles[sh->isr_vec] = (uint32_t)len;
        }
        sh->prof.isr_count[sh->isr_vec]++;
        sh->in_isr = 0;
    }
    if (ie) {
        if (sh->seen_sei && sh->ioff_start) {
            uint64_t len = before - sh->ioff_start;
            if (len > sh->prof.irq_off_max_cycles) {
                sh->prof.irq_off_max_cycles = (uint32_t)len;
                sh->prof.irq_off_max_from_pc = sh->ioff_pc;
                sh->prof.irq_off_max_to_pc = pc_before;
            }
        }
        sh->seen_sei = 1;
        sh->ioff_start = 0;
    } else if (sh->seen_sei && !sh->ioff_start) {
        sh->ioff_start = before;
        sh->ioff_pc = sh->in_isr ? (uint32_t)avr->pc : pc_before;
    }
    /* one main-loop pass: fw_loop's entry to its return (ISRs that hit it included) */
    if (sh->loop_addr && !sh->in_loop && avr->pc == sh->loop_addr) {
        sh->in_loop = 1;
        sh->seen_loop = 1;
        sh->loop_sp = sp;
        sh->loop_start = before;
    } else if (sh->in_loop && sp > sh->loop_sp) {
        uint64_t len = now - sh->loop_start;
        if (len > sh->prof.loop_max_cycles) {
            sh->prof.loop_max_cycles = (uint32_t)len;
        }
        sh->prof.loop_count++;
        sh->in_loop = 0;
    }
    if (sh->seen_sei && (sh->prof.sp_min == 0 || sp < sh->prof.sp_min)) {
        sh->prof.sp_min = sp;
    }
}

/* After an instruction that left the core asleep: with the USART and the RX ring empty, the
 * main loop has handled (and answered) every byte received so far, since it sleeps only when
 * no work is pending. */
static void watch_answered(sh_t *sh)
{
    const avr_t *avr = sh->avr;
    if (sh->uart && sh->rx_tail_addr && uart_fifo_isempty(&sh->uart->input) &&
        avr->data[sh->rx_head_addr] == avr->data[sh->rx_tail_addr]) {
        sh->rx_unanswered = 0;
    }
}

/* Whether a byte handed to the USART is awaited in the RX ring (the latency's queue). */
static inline int rx_awaited(const sh_t *sh)
{
    return sh->rx_head_addr && (sh->rxq_n || sh->rxq_untimed);
}

/* After an instruction while a byte is awaited: a byte reached the RX ring (or was counted as
 * a ring overrun), its latency from its stop bit counted; only a byte handed to the USART
 * moves either, so nothing is read while none is awaited. Returns rx_awaited after it. */
static inline int watch_rx_latency(sh_t *sh)
{
    const avr_t *avr = sh->avr;
    uint8_t head = avr->data[sh->rx_head_addr];
    uint32_t over;
    memcpy(&over, avr->data + sh->rx_over_addr, 4);
    if (head == sh->rx_head_last && over == sh->rx_over_last) {
        return 1;
    }
    unsigned moved = ((uint8_t)(head - sh->rx_head_last) & (RX_RING_BYTES - 1u)) +
                     (over - sh->rx_over_last);
    sh->rx_head_last = head;
    sh->rx_over_last = over;
    while (moved && sh->rxq_untimed) {
        moved--;
        sh->rxq_untimed--;
    }
    uint64_t now = avr->cycle;
    while (moved-- && sh->rxq_n) {
        uint64_t stop = sh->rxq[sh->rxq_head];
        sh->rxq_head = (sh->rxq_head + 1u) % RXQ_MAX;
        sh->rxq_n--;
        uint64_t lat = now > stop ? now - stop : 0;
        if (lat > sh->prof.rx_latency_max_cycles) {
            sh->prof.rx_latency_max_cycles = (uint32_t)lat;
        }
    }
    return rx_awaited(sh);
}

/* simavr 1.6 derives USART0's byte time when UBRRnL is written, counting a parity bit always
 * and the U2X in force then (the firmware sets U2X after UBRR): 2992 cycles instead of 1360 for
 * 8N1 at 117 647 baud. The byte time of the configured line is put back before each step. */
static inline void fix_byte_time(sh_t *sh)
{
    if (sh->uart) {
        sh->uart->cycles_per_byte = sh->byte_cycles;
    }
}

/* One step of the core: what simavr 1.6's avr_run does through avr_callback_run_raw
 * (sim_avr.c), inlined so that a step costs little more than its instruction: avr_run_one,
 * the cycle timers (processed only when the earliest one is due; otherwise the time to it is
 * the sleep it returns, with run_cycle_count bounded as avr_cycle_timer_process bounds it),
 * the sleep, then the interrupts. Used only while the core runs the raw callback (no gdb). */
static inline void step(avr_t *avr)
{
    avr_flashaddr_t new_pc = avr->pc;
    if (avr->state == cpu_Running) {
        new_pc = avr_run_one(avr);
    }
    avr_cycle_count_t sleep;
    const avr_cycle_timer_slot_t *t = avr->cycle_timers.timer;
    if (t && t->when > avr->cycle) {
        sleep = t->when - avr->cycle;
        avr_cycle_count_t run = avr->run_cycle_limit >= sleep ? sleep : avr->run_cycle_limit;
        avr->run_cycle_count = run ? run : 1;
    } else {
        sleep = avr_cycle_timer_process(avr);
    }
    avr->pc = new_pc;
    if (avr->state == cpu_Sleeping) {
        if (!avr->sreg[S_I]) {
            avr->state = cpu_Done;
            return;
        }
        avr->sleep(avr, sleep);
        avr->cycle += 1 + sleep;
    }
    if ((avr->state == cpu_Running || avr->state == cpu_Sleeping) && avr->interrupt_state) {
        avr_service_interrupts(avr);
    }
}

int sh_run_to(sh_t *sh, uint64_t target)
{
    avr_t *avr = sh->avr;
    sh->stop = 0;
    fix_byte_time(sh);
    if (avr->cycle >= target) {
        return SH_REACHED;
    }
    if (sh->timer_armed != target) {
        avr_cycle_timer_cancel(avr, wake_at_target, sh);
        avr_cycle_timer_register(avr, target - avr->cycle, wake_at_target, sh);
        sh->timer_armed = target;
    }
    const int raw = avr->run == avr_callback_run_raw;
    /* watch_core's fast path: an instruction after which the I flag is what watch_core last
     * saw, the PC is outside the vectors and off fw_loop's entry, and the SP within
     * [sp_lo, sp_hi] (not below the lowest seen once counted, not above a pass's start) changes
     * nothing it holds. The first instruction of a run is always watched. */
    uint8_t last_ie = 2;
    uint32_t sp_lo = 0, sp_hi = 0;
    int rx = rx_awaited(sh); /* only sh_uart_in, between runs, adds an awaited byte */
    while (avr->cycle < target) {
        uint64_t before = avr->cycle;
        uint32_t pc_before = avr->pc;
        int state;
        if (raw) {
            step(avr);
            state = avr->state;
        } else {
            state = avr_run(avr);
        }
        if (state == cpu_Done || state == cpu_Crashed) {
            return SH_CRASHED;
        }
        uint8_t ie = avr->sreg[S_I];
        uint16_t sp = (uint16_t)(avr->data[R_SPL] | (avr->data[R_SPH] << 8));
        if (ie != last_ie || avr->pc < VECTORS * 4u || avr->pc == sh->loop_addr || sp < sp_lo ||
            sp > sp_hi) {
            watch_core(sh, before, pc_before, ie, sp);
            last_ie = ie;
            sp_lo = !sh->seen_sei ? 0u : sh->prof.sp_min ? sh->prof.sp_min : 0x10000u;
            sp_hi = sh->in_loop ? sh->loop_sp : 0xFFFFu;
        }
        if (rx) {
            rx = watch_rx_latency(sh);
        }
        if (state == cpu_Sleeping && sh->rx_unanswered) {
            watch_answered(sh);
        }
        if (sh->stop) {
            return SH_STOPPED;
        }
    }
    return SH_REACHED;
}

/* PD bits of (A, B) of the left and right wheel; (A << 1 | B) at count % 4, hal_avr.c's x4 */
static const uint8_t enc_pins[2][2] = {{0, 1}, {2, 3}};
static const uint8_t enc_quad[4] = {0u, 1u, 3u, 2u};

static uint64_t enc_next(const enc_t *e)
{
    if (e->k >= e->n) {
        return UINT64_MAX;
    }
    uint64_t k = e->k + 1u;
    return e->spread ? e->start + e->span * k / e->n : e->start + SH_INSTANT_EDGE_CYCLES * k;
}

static void enc_show(sh_t *sh, int side, int64_t old_pos, int64_t new_pos)
{
    uint8_t old = enc_quad[old_pos & 3], now = enc_quad[new_pos & 3];
    avr_irq_t **port = sh->pins[3]; /* PORTD */
    if ((old ^ now) & 2u) {
        avr_raise_irq(port[enc_pins[side][0]], now >> 1);
    }
    if ((old ^ now) & 1u) {
        avr_raise_irq(port[enc_pins[side][1]], now & 1u);
    }
}

void sh_enc_apply(sh_t *sh, uint64_t until)
{
    for (int side = 0; side < 2; side++) {
        enc_t *e = &sh->enc[side];
        while (enc_next(e) <= until) {
            e->k++;
            int64_t pos = e->pos0 + e->dir * (int64_t)e->k;
            enc_show(sh, side, sh->enc_pos[side], pos);
            sh->enc_pos[side] = pos;
        }
    }
}

void sh_enc_set(sh_t *sh, uint8_t side, uint64_t now, uint64_t span, int64_t count)
{
    enc_t *e = &sh->enc[side & 1u];
    int64_t pos = sh->enc_pos[side & 1u];
    uint64_t n = (uint64_t)(count > pos ? count - pos : pos - count);
    e->start = now;
    e->span = span;
    e->pos0 = pos;
    e->n = (uint32_t)n;
    e->k = 0;
    e->dir = count > pos ? 1 : -1;
    e->spread = span >= n * SH_INSTANT_EDGE_CYCLES;
}

void sh_enc_show_all(sh_t *sh)
{
    for (int side = 0; side < 2; side++) {
        uint8_t ab = enc_quad[sh->enc_pos[side] & 3];
        avr_raise_irq(sh->pins[3][enc_pins[side][0]], ab >> 1);
        avr_raise_irq(sh->pins[3][enc_pins[side][1]], ab & 1u);
    }
}

int64_t sh_enc_pos(const sh_t *sh, uint8_t side) { return sh->enc_pos[side & 1u]; }

uint64_t sh_events(const sh_t *sh) { return sh->events; }

/* Run to `limit` (the caller's next event: its target or a pin level), stopping at each RX
 * line byte's start bit and encoder edge before it to hand the byte to USART0 / show the edge:
 * one run of the core per event time. Returns as soon as a run ends at or past `limit` (the
 * line's bytes due by then handed over; the caller then applies its pin levels and calls
 * sh_enc_apply), or at a stop (a sonar trigger) or a crash, with nothing applied. The order
 * at one time: line bytes, pin levels, encoder edges. */
int sh_advance(sh_t *sh, uint64_t limit)
{
    for (;;) {
        uint64_t nxt = limit, e0 = enc_next(&sh->enc[0]), e1 = enc_next(&sh->enc[1]);
        if (sh->line_n && sh->line_cycle[sh->line_head] < nxt) {
            nxt = sh->line_cycle[sh->line_head];
        }
        if (e0 < nxt) {
            nxt = e0;
        }
        if (e1 < nxt) {
            nxt = e1;
        }
        int rc = sh_run_to(sh, nxt);
        sh->events++;
        if (rc != SH_REACHED) {
            return rc;
        }
        uint64_t now = sh->avr->cycle > nxt ? sh->avr->cycle : nxt;
        while (sh->line_n && sh->line_cycle[sh->line_head] <= now) {
            uint8_t byte = sh->line_byte[sh->line_head];
            sh->line_head = (sh->line_head + 1u) % sh->line_cap;
            sh->line_n--;
            sh->rx_bytes += (uint32_t)sh_uart_in(sh, byte);
        }
        if (now >= limit) {
            return SH_REACHED;
        }
        sh_enc_apply(sh, now);
    }
}

void sh_pin(sh_t *sh, uint8_t port, uint8_t bit, uint8_t level)
{
    avr_raise_irq(sh->pins[port][bit & 7u], level ? 1u : 0u);
}

int sh_pin_at(sh_t *sh, uint64_t cycle, uint8_t port, uint8_t bit, uint8_t level)
{
    if (sh->pinq_n >= PINQ_MAX || port >= 7u) {
        return 0;
    }
    uint32_t i = sh->pinq_n;
    while (i > 0 && sh->pinq[i - 1u].cycle > cycle) {
        sh->pinq[i] = sh->pinq[i - 1u];
        i--;
    }
    sh->pinq[i].cycle = cycle;
    sh->pinq[i].port = port;
    sh->pinq[i].bit = bit;
    sh->pinq[i].level = level;
    sh->pinq_n++;
    return 1;
}

/* Signed duties (left, right), -255..255: OCR0/OCR2 while Timer0/Timer2 run, the sign from
 * the direction pins PA0/PA1 (data-space addresses of the ATmega128's register summary). */
void sh_wheel_duty(const sh_t *sh, int16_t duty[2])
{
    static const uint8_t ocr[2] = {0x51, 0x43}, tccr[2] = {0x53, 0x45};
    const uint8_t *d = sh->avr->data;
    for (int side = 0; side < 2; side++) {
        int16_t v = (d[tccr[side]] & 7u) ? d[ocr[side]] : 0;
        duty[side] = (int16_t)(((d[0x3B] >> side) & 1u) ? -v : v);
    }
}

/* Run to `target`: sh_advance between the queued pin levels, each applied at its cycle (after
 * the RX line's bytes due by then, before the encoder edges). Returns SH_STOPPED at a sonar
 * trigger (the caller schedules its echo with sh_pin_at and calls again) or SH_CRASHED with
 * nothing applied, else SH_REACHED with `out` filled for the cycle reached. */
int sh_advance_to(sh_t *sh, uint64_t target, sh_outputs_t *out)
{
    for (;;) {
        uint64_t nxt = target;
        if (sh->pinq_n && sh->pinq[0].cycle < nxt) {
            nxt = sh->pinq[0].cycle;
        }
        int rc = sh_advance(sh, nxt);
        if (rc != SH_REACHED) {
            return rc;
        }
        uint64_t now = sh->avr->cycle > nxt ? sh->avr->cycle : nxt;
        uint32_t k = 0;
        while (k < sh->pinq_n && sh->pinq[k].cycle <= now) {
            sh_pin(sh, sh->pinq[k].port, sh->pinq[k].bit, sh->pinq[k].level);
            k++;
        }
        if (k) {
            sh->pinq_n -= k;
            memmove(sh->pinq, sh->pinq + k, sh->pinq_n * sizeof sh->pinq[0]);
        }
        sh_enc_apply(sh, now);
        if (nxt >= target) {
            break;
        }
    }
    sh_wheel_duty(sh, out->duty);
    out->periods = sh->per_n;
    uint32_t due = 0;
    while (due < sh->tx_n && sh->tx_cycle[due] <= sh->avr->cycle) {
        due++;
    }
    out->tx_due = due;
    return SH_REACHED;
}

int sh_uart_in(sh_t *sh, uint8_t byte)
{
    /* The part holds two received bytes (UDR's FIFO) plus the one in the shift register;
     * simavr's 64-byte FIFO would hide a slow ISR, so a byte whose start bit comes while three
     * are unread is lost (data overrun). A byte that starts while the receiver is off (the
     * first cycles after a reset) is lost too: simavr drops it, and it must not be waited
     * for in the RX latency's queue. */
    if (!sh->uart || !avr_regbit_get(sh->avr, sh->uart->rxen) ||
        uart_fifo_get_read_size(&sh->uart->input) >= 3) {
        sh->rx_line_lost++;
        return 0;
    }
    fix_byte_time(sh);
    avr_raise_irq(avr_io_getirq(sh->avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT), byte);
    sh->rx_unanswered = 1;
    if (!sh->seen_sei || sh->rxq_untimed) {
        sh->rxq_untimed++;
    } else if (sh->rxq_n < RXQ_MAX) {
        sh->rxq[(sh->rxq_head + sh->rxq_n) % RXQ_MAX] = sh->avr->cycle + sh->byte_cycles;
        sh->rxq_n++;
    }
    return 1;
}

uint32_t sh_rx_line_lost(const sh_t *sh) { return sh->rx_line_lost; }

uint32_t sh_tx_take(sh_t *sh, uint8_t *bytes, uint64_t *cycles, uint32_t max)
{
    uint32_t n = 0;
    while (n < sh->tx_n && n < max && sh->tx_cycle[n] <= sh->avr->cycle) {
        bytes[n] = sh->tx_byte[n];
        cycles[n] = sh->tx_cycle[n];
        n++;
    }
    memmove(sh->tx_byte, sh->tx_byte + n, sh->tx_n - n);
    memmove(sh->tx_cycle, sh->tx_cycle + n, (sh->tx_n - n) * sizeof(uint64_t));
    sh->tx_n -= n;
    return n;
}

uint32_t sh_tx_pending(const sh_t *sh) { return sh->tx_n; }

uint64_t sh_tx_line_free(const sh_t *sh) { return sh->tx_line_free; }

uint32_t sh_triggers_take(sh_t *sh, uint8_t *idx, uint64_t *cycles, uint32_t max)
{
    uint32_t n = sh->trig_n < max ? sh->trig_n : max;
    memcpy(idx, sh->trig_idx, n);
    memcpy(cycles, sh->trig_cycle, n * sizeof(uint64_t));
    memmove(sh->trig_idx, sh->trig_idx + n, sh->trig_n - n);
    memmove(sh->trig_cycle, sh->trig_cycle + n, (sh->trig_n - n) * sizeof(uint64_t));
    sh->trig_n -= n;
    return n;
}

uint32_t sh_periods_take(sh_t *sh, uint64_t *cycles, uint16_t *regs, uint32_t max)
{
    uint32_t n = sh->per_n < max ? sh->per_n : max;
    memcpy(cycles, sh->per_cycle, n * sizeof(uint64_t));
    memcpy(regs, sh->per_regs, n * sizeof sh->per_regs[0]);
    memmove(sh->per_cycle, sh->per_cycle + n, (sh->per_n - n) * sizeof(uint64_t));
    memmove(sh->per_regs, sh->per_regs + n, (sh->per_n - n) * sizeof sh->per_regs[0]);
    sh->per_n -= n;
    return n;
}

void sh_read(const sh_t *sh, uint16_t addr, uint8_t *dst, uint16_t n)
{
    const avr_t *avr = sh->avr;
    for (uint16_t i = 0; i < n; i++) {
        dst[i] = (uint32_t)addr + i <= avr->ramend ? avr->data[addr + i] : 0u;
    }
}

void sh_profile(const sh_t *sh, sh_profile_t *out)
{
    *out = sh->prof;
    /* deepest stack: the lowest byte above the firmware's data that lost its paint */
    const avr_t *avr = sh->avr;
    uint32_t a = sh->bss_end;
    while (a <= avr->ramend && avr->data[a] == PAINT) {
        a++;
    }
    out->stack_depth_bytes = avr->ramend >= a ? (uint32_t)(avr->ramend - a + 1u) : 0u;
}

uint32_t sh_pc(const sh_t *sh) { return sh->avr->pc; }

uint32_t sh_rx_unread(const sh_t *sh)
{
    return sh->uart ? (uint32_t)uart_fifo_get_read_size((uart_fifo_t *)&sh->uart->input) : 0u;
}

/* *cycle: a cycle through which no byte the firmware sends can finish leaving TX0, provided
 * nothing more is received: 0 (the caller's now) while host bytes are on the RX line, now
 * while a byte is leaving or queued, while a received byte may be
 * unanswered (the core has not slept since it came: the main loop sleeps only when it has
 * handled every byte, and every message but the telemetry answers a frame), before the
 * start-up's end or Timer1's first overflow; else the next telemetry time (fw/program.c), in
 * core cycles by hal_micros()'s clock. Returns 0 (and no cycle) when telemetry is off and
 * nothing is pending: the firmware sends nothing until it receives something. */
int sh_tx_idle_through(const sh_t *sh, uint64_t *cycle)
{
    const avr_t *avr = sh->avr;
    const uint8_t *d = avr->data;
    uint64_t now = avr->cycle;
    if (sh->line_n) { /* bytes on the RX line either way: the caller's now */
        *cycle = 0;
        return 1;
    }
    *cycle = now;
    if (!sh->next_tel_addr || !sh->seen_sei || !sh->t1_ovf_n || sh->rx_unanswered ||
        !sh->uart || !uart_fifo_isempty((uart_fifo_t *)&sh->uart->input) ||
        d[sh->rx_head_addr] != d[sh->rx_tail_addr] ||
        d[sh->tx_head_addr] != d[sh->tx_tail_addr] || sh->tx_line_free > now) {
        return 1;
    }
    int32_t hz;
    uint32_t next;
    memcpy(&hz, d + sh->tel_hz_addr, 4);
    memcpy(&next, d + sh->next_tel_addr, 4);
    if (hz == 0) {
        return 0;
    }
    /* hal_micros() was t1_ovf_n * 20 000 us at the last overflow's cycle */
    int32_t after_ovf_us = (int32_t)(next - sh->t1_ovf_n * 20000u);
    int64_t due = (int64_t)sh->t1_ovf_cycle + (int64_t)after_ovf_us * 16;
    if (due > (int64_t)now) {
        *cycle = (uint64_t)due;
    }
    return 1;
}
