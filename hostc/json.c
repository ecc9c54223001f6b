/* JSON for the lockstep channel: Python's json.dumps(sort_keys=True, separators=(",", ":"))
 * output, and a reader of the metadata the rig sends. */
#include "json.h"

#include <string.h>

void mg_json_init(mg_json_t *j, char *buf, size_t cap)
{
    j->buf = buf;
    j->cap = cap;
    j->len = 0;
    j->overflow = 0;
    j->depth = 0;
    j->count[0] = 0;
    j->after_key = 0;
}

static void put(mg_json_t *j, const char *s, size_t n)
{
    if (j->len + n > j->cap) {
        j->overflow = 1;
        return;
    }
    memcpy(j->buf + j->len, s, n);
    j->len += n;
}

static void putc1(mg_json_t *j, char c)
{
    put(j, &c, 1);
}

/* the comma before a value that is not the first of its container nor after a key */
static void value_start(mg_json_t *j)
{
    if (j->after_key)
        j->after_key = 0;
    else if (j->count[j->depth]++ > 0)
        putc1(j, ',');
}

static void open_container(mg_json_t *j, char c)
{
    value_start(j);
    putc1(j, c);
    if (j->depth + 1 >= MG_JSON_DEPTH) {
        j->overflow = 1;
        return;
    }
    j->count[++j->depth] = 0;
}

static void close_container(mg_json_t *j, char c)
{
    putc1(j, c);
    if (j->depth > 0)
        j->depth--;
}

void mg_json_begin_object(mg_json_t *j)
{
    open_container(j, '{');
}

void mg_json_end_object(mg_json_t *j)
{
    close_container(j, '}');
}

void mg_json_begin_array(mg_json_t *j)
{
    open_container(j, '[');
}

void mg_json_end_array(mg_json_t *j)
{
    close_container(j, ']');
}

void mg_json_key(mg_json_t *j, const char *key)
{
    mg_json_string(j, key, strlen(key));
    putc1(j, ':');
    j->after_key = 1;
}

static void digits(mg_json_t *j, uint64_t u)
{
    char tmp[20];
    int n = 0;
    do {
        tmp[n++] = (char)('0' + u % 10u);
        u /= 10u;
    } while (u);
    while (n > 0)
        putc1(j, tmp[--n]);
}

void mg_json_int(mg_json_t *j, int64_t v)
{
    value_start(j);
    if (v < 0) {
        putc1(j, '-');
        digits(j, (uint64_t)0 - (uint64_t)v);
    } else {
        digits(j, (uint64_t)v);
    }
}

void mg_json_bool(mg_json_t *j, int32_t v)
{
    value_start(j);
    if (v)
        put(j, "true", 4);
    else
        put(j, "false", 5);
}

void mg_json_null(mg_json_t *j)
{
    value_start(j);
    put(j, "null", 4);
}

static void hex4(mg_json_t *j, uint32_t u)
{
    static const char hex[] = "0123456789abcdef";
    char e[6] = {'\\', 'u', hex[(u >> 12) & 15], hex[(u >> 8) & 15], hex[(u >> 4) & 15],
                 hex[u & 15]};
    put(j, e, 6);
}

/* one UTF-8 sequence at s (n bytes left): its code point and length; a malformed byte is taken
 * as U+FFFD, as Python's decoder with errors="replace" would */
static uint32_t utf8(const unsigned char *s, size_t n, size_t *len)
{
    uint32_t cp;
    size_t k;
    if (s[0] < 0x80)
        return *len = 1, s[0];
    if ((s[0] & 0xE0) == 0xC0)
        cp = s[0] & 0x1Fu, k = 2;
    else if ((s[0] & 0xF0) == 0xE0)
        cp = s[0] & 0x0Fu, k = 3;
    else if ((s[0] & 0xF8) == 0xF0)
        cp = s[0] & 0x07u, k = 4;
    else
        return *len = 1, 0xFFFDu;
    if (k > n)
        return *len = 1, 0xFFFDu;
    for (size_t i = 1; i < k; i++) {
        if ((s[i] & 0xC0) != 0x80)
            return *len = 1, 0xFFFDu;
        cp = (cp << 6) | (s[i] & 0x3Fu);
    }
    *len = k;
    return cp;
}

void mg_json_string(mg_json_t *j, const char *s, size_t n)
{
    value_start(j);
    putc1(j, '"');
    const unsigned char *u = (const unsigned char *)s;
    for (size_t i = 0; i < n;) {
        size_t k;
        const uint32_t c = utf8(u + i, n - i, &k);
        i += k;
        switch (c) {
        case '"': put(j, "\\\"", 2); break;
        case '\\': put(j, "\\\\", 2); break;
        case '\n': put(j, "\\n", 2); break;
        case '\r': put(j, "\\r", 2); break;
        case '\t': put(j, "\\t", 2); break;
        case '\b': put(j, "\\b", 2); break;
        case '\f': put(j, "\\f", 2); break;
        default:
            if (c < 0x20 || (c >= 0x7F && c < 0x10000)) {
                hex4(j, c);
            } else if (c >= 0x10000) { /* a UTF-16 surrogate pair */
                hex4(j, 0xD800u + ((c - 0x10000u) >> 10));
                hex4(j, 0xDC00u + ((c - 0x10000u) & 0x3FFu));
            } else {
                putc1(j, (char)c);
            }
        }
    }
    putc1(j, '"');
}

