/* An MCU reset seen in the telemetry (host/mcu_watch.py). */
#include "mcu_watch.h"

#include "messages.h"

void mg_watch_init(mg_mcu_watch_t *w)
{
    w->resets = 0;
    w->has_last = 0;
    w->last_time_us = 0;
    w->session_up = 0;
}

void mg_watch_handshake_done(mg_mcu_watch_t *w)
{
    w->session_up = 1;
}

int32_t mg_watch_feed(mg_mcu_watch_t *w, uint32_t time_us, uint16_t flags)
{
    int32_t reason = MG_WATCH_OK;
    if (w->has_last && time_us < w->last_time_us && w->last_time_us - time_us < 0x80000000u)
        reason = MG_WATCH_TIME_WENT_BACK;
    if (w->session_up && (flags & FLAG_RESET))
        reason = MG_WATCH_FLAG_RESET;
    else if (w->session_up && !(flags & FLAG_HANDSHAKE) && reason == MG_WATCH_OK)
        reason = MG_WATCH_HANDSHAKE_LOST;
    w->last_time_us = time_us;
    w->has_last = 1;
    if (reason != MG_WATCH_OK) {
        w->resets++;
        w->session_up = 0; /* until the new HELLO_ACK */
    }
    return reason;
}

const char *mg_watch_reason_name(int32_t reason)
{
    switch (reason) {
    case MG_WATCH_TIME_WENT_BACK:
        return "time_went_back";
    case MG_WATCH_FLAG_RESET:
        return "flag_reset";
    case MG_WATCH_HANDSHAKE_LOST:
        return "handshake_lost";
    default:
        return "";
    }
}
