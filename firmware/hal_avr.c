/* The HAL on the ATmega128 at 16 MHz: registers, the interrupt vectors and main().
 * Pins are those of board.h (generated from mcu_sim/avr/pinmap.py). Every ISR stores what
 * happened and returns; the main loop (fw_loop) does the work and sleeps (idle mode) until a
 * handler leaves work for it or Timer0's tick finds something due. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <util/atomic.h>

#include "board.h"
#include "fw/program.h"
#include "hal.h"

#define TX_RING_BYTES 128u

static volatile uint32_t timer1_overflows; /* 20 ms periods since reset */
static uint8_t tx_ring[TX_RING_BYTES];
static volatile uint8_t tx_head;
static volatile uint8_t tx_tail;
static volatile uint32_t rx_lost; /* data overruns and framing errors seen by the receiver */
static volatile uint8_t enc_state[2]; /* last A/B levels of each encoder */
static volatile uint8_t wheel_r_on; /* right wheel soft PWM: drive the pin at BOTTOM */
static volatile uint8_t ticks_to_look; /* Timer0 ticks (1.024 ms) before the clock is read */
static volatile uint8_t look_now;      /* they have passed: read the clock */

/* -- clock: Timer1 periods plus TCNT1 (0.5 us ticks) ------------------------------------- */
uint32_t hal_micros(void)
{
    uint32_t periods;
    uint16_t ticks;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        periods = timer1_overflows;
        ticks = TCNT1;
        if ((TIFR & _BV(TOV1)) && ticks < 20000u) { /* overflow pending, not yet counted */
            periods++;
        }
    }
    return periods * 20000ul + ticks / 2u;
}

uint8_t hal_irq_save(void)
{
    uint8_t s = SREG;
    cli();
    return s;
}

void hal_irq_restore(uint8_t state) { SREG = state; }

/* -- servo timers ------------------------------------------------------------------------- */
void hal_servo_timers_config(uint8_t tccra, uint16_t icr)
{
    DDRB |= _BV(SERVO0_BIT) | _BV(SERVO1_BIT) | _BV(SERVO2_BIT);
    DDRE |= _BV(SERVO3_BIT) | _BV(SERVO4_BIT) | _BV(SERVO5_BIT);
    TCCR1A = tccra;
    TCCR3A = tccra;
    ICR1 = icr;
    ICR3 = icr;
}

void hal_servo_timers_start(uint8_t tccrb)
{
    /* Timer1 runs since .init3 (the clock): Timer3 starts in its phase, TCNT3 written one
     * 0.5 us tick ahead of the TCNT1 read (the copy takes under 8 cycles), and Timer1's mode
     * and clock stay as they are (TCCR1B is written with the value it has) */
    TCNT3 = (uint16_t)(TCNT1 + 1u);
    TCCR3B = tccrb;
    TIMSK |= _BV(TOIE1);
    TCCR1B = tccrb;
}

void hal_servo_ocr(uint8_t ch, uint16_t ocr)
{
    switch (ch) {
    case 0: OCR1A = ocr; break;
    case 1: OCR1B = ocr; break;
    case 2: OCR1C = ocr; break;
    case 3: OCR3A = ocr; break;
    case 4: OCR3B = ocr; break;
    default: OCR3C = ocr; break;
    }
}

/* -- wheels: Timer0 fast PWM on OC0 (left), Timer2 fast PWM by interrupts on a port pin
 * (right: OC2 is PB7, which OC1C drives); both clk/64, 976.6 Hz ------------------------- */
void hal_wheel_start(uint8_t side)
{
    if (side == 0) {
        WHEEL_L_PWM_DDR |= _BV(WHEEL_L_PWM_BIT);
        WHEEL_L_DIR_DDR |= _BV(WHEEL_L_DIR_BIT);
        TCCR0 = _BV(WGM00) | _BV(WGM01) | _BV(COM01) | _BV(CS02); /* fast PWM, clk/64 */
        TIMSK |= _BV(TOIE0); /* the scheduler's tick, every 1.024 ms */
    } else {
        WHEEL_R_PWM_DDR |= _BV(WHEEL_R_PWM_BIT);
        WHEEL_R_DIR_DDR |= _BV(WHEEL_R_DIR_BIT);
        TCCR2 = _BV(WGM20) | _BV(WGM21) | _BV(CS21) | _BV(CS20); /* fast PWM, clk/64 */
        TIMSK |= _BV(TOIE2) | _BV(OCIE2);
    }
}

void hal_wheel_direction(uint8_t side, uint8_t reverse)
{
    if (side == 0) {
        if (reverse) WHEEL_L_DIR_PORT |= _BV(WHEEL_L_DIR_BIT);
        else WHEEL_L_DIR_PORT &= (uint8_t)~_BV(WHEEL_L_DIR_BIT);
    } else {
        if (reverse) WHEEL_R_DIR_PORT |= _BV(WHEEL_R_DIR_BIT);
        else WHEEL_R_DIR_PORT &= (uint8_t)~_BV(WHEEL_R_DIR_BIT);
    }
}

