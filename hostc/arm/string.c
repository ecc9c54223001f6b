/* The C library functions the portable modules and the compiler's own code may call (gcc emits
 * memcpy and memset for struct copies and initialisers even with -ffreestanding).
 *
 * memcpy, memmove and memset move words where they can: a byte loop costs the ARM920T ~9 cycles
 * a byte (LDRB's interlock, the loop), a word loop of eight words (LDM/STM) ~1 a byte, and the
 * control step copies and shifts kilobytes (the detectors' results, the task's histories;
 * docs/budget.md "Whole control steps and frame pipelines"). ARMv4T has no unaligned word
 * access, so the cases are: the destination word-aligned by a few bytes first, then a source of
 * the same alignment copied word by word, another one by aligned words shifted together
 * (little-endian), the last bytes one by one. An aligned word read at either end of the source
 * may hold bytes outside it, never outside its own aligned word.
 * The attribute keeps gcc from recognising each loop as a call to the function itself. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define NO_LIBCALL __attribute__((optimize("no-tree-loop-distribute-patterns")))

typedef uint32_t __attribute__((may_alias)) word_t;

/* below this many bytes a plain byte loop is cheaper than the alignment steps */
#define SHORT_BYTES 16u

static inline uintptr_t misalign(const void *p)
{
    return (uintptr_t)p & 3u;
}

/* n bytes forward from s to d, d word-aligned; the areas may overlap with d before s */
static inline NO_LIBCALL void words_forward(unsigned char *d, const unsigned char *s, size_t n)
{
    word_t *dw = (word_t *)(void *)d;
    const uintptr_t k = misalign(s);
    if (k == 0) {
        const word_t *sw = (const word_t *)(const void *)s;
        for (; n >= 32; n -= 32, dw += 8, sw += 8) { /* LDM/STM of eight registers */
            const uint32_t a = sw[0], b = sw[1], c = sw[2], e = sw[3];
            const uint32_t f = sw[4], g = sw[5], h = sw[6], i = sw[7];
            dw[0] = a, dw[1] = b, dw[2] = c, dw[3] = e;
            dw[4] = f, dw[5] = g, dw[6] = h, dw[7] = i;
        }
        for (; n >= 4; n -= 4)
            *dw++ = *sw++;
        s = (const unsigned char *)sw;
    } else {
        /* each destination word is the tail of one aligned source word and the head of the
         * next: the bytes from s on in the first, shifted down */
        const unsigned lo = 8u * (unsigned)k, hi = 32u - lo;
        const word_t *sw = (const word_t *)(const void *)(s - k);
        uint32_t w = *sw++;
        for (; n >= 4; n -= 4, s += 4) {
            const uint32_t next = *sw++;
            *dw++ = w >> lo | next << hi;
            w = next;
        }
    }
    d = (unsigned char *)dw;
    while (n--)
        *d++ = *s++;
}

/* forward from the destination's first word boundary on; out of line, so that the short copies
 * (most calls: a character, a table row) take the byte loop without its registers' saving */
static __attribute__((noinline)) NO_LIBCALL void copy_forward(unsigned char *d,
                                                              const unsigned char *s, size_t n)
{
    for (; n > 0 && misalign(d) != 0; n--)
        *d++ = *s++;
    words_forward(d, s, n);
}

NO_LIBCALL void *memcpy(void *restrict dst, const void *restrict src, size_t n)
{
    unsigned char *d = dst;
    const unsigned char *s = src;
    if (n >= SHORT_BYTES) {
        copy_forward(d, s, n);
        return dst;
    }
    while (n--)
        *d++ = *s++;
    return dst;
}

NO_LIBCALL void *memmove(void *dst, const void *src, size_t n)
{
    unsigned char *d = dst;
    const unsigned char *s = src;
    if (d == s || n == 0)
        return dst;
    if (d < s || d >= s + n) { /* forward: every byte is read before it is written over */
        if (n >= SHORT_BYTES) {
            copy_forward(d, s, n);
            return dst;
        }
        while (n--)
            *d++ = *s++;
        return dst;
    }
    /* d inside the source, after it: backward, by words when both end on the same alignment */
    d += n, s += n;
    if (misalign(d) == misalign(s)) {
        for (; n > 0 && misalign(d) != 0; n--)
            *--d = *--s;
        word_t *dw = (word_t *)(void *)d;
        const word_t *sw = (const word_t *)(const void *)s;
        for (; n >= 4; n -= 4)
            *--dw = *--sw;
        d = (unsigned char *)dw, s = (const unsigned char *)sw;
    }
    while (n--)
        *--d = *--s;
    return dst;
}

NO_LIBCALL void *memset(void *dst, int c, size_t n)
{
    unsigned char *d = dst;
    if (n < SHORT_BYTES) {
        while (n--)
            *d++ = (unsigned char)c;
        return dst;
    }
    for (; n > 0 && misalign(d) != 0; n--)
        *d++ = (unsigned char)c;
    const uint32_t v = 0x01010101u * (unsigned char)c;
    word_t *dw = (word_t *)(void *)d;
    for (; n >= 32; n -= 32, dw += 8) /* STM of eight registers */
        dw[0] = v, dw[1] = v, dw[2] = v, dw[3] = v, dw[4] = v, dw[5] = v, dw[6] = v, dw[7] = v;
    for (; n >= 4; n -= 4)
        *dw++ = v;
    d = (unsigned char *)dw;
    while (n--)
        *d++ = (unsigned char)c;
    return dst;
}

int memcmp(const void *a, const void *b, size_t n)
{
    const unsigned char *p = a, *q = b;
    for (; n; n--, p++, q++)
        if (*p != *q)
            return *p - *q;
    return 0;
}

size_t strlen(const char *s)
{
    size_t n = 0;
    while (s[n])
        n++;
    return n;
}

int strcmp(const char *a, const char *b)
{
    while (*a && *a == *b) {
        a++;
        b++;
    }
    return (unsigned char)*a - (unsigned char)*b;
}

int strncmp(const char *a, const char *b, size_t n)
{
    for (; n; n--, a++, b++) {
        if (*a != *b || !*a)
            return (unsigned char)*a - (unsigned char)*b;
    }
    return 0;
}
