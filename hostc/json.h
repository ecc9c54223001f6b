/* A small JSON writer and reader for the lockstep channel (cosim/lockstep.py's metadata), with
 * Python's json output exactly: no spaces (separators "," and ":"), ASCII only (other
 * characters as \uXXXX escapes), the caller writing keys in sorted order. No allocation: the
 * writer fills the caller's buffer (overflow is remembered, the text then unusable); the reader
 * walks the caller's text. */
#ifndef MOBIGRASP_HOSTC_JSON_H
#define MOBIGRASP_HOSTC_JSON_H

#include <stddef.h>
#include <stdint.h>

#define MG_JSON_DEPTH 16

typedef struct {
    char *buf;
    size_t cap, len;
    int32_t overflow;
    int32_t depth;
    int32_t count[MG_JSON_DEPTH]; /* values written in each open container */
    int32_t after_key;
} mg_json_t;

void mg_json_init(mg_json_t *j, char *buf, size_t cap);
void mg_json_begin_object(mg_json_t *j);
void mg_json_end_object(mg_json_t *j);
void mg_json_begin_array(mg_json_t *j);
void mg_json_end_array(mg_json_t *j);
void mg_json_key(mg_json_t *j, const char *key);
void mg_json_int(mg_json_t *j, int64_t v);
void mg_json_bool(mg_json_t *j, int32_t v);
void mg_json_null(mg_json_t *j);
void mg_json_string(mg_json_t *j, const char *s, size_t n); /* UTF-8 in, escaped ASCII out */
/* v / 10^6 as Python's repr of the float round(v / 10^6, 6) prints it (0.25, 1.0, 1e-06) */
void mg_json_micro(mg_json_t *j, int64_t v);
void mg_json_raw(mg_json_t *j, const char *text, size_t n); /* a value already in JSON */
void mg_json_int_pair(mg_json_t *j, int64_t a, int64_t b); /* [a, b] */
/* ends the text with a NUL at buf[len] (buf[0] after an overflow: the text is then empty); the
 * buffer given to mg_json_init holds cap + 1 bytes */
void mg_json_terminate(mg_json_t *j);

/* The reader: a cursor over JSON text. Each function returns 1 on success and moves the
 * cursor past what it read, or 0 (the text is not what was asked for). */
typedef struct {
    const char *p, *end;
} mg_json_in_t;

void mg_json_in_init(mg_json_in_t *in, const char *text, size_t n);
int mg_json_utf8_valid(const char *text, size_t n); /* strict, as Python's decoder */
int mg_json_read_int(mg_json_in_t *in, int64_t *out);
int mg_json_read_bool(mg_json_in_t *in, int32_t *out);
/* a string, unescaped into out (cap bytes with the terminating 0; longer ones fail) */
int mg_json_read_string(mg_json_in_t *in, char *out, size_t cap);
int mg_json_skip_value(mg_json_in_t *in);
/* containers: begin, then next_member / next_element (first = 1 before the first) until they
 * return 0 at the container's end; -1 when the text is malformed. next_member reads the key
 * (NULL: skipped) and the colon, leaving the cursor at the value. */
int mg_json_begin_object_in(mg_json_in_t *in);
int mg_json_next_member(mg_json_in_t *in, int *first, char *key, size_t cap);
int mg_json_begin_array_in(mg_json_in_t *in);
int mg_json_next_element(mg_json_in_t *in, int *first);
int mg_json_at_end(mg_json_in_t *in); /* only white space left */

#endif
