/* The S3C2440 host program in C: the options of `mobigrasp host` (--port, --camera, --method,
 * --config FILE: config.h, --lockstep SOCK, --poll-ms), the method's task, and the driver:
 * lockstep (the rig's grants over the Unix socket, the bytes over the serial port) or free
 * running (the board's clock); `--list-methods` prints the method table's names, one a line
 * (what `mobigrasp run --host c` reads before it starts the program); the self-test options
 * (selftest.h). Bad options exit 2 with one line naming the option (a bad configuration: the
 * file and the key). */
#include <string.h>

#include "app.h"
#include "camera.h"
#include "config.h"
#include "detectors.h"
#include "json.h"
#include "linux_driver.h"
#include "lockstep_driver.h"
#include "selftest.h"
#include "sys.h"
#include "task.h"

static void say(const char *a, const char *b, const char *c)
{
    sys_write(2, "mobigrasp-host-c: ", 18);
    sys_write(2, a, strlen(a));
    sys_write(2, b, strlen(b));
    sys_write(2, c, strlen(c));
    sys_write(2, "\n", 1);
}

/* one line: why, and the options */
static int usage(const char *why, const char *what)
{
    static const char opts[] = " (mobigrasp-host-c --port PATH [--camera SOURCE] [--method NAME]"
                               " [--config FILE] [--lockstep SOCK] [--poll-ms MS] | "
                               "--list-methods | " HOSTC_SELFTEST_USAGE ")\n";
    sys_write(2, "usage: ", 7);
    sys_write(2, why, strlen(why));
    sys_write(2, what, strlen(what));
    sys_write(2, opts, sizeof opts - 1);
    return 2;
}

/* the configuration of a JSON file (config.h): 0, or 2 after one line naming the file and
 * the key */
static int read_config(const char *path, mg_config_t *cfg)
{
    static char text[1 << 16];
    const int fd = sys_open(path, SYS_O_RDONLY, 0);
    if (fd < 0)
        return usage("cannot read --config ", path);
    long n = 0, r;
    while ((r = sys_read(fd, text + n, sizeof text - (size_t)n)) > 0)
        n += r;
    sys_close(fd);
    if (r < 0 || n >= (long)sizeof text)
        return usage("cannot read --config (or larger than 64 kB) ", path);
    char why[MG_CONFIG_WHY], line[MG_CONFIG_WHY + 256];
    if (mg_config_parse(text, (size_t)n, cfg, why, sizeof why) != 0) {
        size_t k = mg_task_text(line, sizeof line, 0, "--config ");
        k = mg_task_text(line, sizeof line, k, path);
        k = mg_task_text(line, sizeof line, k, ": ");
        mg_task_text(line, sizeof line, k, why);
        return usage(line, "");
    }
    return 0;
}

static int poll_ms_ok(const char *s)
{
    /* a number of ms in [0, 10000] (digits and one point) */
    int digits = 0, points = 0, whole = 0;
    for (; *s; s++) {
        if (*s == '.' && !points++)
            continue;
        if (*s < '0' || *s > '9')
            return 0;
        if (!points)
            whole = whole * 10 + (*s - '0');
        digits++;
        if (whole > 10000)
            return 0;
    }
    return digits > 0 && (whole < 10000 || (whole == 10000 && !points));
}

/* the method table's names, one a line on standard output */
static int list_methods(void)
{
    for (int32_t i = 0; i < mg_n_methods; i++) {
        sys_write(1, mg_methods[i].method, strlen(mg_methods[i].method));
        sys_write(1, "\n", 1);
    }
    return 0;
}

static mg_app_t app;
static mg_detectors_t detectors;
static mg_detector_t table[MG_MAX_DETECTORS];
static mg_lockstep_t driver;
static uint64_t task_state[MG_TASK_STATE_BYTES / sizeof(uint64_t)];