void hal_wheel_ocr(uint8_t side, uint8_t ocr)
{
    if (side == 0) {
        OCR0 = ocr;
        return;
    }
    OCR2 = ocr;
    /* the right wheel's pin switches within a period only for a duty strictly between 0 and
     * 255: at either end it is held (from now, not the next BOTTOM) and Timer2's two
     * interrupts stay off, 1953 wake-ups a second fewer while the wheel stands */
    if (ocr == 0 || ocr == 0xFF) {
        TIMSK &= (uint8_t)~(_BV(TOIE2) | _BV(OCIE2));
        if (ocr) WHEEL_R_PWM_PORT |= _BV(WHEEL_R_PWM_BIT);
        else WHEEL_R_PWM_PORT &= (uint8_t)~_BV(WHEEL_R_PWM_BIT);
    } else if (!(TIMSK & _BV(TOIE2))) {
        TIFR = _BV(TOV2) | _BV(OCF2); /* stale flags would switch the pin mid-period */
        TIMSK |= _BV(TOIE2) | _BV(OCIE2);
    }
}

/* The scheduler's tick: counts down the ticks the main loop asked to sleep through. */
ISR(TIMER0_OVF_vect)
{
    if (ticks_to_look && --ticks_to_look == 0) {
        look_now = 1;
    }
}

ISR(TIMER2_OVF_vect)
{
    wheel_r_on = OCR2 != 0;
    if (wheel_r_on) WHEEL_R_PWM_PORT |= _BV(WHEEL_R_PWM_BIT);
}

ISR(TIMER2_COMP_vect)
{
    if (OCR2 != 0xFF) WHEEL_R_PWM_PORT &= (uint8_t)~_BV(WHEEL_R_PWM_BIT);
}

/* -- USART0, 8N1, U2X = 1, UBRR = 16: 117 647 baud (+2.1 % against 115 200) -------------- */
void uart_init(void); /* called from .init3 only */
void uart_init(void)
{
    UBRR0H = 0;
    UBRR0L = 16;
    UCSR0A = _BV(U2X0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
}

/* The receiver is the first thing the part starts, before the C runtime clears .bss (some
 * 0.37 ms): .init3 runs right after the stack pointer is set and r1 cleared. Its handler runs
 * from main's sei on; until then the USART holds what arrives (two bytes and the one shifting
 * in). A call from .init3 falls through to .init4 when it returns. */
__asm__(".section .init3,\"ax\",@progbits\n\tcall uart_init\n\t.text");

/* The clock starts at the reset too: Timer1 counts from .init3 in the servo mode (14, TOP
 * ICR1 = 39 999, clk/8: 20 ms periods of 0.5 us ticks, as hal_micros reads it), its outputs
 * off until fw_setup sets the compare modes and the pins. hal_micros is then the time since
 * the reset, as on the native HAL and the Python model, not since the end of the start-up
 * (some 2.2 ms later): the telemetry keeps the models' phase in the 20 ms period. */
void clock_init(void); /* called from .init3 only */
void clock_init(void)
{
    ICR1 = 39999u;
    TCCR1A = _BV(WGM11);
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11);
}
__asm__(".section .init3,\"ax\",@progbits\n\tcall clock_init\n\t.text");

ISR(USART0_RX_vect)
{
    uint8_t status = UCSR0A;
    uint8_t byte = UDR0;
    if (status & (_BV(DOR0) | _BV(FE0))) {
        rx_lost++;
    }
#ifdef FW_TEST_RX_ISR_BUSY_CYCLES
    /* a deliberately slow handler, built only by the simavr timing test */
    __builtin_avr_delay_cycles(FW_TEST_RX_ISR_BUSY_CYCLES);
#endif
    fw_isr_usart_rx(byte);
}

ISR(USART0_UDRE_vect)
{
    if (tx_head == tx_tail) {
        UCSR0B &= (uint8_t)~_BV(UDRIE0);
        return;
    }
    UDR0 = tx_ring[tx_tail];
    tx_tail = (uint8_t)((tx_tail + 1u) % TX_RING_BYTES);
}

uint8_t hal_uart_send(const uint8_t *data, uint8_t n)
{
    uint8_t used = (uint8_t)((tx_head - tx_tail + TX_RING_BYTES) % TX_RING_BYTES);
    if ((uint16_t)used + n > TX_RING_BYTES - 1u) {
        return 0;
    }
    for (uint8_t i = 0; i < n; i++) {
        tx_ring[tx_head] = data[i];
        tx_head = (uint8_t)((tx_head + 1u) % TX_RING_BYTES);
    }
    UCSR0B |= _BV(UDRIE0);
    return 1;
}

uint32_t hal_uart_rx_lost(void)
{
    uint32_t n;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { n = rx_lost; }
    return n;
}

