/* The host's self-test: every C kernel run on built-in, deterministic inputs (drawn markers on a
 * 320x240 card, fixed angles, numbers and Bezier candidates), one line per kernel written
 * through sys_write: its name, its result and the FNV-1a hash of its outputs. The same lines
 * come from any correct build of the same C, natively or as the ARMv4T ELF under qemu-arm, so
 * comparing them checks the cross compiler, libgcc's 32- and 64-bit integer division, and the
 * start-up code. Then the OS services of sys.h, through their deterministic results (/dev/zero
 * read, polled and mapped shared; a path that is no socket; a device that is no terminal).
 * hostc_selftest_io does what needs a peer: a terminal made raw, a Unix socket, a shared file.
 * No allocation: the buffers are static. */
#include <string.h>

#include "bezier.h"
#include "isqrt.h"
#include "kernels.h"
#include "selftest.h"
#include "sys.h"

#define W 320
#define H 240
#define NPX (W * H)
#define SCRATCH_WORDS (NPX * 3)  /* 8-byte words: more than any kernel's scratch at 320x240 */
#define BLOCKS (((W + 1) / 2) * ((H + 1) / 2))

static uint8_t rgb[NPX * 3];
static uint8_t grey[NPX];
static uint8_t mask[NPX];
static uint32_t hist[256];
static int32_t labels[NPX];
static int32_t block_lab[BLOCKS];
static int32_t parent[BLOCKS + 1];
static int32_t stats[5 * (BLOCKS + 1)];
static uint64_t scratch[SCRATCH_WORDS];
static mg_plus_t plus[MG_MAX_PLUS];
static int32_t lvl[6 * (H + 2)];
static int failures;