int main(int argc, char **argv)
{
    const int selftest = hostc_selftest_main(argc, argv); /* --self-test, --self-test-io */
    if (selftest >= 0)
        return selftest;
    if (argc == 2 && strcmp(argv[1], "--list-methods") == 0)
        return list_methods();
    const char *port = NULL, *camera = NULL, *method_opt = NULL, *config = NULL, *sock = NULL;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        const char **slot = strcmp(o, "--port") == 0       ? &port
                            : strcmp(o, "--camera") == 0   ? &camera
                            : strcmp(o, "--method") == 0   ? &method_opt
                            : strcmp(o, "--config") == 0   ? &config
                            : strcmp(o, "--lockstep") == 0 ? &sock
                                                           : NULL;
        if (strcmp(o, "--poll-ms") == 0) {
            if (i + 1 >= argc || !poll_ms_ok(argv[i + 1]))
                return usage("--poll-ms must be a number of ms in [0, 10000]", "");
            i++; /* accepted; the C host waits in the kernel (busy polling is the Python's) */
            continue;
        }
        if (slot == NULL)
            return usage("unknown option ", o);
        if (i + 1 >= argc)
            return usage("missing the value of ", o);
        *slot = argv[++i];
    }
    if (port == NULL)
        return usage("--port is required", "");
    static mg_config_t conf; /* method 000, f_px 611, u0_px 160, v0_px 120 without --config */
    mg_config_default(&conf);
    if (config != NULL && read_config(config, &conf) != 0)
        return 2;
    if (method_opt != NULL) {
        if (strlen(method_opt) >= sizeof conf.method)
            return usage("unknown --method ", method_opt);
        mg_config_set_method(&conf, method_opt);
    }
    const mg_method_t *m = mg_method_find(conf.method);
    if (m == NULL || m->state_bytes > sizeof task_state)
        return usage("method not in the C host yet (--list-methods names those it has): ",
                     conf.method);
    static mg_camera_t cam = {.fd = -1}; /* free running: frames from --camera (camera.h) */
    if (camera != NULL && sock == NULL) {
        const char *why = "";
        if (mg_camera_open(&cam, camera, &why) < 0)
            return usage(why, camera);
    }
    const int fd = sys_open(port, SYS_O_RDWR | SYS_O_NOCTTY, 0);
    if (fd < 0)
        return usage("cannot open --port ", port);
    sys_tty_raw(fd); /* a pty or a UART; a plain file (a test) stays as it is */
    mg_host_config_t cfg;
    mg_host_config_default(&cfg);
    const mg_task_if_t task = mg_method_bind(m, task_state, &conf);
    const int32_t n_det = mg_detectors_table(&detectors, &app, conf.f_px, table,
                                             MG_MAX_DETECTORS);
    detectors.u0_px = conf.u0_px;
    detectors.v0_px = conf.v0_px;
    mg_app_init(&app, &cfg, &task, table, n_det);
    if (sock != NULL) {
        const int s = sys_unix_connect(sock);
        if (s < 0)
            return usage("cannot connect to --lockstep ", sock);
        mg_lockstep_init(&driver, &app);
        const char *why = "";
        const int r = mg_lockstep_run(&driver, s, fd, &why);
        sys_close(s);
        sys_close(fd);
        if (r != 0) {
            say("the simulator went away mid-run or sent a bad message: ", why, "; stopping");
            return 1;
        }
        return 0;
    }
    const int r = mg_linux_run(&app, fd, camera != NULL ? &cam : NULL);
    sys_close(fd);
    mg_camera_close(&cam);
    static char stats[MG_APP_STATS_BYTES + 1]; /* the program's figures (app.h) */
    const size_t len = mg_app_stats_json(&app, stats, sizeof stats - 1);
    if (len > 0) {
        stats[len] = 0;
        say("stats ", stats, "");
    }
    if (r != 0) {
        say("the MCU side closed the port ", port, "; stopping");
        return 1;
    }
    return strcmp(app.state, "DONE") == 0 ? 0 : 1;
}
