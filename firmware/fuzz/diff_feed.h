/* The differential fuzz's entry point (diff_feed.c). */
#ifndef MOBIGRASP_DIFF_FEED_H
#define MOBIGRASP_DIFF_FEED_H
#include <stdint.h>

#include "protocol/frame.h"

/* Feed ``n`` bytes; every delivered frame is appended to ``out`` as len, version, seq, type,
 * msg_check's answer, then the ``len`` payload bytes (stops before ``cap``); bytes used. */
uint32_t diff_feed(frame_parser_t *p, const uint8_t *in, uint32_t n, uint8_t *out, uint32_t cap);
#endif