void mg_json_micro(mg_json_t *j, int64_t v)
{
    value_start(j);
    uint64_t u = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
    if (v < 0)
        putc1(j, '-');
    if (u != 0 && u < 100) { /* below 1e-4 Python prints the exponent: 5e-06, 1.2e-05 */
        const int exp = u < 10 ? 6 : 5;
        putc1(j, (char)('0' + (u < 10 ? u : u / 10)));
        if (u >= 10 && u % 10) {
            putc1(j, '.');
            putc1(j, (char)('0' + u % 10));
        }
        put(j, exp == 6 ? "e-06" : "e-05", 4);
        return;
    }
    digits(j, u / 1000000u);
    putc1(j, '.');
    uint64_t frac = u % 1000000u;
    if (frac == 0) {
        putc1(j, '0');
        return;
    }
    char tmp[6];
    for (int i = 5; i >= 0; i--, frac /= 10u)
        tmp[i] = (char)('0' + frac % 10u);
    int n = 6;
    while (tmp[n - 1] == '0')
        n--;
    put(j, tmp, (size_t)n);
}

void mg_json_int_pair(mg_json_t *j, int64_t a, int64_t b)
{
    mg_json_begin_array(j);
    mg_json_int(j, a);
    mg_json_int(j, b);
    mg_json_end_array(j);
}

void mg_json_terminate(mg_json_t *j)
{
    j->buf[j->overflow ? 0 : j->len] = 0;
}

void mg_json_raw(mg_json_t *j, const char *text, size_t n)
{
    value_start(j);
    put(j, text, n);
}

/* ---- reader ---- */

int mg_json_utf8_valid(const char *text, size_t n)
{
    const unsigned char *s = (const unsigned char *)text;
    size_t i = 0;
    while (i < n) {
        const unsigned c = s[i];
        size_t k;
        unsigned lo = 0x80, hi = 0xBF; /* the range of the second byte */
        if (c < 0x80) {
            i++;
            continue;
        }
        if (c >= 0xC2 && c <= 0xDF)
            k = 2;
        else if (c >= 0xE0 && c <= 0xEF)
            k = 3, lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
        else if (c >= 0xF0 && c <= 0xF4)
            k = 4, lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
        else
            return 0; /* a continuation byte, an overlong lead, or beyond U+10FFFF */
        if (i + k > n || s[i + 1] < lo || s[i + 1] > hi)
            return 0;
        for (size_t m = 2; m < k; m++)
            if ((s[i + m] & 0xC0) != 0x80)
                return 0;
        i += k;
    }
    return 1;
}

void mg_json_in_init(mg_json_in_t *in, const char *text, size_t n)
{
    in->p = text;
    in->end = text + n;
}

static void ws(mg_json_in_t *in)
{
    while (in->p < in->end && (*in->p == ' ' || *in->p == '\t' || *in->p == '\n'
                               || *in->p == '\r'))
        in->p++;
}

static int take(mg_json_in_t *in, char c)
{
    ws(in);
    if (in->p < in->end && *in->p == c) {
        in->p++;
        return 1;
    }
    return 0;
}

int mg_json_read_int(mg_json_in_t *in, int64_t *out)
{
    ws(in);
    const char *p = in->p;
    int neg = 0;
    if (p < in->end && *p == '-')
        neg = 1, p++;
    if (p >= in->end || *p < '0' || *p > '9' || (*p == '0' && p + 1 < in->end && p[1] >= '0'
                                                 && p[1] <= '9'))
        return 0;
    uint64_t v = 0;
    while (p < in->end && *p >= '0' && *p <= '9') {
        const uint64_t d = (uint64_t)(*p++ - '0');
        if (v > (UINT64_C(9223372036854775808) - d) / 10u)
            return 0;
        v = v * 10u + d;
    }
    if (p < in->end && (*p == '.' || *p == 'e' || *p == 'E'))
        return 0; /* a float is not an integer */
    if (!neg && v > (uint64_t)INT64_MAX)
        return 0;
    *out = neg ? (int64_t)((uint64_t)0 - v) : (int64_t)v;
    in->p = p;
    return 1;
}

static int word(mg_json_in_t *in, const char *w)
{
    const size_t n = strlen(w);
    ws(in);
    if ((size_t)(in->end - in->p) >= n && memcmp(in->p, w, n) == 0) {
        in->p += n;
        return 1;
    }
    return 0;
}

int mg_json_read_bool(mg_json_in_t *in, int32_t *out)
{
    if (word(in, "true"))
        return *out = 1, 1;
    if (word(in, "false"))
        return *out = 0, 1;
    return 0;
}