/* FNV-1a, 32 bits, over bytes; words are hashed little-endian whatever the machine */
static uint32_t fnv_bytes(uint32_t h, const void *p, int32_t n)
{
    const uint8_t *b = p;
    for (int32_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 16777619u;
    return h;
}

static uint32_t fnv_u64(uint32_t h, uint64_t v)
{
    for (int i = 0; i < 8; i++, v >>= 8)
        h = (h ^ (uint8_t)v) * 16777619u;
    return h;
}

static uint32_t fnv_i32(uint32_t h, const int32_t *v, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        h = fnv_bytes(h, (const uint8_t[4]){ (uint8_t)v[i], (uint8_t)(v[i] >> 8),
                                          (uint8_t)(v[i] >> 16), (uint8_t)(v[i] >> 24) }, 4);
    return h;
}

static uint32_t fnv_i64(uint32_t h, const int64_t *v, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        h = fnv_u64(h, (uint64_t)v[i]);
    return h;
}

#define FNV0 2166136261u

/* "name result hash\n", decimal result, 8 hex digits */
static void report(const char *name, int64_t result, uint32_t hash)
{
    char line[80];
    int n = 0;
    while (*name && n < 40)
        line[n++] = *name++;
    line[n++] = ' ';
    uint64_t mag = result < 0 ? (uint64_t)-result : (uint64_t)result;
    if (result < 0)
        line[n++] = '-';
    char digits[20];
    int d = 0;
    do {
        digits[d++] = (char)('0' + (int)(mag % 10u));
        mag /= 10u;
    } while (mag);
    while (d)
        line[n++] = digits[--d];
    line[n++] = ' ';
    for (int s = 28; s >= 0; s -= 4)
        line[n++] = "0123456789abcdef"[(hash >> s) & 15u];
    line[n++] = '\n';
    if (sys_write(1, line, (size_t)n) != n)
        failures++;
}

/* --- the drawn scenes ---------------------------------------------------------------------- */

static uint32_t lcg_state;

static uint32_t lcg(void)
{
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return lcg_state >> 16;
}

/* a light card with a faint vertical gradient and +-3 of noise */
static void card(uint8_t r, uint8_t g, uint8_t b)
{
    lcg_state = 12345u;
    for (int32_t i = 0; i < NPX; i++) {
        int32_t shade = (i / W) / 16 - (int32_t)(lcg() % 7u) + 3;
        const uint8_t c[3] = { r, g, b };
        for (int k = 0; k < 3; k++) {
            int32_t v = c[k] + shade;
            rgb[3 * i + k] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
        }
    }
}

static void px(int32_t x, int32_t y, uint8_t r, uint8_t g, uint8_t b)
{
    if (x < 0 || y < 0 || x >= W || y >= H)
        return;
    uint8_t *p = rgb + 3 * (y * W + x);
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

/* 000's radial symbol: a dark elliptical ring (outer semi-axes a, b; ring width t) */
static void ring(int32_t cx, int32_t cy, int32_t a, int32_t b, int32_t t)
{
    for (int32_t y = cy - b; y <= cy + b; y++)
        for (int32_t x = cx - a; x <= cx + a; x++) {
            const int32_t dx = x - cx, dy = y - cy;
            const int64_t outer = (int64_t)dx * dx * b * b + (int64_t)dy * dy * a * a;
            const int32_t ai = a - t, bi = b - t;
            const int64_t inner = (int64_t)dx * dx * bi * bi + (int64_t)dy * dy * ai * ai;
            if (outer <= (int64_t)a * a * b * b && inner > (int64_t)ai * ai * bi * bi)
                px(x, y, 25, 25, 25);
        }
}

/* 000's "+": two dark bars of half-width hw and half-length hl */
static void plus_mark(int32_t cx, int32_t cy, int32_t hl, int32_t hw)
{
    for (int32_t y = cy - hl; y <= cy + hl; y++)
        for (int32_t x = cx - hl; x <= cx + hl; x++) {
            const int32_t dx = x - cx, dy = y - cy;
            if ((dx >= -hw && dx <= hw) || (dy >= -hw && dy <= hw))
                px(x, y, 20, 20, 20);
        }
}

/* 002's cross: a dark centre and four dark 45-degree wedges on the axes out to radius r */
static void cross_mark(int32_t cx, int32_t cy, int32_t r)
{
    for (int32_t y = cy - r; y <= cy + r; y++)
        for (int32_t x = cx - r; x <= cx + r; x++) {
            const int32_t dx = x - cx, dy = y - cy;
            const int32_t ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
            const int32_t lo = ax < ay ? ax : ay, hi = ax < ay ? ay : ax;
            if (dx * dx + dy * dy <= r * r && (dx * dx + dy * dy <= 4 || 1000 * lo <= 414 * hi))
                px(x, y, 15, 15, 15);
        }
}

/* 002's red cylinder seen from the side: a red band with two dark rings across it */
static void cylinder(int32_t x0, int32_t y0, int32_t w, int32_t h, int32_t ring1, int32_t ring2)
{
    for (int32_t y = y0; y < y0 + h; y++)
        for (int32_t x = x0; x < x0 + w; x++) {
            const int dark = (y >= ring1 && y < ring1 + 6) || (y >= ring2 && y < ring2 + 6);
            if (dark)
                px(x, y, 35, 15, 15);
            else
                px(x, y, 200, 30, 35);
        }
}

/* --- the kernels --------------------------------------------------------------------------- */

/* grey, dark mask and labelling of the current frame: the front end of the 000 detectors */
static int32_t front_end(const char *tag)
{
    mg_grey(rgb, grey, NPX);
    int32_t thr = mg_dark_mask(grey, mask, NPX, hist);
    int32_t n_lab = mg_label(mask, W, H, labels, block_lab, parent, stats);
    char name[24] = "grey_";
    char dark[24] = "dark_";
    char label[24] = "label_";
    for (int i = 0; tag[i] && i < 16; i++) {
        name[5 + i] = tag[i];
        name[6 + i] = '\0';
        dark[5 + i] = tag[i];
        dark[6 + i] = '\0';
        label[6 + i] = tag[i];
        label[7 + i] = '\0';
    }
    report(name, 0, fnv_bytes(FNV0, grey, NPX));
    report(dark, thr, fnv_bytes(FNV0, mask, NPX));
    report(label, n_lab, fnv_i32(fnv_i32(FNV0, labels, NPX), stats, 5 * n_lab));
    return n_lab;
}

static int scratch_fits(int32_t bytes)
{
    if (bytes <= (int32_t)sizeof scratch)
        return 1;
    report("scratch_too_small", bytes, 0);
    failures++;
    return 0;
}

static void vision(void)
{
    int32_t out[32];

    card(215, 215, 210);
    ring(150, 110, 46, 30, 8);
    int32_t n_lab = front_end("radial");
    if (scratch_fits(mg_radial_scratch_bytes(W, H))) {
        for (int i = 0; i < 6; i++)
            out[i] = 0;
        int32_t r = mg_radial_symbol(grey, W, H, stats, n_lab, 611, 160, 120,
                                     (uint8_t *)scratch, out, NULL);
        report("radial_symbol", r, fnv_i32(FNV0, out, 6));
    }

    card(220, 220, 220);
    plus_mark(120, 130, 12, 4);
    plus_mark(190, 120, 12, 4);
    n_lab = front_end("plus");
    mg_ops_t plus_ops;
    mg_ops_clear(&plus_ops);
    int32_t n_plus = mg_plus_candidates(grey, labels, W, H, stats, n_lab, plus, lvl, &plus_ops);
    uint32_t h = FNV0;
    for (int32_t i = 0; i < n_plus; i++) {
        h = fnv_i32(h, &plus[i].u_q4, 2);
        h = fnv_i32(h, plus[i].box, 4);
        for (int k = 0; k < 6; k++)
            h = fnv_u64(h, (uint64_t)plus[i].m[k]);
    }
    report("plus_candidates", n_plus, h);
    if (scratch_fits(mg_dual_plus_scratch_bytes(W, H))) {
        for (int i = 0; i < 11; i++)
            out[i] = 0;
        int32_t r = mg_dual_plus(grey, labels, W, H, stats, n_lab, 700, 611, 160,
                                 (uint8_t *)scratch, out, NULL);
        report("dual_plus", r, fnv_i32(FNV0, out, 11));
    }

    card(225, 225, 225);
    plus_mark(165, 118, 45, 10);
    n_lab = front_end("spoke");
    if (scratch_fits(mg_dual_plus_scratch_bytes(W, H))) {
        for (int i = 0; i < 26; i++)
            out[i] = 0;
        int32_t r = mg_spoke(grey, labels, W, H, stats, n_lab, (uint8_t *)scratch, out, NULL);
        report("spoke", r, fnv_i32(FNV0, out, 26));
    }

    card(190, 195, 200);
    cylinder(140, 50, 40, 150, 95, 140);
    if (scratch_fits(mg_red_scratch_bytes(W, H))) {
        for (int i = 0; i < 10; i++)
            out[i] = 0;
        int32_t r = mg_red_roi(rgb, W, H, (uint8_t *)scratch, out, 0);
        report("red_roi", r, fnv_i32(FNV0, out, 8));
        r = mg_red_cylinder(rgb, W, H, (uint8_t *)scratch, out, 0);
        report("red_cylinder", r, fnv_i32(FNV0, out, 10));
    }

    card(210, 210, 205);
    cross_mark(130, 125, 18);
    cross_mark(195, 125, 18);
    mg_grey(rgb, grey, NPX);
    if (scratch_fits(mg_double_cross_scratch_bytes(W, H))) {
        for (int i = 0; i < 10; i++)
            out[i] = 0;
        int32_t r = mg_double_cross(grey, W, H, 0, -300, 611, (uint8_t *)scratch, out, 0);
        report("double_cross", r, fnv_i32(FNV0, out, 10));
    }

    /* the sub-pixel edge along every row of the last grey image, light to dark */
    h = FNV0;
    int32_t found = 0;
    for (int32_t y = 0; y < H; y += 3)
        for (int32_t x = 4; x < W - 4; x += 5) {
            int32_t q4 = 0;
            int ok = mg_edge_q4(grey + y * W, 1, W, x, -1, &q4);
            found += ok;
            h = fnv_i32(h, &q4, 1);
        }
    report("edge_q4", found, h);
}

static void arithmetic(void)
{
    uint32_t h = FNV0;
    int64_t sum = 0;
    for (int32_t a = -7000; a <= 7000; a += 7) {
        int32_t v[2] = { mg_sin_q12(a), mg_cos_q12(a) };
        sum += v[0];
        h = fnv_i32(h, v, 2);
    }
    report("sin_cos_q12", sum, h);

    h = FNV0;
    sum = 0;
    for (int64_t y = -90000; y <= 90000; y += 4093)
        for (int64_t x = -90000; x <= 90000; x += 3571) {
            int32_t a = mg_atan2_mrad(y * 1013, x * 997);
            sum += a;
            h = fnv_i32(h, &a, 1);
        }
    report("atan2_mrad", sum, h);

    h = FNV0;
    sum = 0;
    uint32_t n = 0;
    uint64_t n64 = 1;
    for (int i = 0; i < 500; i++, n = n * 2654435761u + 12345u) {
        int32_t r32 = mg_isqrt32(n);
        int64_t r64 = mg_isqrt64(n64);
        sum += r32;
        h = fnv_i32(h, &r32, 1);
        h = fnv_u64(h, (uint64_t)r64);
        n64 = n64 * 5u + 3u;
    }
    report("isqrt", sum, h);

    h = FNV0;
    sum = 0;
    for (int32_t a = -1000; a <= 1000; a += 37)
        for (int32_t b = -97; b <= 97; b += 13) {
            if (b == 0)
                continue;
            int32_t v[2] = { mg_floordiv(a * 1009, b), 0 };
            if (b > 0)
                v[1] = mg_div_round((int64_t)a * 1000003, b);
            sum += v[0] + v[1];
            h = fnv_i32(h, v, 2);
        }
    report("floordiv_divround", sum, h);

    h = FNV0;
    sum = 0;
    int32_t out[6];
    for (int32_t k = 0; k < 40; k++) {
        for (int i = 0; i < 6; i++)
            out[i] = 0;
        int32_t r = mg_locate_ring_pair(160 + 37 * k, 16 * (60 + 5 * k), 16 * (200 - 3 * k),
                                        16 * (20 + k), 300 - 29 * k, -200 + 17 * k, 611, 160,
                                        120, 14500, out);
        sum += r;
        h = fnv_i32(h, out, 6);
    }
    report("ring_pair", sum, h);

    /* the Bezier kernels' 64-bit root on wide operands (squared speeds up to 2^55) */
    int64_t v[64];
    for (int i = 0; i < 64; i++)
        v[i] = mg_isqrt64(((uint64_t)(i * i * 7919 + 1) << (i % 28)) / (uint64_t)(i + 3));
    report("isqrt64_wide", 64, fnv_i64(FNV0, v, 64));
}

/* Bezier candidates in 1/16 mm and 1/16 ms (host/planning/bezier_q.py): a fan of end headings
 * and durations from the origin to a target 1 m ahead, some too fast, some too sharp, some
 * through the grasp circle */
#define N_CAND 24
#define Q 16000  /* counts per metre and per second */
static int32_t ctrl[N_CAND * 12];

static void candidates(void)
{
    for (int c = 0; c < N_CAND; c++) {
        int32_t *p = ctrl + 12 * c;
        const int32_t t_end = 2 * Q + Q / 2 * (c % 6);
        const int32_t side = (c / 6) * (Q * 15 / 100) - Q / 5;
        const int32_t pts[12] = { 0, 0, 0,
                                  Q * 35 / 100, side, t_end / 3,
                                  Q * 7 / 10, -side / 2, 2 * t_end / 3,
                                  Q, Q / 10 * (c % 3), t_end };
        for (int k = 0; k < 12; k++)
            p[k] = pts[k];
    }
}

static void planning(void)
{
    candidates();
    /* v_max 0.4 m/s, a_max 0.5 / 0.6 m/s^2 (Q16), R_min 0.15 m for 001's table row (unused) */
    const int32_t lim000[MG_LIM_WORDS] = { 26214, 32768, -1, 0 };
    const int32_t lim001[MG_LIM_WORDS] = { 26214, 39322, 436907, 1 };
    /* the grasp circle around (1.3, 0.1) m of (0.25 - 0.001) m, one sonar region ahead-left:
     * apex (0.5, 0.35) m, bisector along +y (cos 0, sin 1 in Q14), tan 0.2679, sensing at the
     * origin, band radii 0 and 0.45 m, the arc bound with cos(bound)^2 = 0.5 (Q16) */
    const int64_t geo[MG_GEO_HEAD + MG_REGION_WORDS] = {
        Q * 13 / 10, Q / 10, (int64_t)(Q * 249 / 1000) * (Q * 249 / 1000),
        Q / 2, Q * 35 / 100, 0, 16384, 4389, 0, 0, 0, (int64_t)(Q * 45 / 100) * (Q * 45 / 100),
        1, 1, 32768
    };
    int32_t reason[N_CAND], first[N_CAND], tried = 0;
    int64_t cost[N_CAND];

    int32_t best = mg_bezier000(ctrl, N_CAND, 41, lim000, 65536, 32768, reason, first, cost);
    report("bezier000", best,
           fnv_i64(fnv_i32(fnv_i32(FNV0, reason, N_CAND), first, N_CAND), cost, N_CAND));

    int32_t taken = mg_bezier001_coarse(ctrl, N_CAND, 41, lim001, geo, 1, 900, 4000, 400000,
                                        65536, 32768, reason, first, cost);
    report("bezier001_coarse", taken,
           fnv_i64(fnv_i32(fnv_i32(FNV0, reason, N_CAND), first, N_CAND), cost, N_CAND));

    int32_t pick = mg_bezier001_fine(ctrl, N_CAND, 101, lim001, geo, 1, 900, 4000, 250, 2500,
                                     reason, &tried);
    report("bezier001_fine", pick, fnv_i32(fnv_i32(FNV0, reason, tried), &tried, 1));
}

/* --- the OS services ----------------------------------------------------------------------- */

static void services(void)
{
    int32_t res[8];
    int64_t t0 = sys_monotonic_us();
    res[0] = sys_sleep_us(2000);
    int64_t t1 = sys_monotonic_us();
    res[1] = t0 > 0 && t1 - t0 >= 2000;  /* the clock runs and the sleep slept */

    uint8_t buf[64];
    int fd = sys_open("/dev/zero", SYS_O_RDWR, 0);
    res[2] = fd >= 0;
    for (int i = 0; i < 64; i++)
        buf[i] = 0xa5;
    long got = sys_read(fd, buf, sizeof buf);
    int zeros = 0;
    for (int i = 0; i < 64; i++)
        zeros += buf[i] == 0;
    res[3] = (int32_t)got * 1000 + zeros;

    struct sys_pollfd p = { fd, SYS_POLLIN, 0 };
    int ready = sys_poll(&p, 1, 0);
    res[4] = ready * 100 + p.revents;

    uint8_t *map = sys_mmap_shared(fd, 4096, 1);
    int ok = map != NULL;
    if (ok) {
        ok = map[0] == 0 && map[4095] == 0;
        map[7] = 42;
        ok = ok && map[7] == 42;
        ok = ok && sys_munmap(map, 4096) == 0;
    }
    res[5] = ok;
    res[6] = sys_tty_raw(fd);  /* /dev/zero is no terminal: -ENOTTY */
    res[6] = res[6] * 1000 + sys_close(fd);
    res[7] = sys_unix_connect("/proc/self/no-such-socket");  /* -ENOENT */
    int64_t sum = 0;
    for (int i = 0; i < 8; i++)
        sum += res[i];
    report("sys", sum, fnv_i32(FNV0, res, 8));
    if (!res[1] || !res[2] || !res[5])
        failures++;
}

int hostc_selftest(void)
{
    failures = 0;
    vision();
    arithmetic();
    planning();
    services();
    report("failures", failures, 0);
    return failures ? 1 : 0;
}

/* "name text\n" */
static void say(const char *name, const char *text, long n)
{
    char line[96];
    int k = 0;
    while (*name && k < 40)
        line[k++] = *name++;
    line[k++] = ' ';
    for (long i = 0; i < n && k < 94; i++)
        line[k++] = text[i];
    line[k++] = '\n';
    if (sys_write(1, line, (size_t)k) != k)
        failures++;
}

/* read what the peer sends on fd within timeout_ms; the bytes read, or <= 0 */
static long await_read(int fd, char *buf, size_t n, int timeout_ms)
{
    struct sys_pollfd p = { fd, SYS_POLLIN, 0 };
    int ready = sys_poll(&p, 1, timeout_ms);
    if (ready <= 0 || !(p.revents & SYS_POLLIN))
        return ready < 0 ? ready : 0;
    return sys_read(fd, buf, n);
}

int hostc_selftest_io(const char *tty, const char *sock, const char *file)
{
    char buf[32];
    failures = 0;

    /* the terminal: raw, then "ping" out and the peer's answer in */
    int fd = sys_open(tty, SYS_O_RDWR | SYS_O_NOCTTY, 0);
    report("tty_open", fd >= 0, 0);
    if (fd >= 0) {
        report("tty_raw", sys_tty_raw(fd), 0);
        report("tty_write", sys_write(fd, "ping\n", 5), 0);
        long n = await_read(fd, buf, sizeof buf, 20000);
        say("tty_read", buf, n > 0 ? n : 0);
        sys_close(fd);
    }

    /* the Unix socket: "hello" out, the peer's answer in */
    fd = sys_unix_connect(sock);
    report("unix_connect", fd >= 0, 0);
    if (fd >= 0) {
        report("unix_write", sys_write(fd, "hello", 5), 0);
        long n = await_read(fd, buf, sizeof buf, 20000);
        say("unix_read", buf, n > 0 ? n : 0);
        sys_close(fd);
    }

    /* the shared file: the sum of its first page read through the mapping, then byte 100
     * written through it, which the file must show */
    fd = sys_open(file, SYS_O_RDWR, 0);
    uint8_t *map = fd >= 0 ? sys_mmap_shared(fd, 4096, 1) : NULL;
    int64_t sum = 0;
    if (map != NULL) {
        for (int i = 0; i < 4096; i++)
            sum += map[i];
        map[100] = 0x5a;
        if (sys_munmap(map, 4096) != 0)
            failures++;
    } else {
        failures++;
    }
    if (fd >= 0)
        sys_close(fd);
    report("mmap_sum", sum, 0);
    report("failures", failures, 0);
    return failures ? 1 : 0;
}

int hostc_selftest_main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--self-test") == 0)
        return hostc_selftest();
    if (argc == 5 && strcmp(argv[1], "--self-test-io") == 0)
        return hostc_selftest_io(argv[2], argv[3], argv[4]);
    return -1;
}
