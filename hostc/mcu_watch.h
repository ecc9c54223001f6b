/* Noticing an MCU reset from the host's side (host/mcu_watch.py): once the session was up, a
 * telemetry with FLAG_RESET, without FLAG_HANDSHAKE, or whose u32 time_us went back (by less
 * than half the range: more is a wrap) means the MCU forgot the session. */
#ifndef MOBIGRASP_HOSTC_MCU_WATCH_H
#define MOBIGRASP_HOSTC_MCU_WATCH_H

#include <stdint.h>

enum {
    MG_WATCH_OK = 0,
    MG_WATCH_TIME_WENT_BACK = 1,
    MG_WATCH_FLAG_RESET = 2,
    MG_WATCH_HANDSHAKE_LOST = 3
};

typedef struct {
    int32_t resets;
    int32_t has_last;
    uint32_t last_time_us;
    int32_t session_up;
} mg_mcu_watch_t;

void mg_watch_init(mg_mcu_watch_t *w);
void mg_watch_handshake_done(mg_mcu_watch_t *w);
int32_t mg_watch_feed(mg_mcu_watch_t *w, uint32_t time_us, uint16_t flags); /* the reason */
const char *mg_watch_reason_name(int32_t reason); /* as host/mcu_watch.py names it */

#endif
