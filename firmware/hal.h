/* The hardware the firmware talks to (ArduPilot AP_HAL style): one header, two implementations.
 * hal_avr.c drives the ATmega128's registers and owns the interrupt vectors and main();
 * hal_native.c hands every call to the Python peripheral models (mcu_sim/avr) through cffi.
 * The firmware (fw/) never touches a register. */
#ifndef MOBIGRASP_HAL_H
#define MOBIGRASP_HAL_H

#include <stdint.h>

/* Globals of the firmware carry FW_STATE: on the native build they are gathered in one
 * section, so the glue can keep one copy of them per emulated MCU. */
#ifdef FW_NATIVE
#define FW_STATE __attribute__((section("mobigrasp_fw")))
#else
#define FW_STATE
#endif

/* Constant tables that live in flash (program memory) on the AVR, and their reader. */
#ifdef __AVR__
#include <avr/pgmspace.h>
#define HAL_FLASH PROGMEM
#define hal_flash_read(dst, src, n) memcpy_P((dst), (src), (n))
#else
#include <string.h>
#define HAL_FLASH
#define hal_flash_read(dst, src, n) memcpy((dst), (src), (n))
#endif

/* Time since reset in µs (wraps after 71 minutes; compare with signed differences). */
uint32_t hal_micros(void);

/* Timer1 and Timer3 (servo channels 0..2 and 3..5): TCCRnA, ICRn, OCRnx, then TCCRnB starts
 * both (OCRnx latched at BOTTOM once running). */
void hal_servo_timers_config(uint8_t tccra, uint16_t icr);
void hal_servo_timers_start(uint8_t tccrb);
void hal_servo_ocr(uint8_t ch, uint16_t ocr);

/* Wheel bridges (0 left, 1 right): start the 8-bit PWM, set the direction pin, write OCR
 * (double-buffered, effective at the next PWM BOTTOM). */
void hal_wheel_start(uint8_t side);
void hal_wheel_direction(uint8_t side, uint8_t reverse);
void hal_wheel_ocr(uint8_t side, uint8_t ocr);

/* Queue ``n`` bytes for USART0 if all fit in the TX ring: 1, else 0 and nothing queued. */
uint8_t hal_uart_send(const uint8_t *data, uint8_t n);
/* Bytes the receiver lost before they reached the RX ring (data overrun, line side). */
uint32_t hal_uart_rx_lost(void);

/* Trigger pulse on sonar ``index``. */
void hal_sonar_trigger(uint8_t index);

/* A build-time power-on value of PARAM ``id`` (none on the AVR build; the emulator's McuConfig
 * on the native one): 1 and *value set, or 0 to keep the table's default. */
uint8_t hal_boot_param(uint16_t id, int32_t *value);

/* Interrupts off around a multi-byte read of a variable an ISR writes. */
uint8_t hal_irq_save(void);
void hal_irq_restore(uint8_t state);

#endif
