/* The HAL on the machine's own CPU, for the native MCU backend (mcu_sim/native): the Python
 * peripheral models own the registers. The output calls (hal_servo_*, hal_wheel_*,
 * hal_uart_*, hal_sonar_trigger, hal_boot_param) are cffi callbacks into those models
 * (mcu_sim/native/build.py declares them from hal.h); what is defined here is the rest: the clock the
 * emulator sets before each call, no interrupts to mask, and the firmware's globals
 * (section mobigrasp_fw) saved and restored so that one loaded library serves several MCUs. */
#include <string.h>

#include "fw/program.h"
#include "hal.h"
#include "hal_native.h"

uint32_t native_now_us; /* us since reset, set by the emulator before every call */

uint32_t hal_micros(void) { return native_now_us; }
uint8_t hal_irq_save(void) { return 0; }
void hal_irq_restore(uint8_t state) { (void)state; }

/* The emulator hands over all edges since its last look at once: that many ISR calls. */
void native_encoder_edges(uint8_t side, int32_t edges)
{
    fw_enc_count[side] = (int32_t)((uint32_t)fw_enc_count[side] + (uint32_t)edges);
}

void native_usart_rx_bytes(const uint8_t *data, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        fw_isr_usart_rx(data[i]);
    }
}

/* The linker gathers every FW_STATE global between these two symbols. */
extern uint8_t __start_mobigrasp_fw[];
extern uint8_t __stop_mobigrasp_fw[];

uint32_t native_state_size(void) { return (uint32_t)(__stop_mobigrasp_fw - __start_mobigrasp_fw); }
void native_state_save(uint8_t *dst) { memcpy(dst, __start_mobigrasp_fw, native_state_size()); }
void native_state_load(const uint8_t *src) { memcpy(__start_mobigrasp_fw, src, native_state_size()); }