/* -- encoders: INT0..3 on any edge, x4 quadrature decoding ------------------------------- */
static const int8_t quad_step[16] = {0, 1, -1, 0, -1, 0, 0, 1, 1, 0, 0, -1, 0, -1, 1, 0};

static void encoder_edge(uint8_t side, uint8_t ab)
{
    uint8_t idx = (uint8_t)((enc_state[side] << 2) | ab);
    enc_state[side] = ab;
    fw_isr_encoder(side, quad_step[idx]);
}

static uint8_t enc_ab(uint8_t side)
{
    uint8_t pins = ENC_L_A_PIN;
    if (side == 0) {
        return (uint8_t)((((pins >> ENC_L_A_BIT) & 1u) << 1) | ((pins >> ENC_L_B_BIT) & 1u));
    }
    return (uint8_t)((((pins >> ENC_R_A_BIT) & 1u) << 1) | ((pins >> ENC_R_B_BIT) & 1u));
}

ISR(INT0_vect) { encoder_edge(0, enc_ab(0)); }
ISR(INT1_vect, ISR_ALIASOF(INT0_vect));
ISR(INT2_vect) { encoder_edge(1, enc_ab(1)); }
ISR(INT3_vect, ISR_ALIASOF(INT2_vect));

/* -- sonars: triggers on PORTC0..4, the OR-ed echo on INT6, any edge --------------------- */
void hal_sonar_trigger(uint8_t index)
{
    SONAR_TRIG0_PORT |= (uint8_t)_BV(SONAR_TRIG0_BIT + index);
    /* a 10 us trigger pulse: 160 cycles */
    __builtin_avr_delay_cycles(160);
    SONAR_TRIG0_PORT &= (uint8_t)~_BV(SONAR_TRIG0_BIT + index);
}

ISR(INT6_vect)
{
    fw_isr_echo(fw_sonar.index, (SONAR_ECHO_PIN >> SONAR_ECHO_BIT) & 1u);
}

ISR(TIMER1_OVF_vect)
{
    timer1_overflows++;
    fw_isr_timer1_ovf();
}

uint8_t hal_boot_param(uint16_t id, int32_t *value)
{
#ifdef FW_BOOT_PARAMS
    /* PARAM power-on values chosen at build time: {id, value} pairs (an emulated build's
     * McuConfig.params; the host checked them against the table as a PARAM_SET would) */
    static const int32_t chosen[][2] = {FW_BOOT_PARAMS};
    for (uint8_t i = 0; i < sizeof chosen / sizeof chosen[0]; i++) {
        if (chosen[i][0] == (int32_t)id) {
            *value = chosen[i][1];
            return 1;
        }
    }
#endif
    (void)id;
    (void)value;
    return 0;
}

static void io_init(void)
{
    SONAR_TRIG0_DDR |= 0x1Fu; /* PORTC0..4 */
    /* INT0..3 any edge (EICRA ISCn = 01), INT6 any edge (EICRB ISC6 = 01) */
    EICRA = _BV(ISC00) | _BV(ISC10) | _BV(ISC20) | _BV(ISC30);
    EICRB = _BV(ISC60);
    enc_state[0] = enc_ab(0);
    enc_state[1] = enc_ab(1);
    EIMSK = _BV(INT0) | _BV(INT1) | _BV(INT2) | _BV(INT3) | _BV(INT6);
}

/* Sleep until the main loop has work: a handler left some (a frame's end in the RX ring, a
 * servo period) or the due time ``next`` has come. The clock is read only when Timer0 has
 * counted down the whole ticks of the wait (at most three reads per due time, each within a
 * tick of it); encoder edges, the right wheel's PWM and the TX handler wake the core for
 * their own handler only, and the check after such a wake is two flag reads. */
static void wait_for_work(uint32_t next)
{
    for (;;) {
        int32_t left_us = (int32_t)(next - hal_micros());
        if (left_us <= 0) {
            return;
        }
        /* after n ticks more than (n - 1) x 1024 us have passed: look after n = left / 1024
         * ticks, when less than two ticks are left (one, when less than one is) */
        uint8_t ticks = left_us >= 255L * 1024 ? 255u : (uint8_t)((uint32_t)left_us >> 10);
        cli();
        ticks_to_look = ticks ? ticks : 1u;
        look_now = 0;
        while (!fw_work_pending() && !look_now) {
            sleep_enable();
            sei(); /* takes effect after the next instruction: no wake-up is missed */
            sleep_cpu();
            sleep_disable();
            cli();
        }
        ticks_to_look = 0;
        sei();
        if (fw_work_pending()) {
            return;
        }
    }
}

int main(void)
{
    /* the receiver's handler first (the receiver itself runs since .init3): a byte the host
     * sends while the rest starts up is kept in the RX ring (docs/firmware.md, "simavr") */
    fw_setup_rx();
    sei();
    fw_setup();
    io_init(); /* encoder and echo interrupts once their state is set */
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        wait_for_work(fw_loop());
    }
}