static int hexval(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
                                          : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

static int emit(char *out, size_t cap, size_t *n, uint32_t cp)
{
    char b[4];
    size_t k;
    if (cp < 0x80)
        b[0] = (char)cp, k = 1;
    else if (cp < 0x800)
        b[0] = (char)(0xC0 | (cp >> 6)), b[1] = (char)(0x80 | (cp & 63)), k = 2;
    else if (cp < 0x10000)
        b[0] = (char)(0xE0 | (cp >> 12)), b[1] = (char)(0x80 | ((cp >> 6) & 63)),
        b[2] = (char)(0x80 | (cp & 63)), k = 3;
    else
        b[0] = (char)(0xF0 | (cp >> 18)), b[1] = (char)(0x80 | ((cp >> 12) & 63)),
        b[2] = (char)(0x80 | ((cp >> 6) & 63)), b[3] = (char)(0x80 | (cp & 63)), k = 4;
    if (out == NULL)
        return 1; /* skipping */
    if (*n + k + 1 > cap)
        return 0;
    memcpy(out + *n, b, k);
    *n += k;
    return 1;
}

static int string_in(mg_json_in_t *in, char *out, size_t cap)
{
    if (!take(in, '"'))
        return 0;
    size_t n = 0;
    const char *p = in->p;
    while (p < in->end && *p != '"') {
        uint32_t cp = (unsigned char)*p++;
        if (cp < 0x20)
            return 0;
        if (cp == '\\') {
            if (p >= in->end)
                return 0;
            const char e = *p++;
            if (e == 'u') {
                if (in->end - p < 4)
                    return 0;
                cp = 0;
                for (int i = 0; i < 4; i++) {
                    const int h = hexval(*p++);
                    if (h < 0)
                        return 0;
                    cp = cp << 4 | (uint32_t)h;
                }
                if (cp >= 0xD800 && cp < 0xDC00 && in->end - p >= 6 && p[0] == '\\'
                    && p[1] == 'u') { /* a surrogate pair */
                    uint32_t lo = 0;
                    int ok = 1;
                    for (int i = 2; i < 6; i++) {
                        const int h = hexval(p[i]);
                        ok &= h >= 0;
                        lo = lo << 4 | (uint32_t)(h < 0 ? 0 : h);
                    }
                    if (ok && lo >= 0xDC00 && lo < 0xE000) {
                        cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
                        p += 6;
                    }
                }
            } else {
                static const char from[] = "\"\\/bfnrt", to[] = "\"\\/\b\f\n\r\t";
                int hit = -1;
                for (int i = 0; i < 8; i++)
                    if (from[i] == e)
                        hit = i;
                if (hit < 0)
                    return 0;
                cp = (unsigned char)to[hit];
            }
            if (!emit(out, cap, &n, cp))
                return 0;
        } else if (out != NULL) {
            if (n + 2 > cap)
                return 0;
            out[n++] = (char)cp;
        }
    }
    if (p >= in->end)
        return 0;
    in->p = p + 1;
    if (out != NULL)
        out[n] = 0;
    return 1;
}

int mg_json_read_string(mg_json_in_t *in, char *out, size_t cap)
{
    return cap > 0 && string_in(in, out, cap);
}

int mg_json_begin_object_in(mg_json_in_t *in)
{
    return take(in, '{');
}

int mg_json_begin_array_in(mg_json_in_t *in)
{
    return take(in, '[');
}

int mg_json_next_member(mg_json_in_t *in, int *first, char *key, size_t cap)
{
    if (take(in, '}'))
        return 0;
    if (!*first && !take(in, ','))
        return -1;
    *first = 0;
    return string_in(in, key, cap) && take(in, ':') ? 1 : -1;
}

int mg_json_next_element(mg_json_in_t *in, int *first)
{
    if (take(in, ']'))
        return 0;
    if (!*first && !take(in, ','))
        return -1;
    *first = 0;
    return 1;
}

static int skip(mg_json_in_t *in, int depth)
{
    int64_t i;
    int32_t b;
    int first = 1, r;
    ws(in);
    if (in->p >= in->end || depth > MG_JSON_DEPTH)
        return 0;
    switch (*in->p) {
    case '"':
        return string_in(in, NULL, 0);
    case '{':
        in->p++;
        while ((r = mg_json_next_member(in, &first, NULL, 0)) == 1)
            if (!skip(in, depth + 1))
                return 0;
        return r == 0;
    case '[':
        in->p++;
        while ((r = mg_json_next_element(in, &first)) == 1)
            if (!skip(in, depth + 1))
                return 0;
        return r == 0;
    default:
        break;
    }
    if (mg_json_read_bool(in, &b) || word(in, "null") || mg_json_read_int(in, &i))
        return 1;
    /* a number with a fraction or an exponent: its characters */
    const char *p = in->p;
    while (p < in->end && ((*p >= '0' && *p <= '9') || *p == '-' || *p == '+' || *p == '.'
                           || *p == 'e' || *p == 'E'))
        p++;
    if (p == in->p)
        return 0;
    in->p = p;
    return 1;
}

int mg_json_skip_value(mg_json_in_t *in)
{
    return skip(in, 0);
}

int mg_json_at_end(mg_json_in_t *in)
{
    ws(in);
    return in->p == in->end;
}
