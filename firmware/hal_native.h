/* What the native HAL (hal_native.c) adds for the emulator (mcu_sim/native): the clock it sets
 * before every call, the edges and bytes it hands over, and the firmware's globals saved and
 * restored so that one loaded library serves several MCUs. */
#ifndef MOBIGRASP_HAL_NATIVE_H
#define MOBIGRASP_HAL_NATIVE_H

#include <stdint.h>

extern uint32_t native_now_us; /* us since reset */

void native_encoder_edges(uint8_t side, int32_t edges);
void native_usart_rx_bytes(const uint8_t *data, uint32_t n);
uint32_t native_state_size(void);
void native_state_save(uint8_t *dst);
void native_state_load(const uint8_t *src);

#endif
