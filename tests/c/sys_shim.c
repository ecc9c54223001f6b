/* hostc/sys.h on the machine's C library, for the native build of the self-test that the
 * ARM build's output is compared with (tests/test_hostc_arm.py): only what selftest.c calls,
 * each returning -errno on failure as sys.h says. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "sys.h"

static long ret(long r) { return r < 0 ? -errno : r; }

long sys_read(int fd, void *buf, size_t n) { return ret(read(fd, buf, n)); }
long sys_write(int fd, const void *buf, size_t n) { return ret(write(fd, buf, n)); }
int sys_open(const char *path, int flags, int mode) { return (int)ret(open(path, flags, mode)); }
int sys_close(int fd) { return (int)ret(close(fd)); }

int sys_tty_raw(int fd)
{
    struct termios t;
    if (tcgetattr(fd, &t) < 0)
        return -errno;
    t.c_lflag &= ~(tcflag_t)(ECHO | ICANON);
    return (int)ret(tcsetattr(fd, TCSANOW, &t));
}

int sys_poll(struct sys_pollfd *fds, unsigned nfds, int timeout_ms)
{
    return (int)ret(poll((struct pollfd *)fds, nfds, timeout_ms));
}

int64_t sys_monotonic_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

int sys_sleep_us(uint32_t us)
{
    struct timespec ts = { us / 1000000u, (long)(us % 1000000u) * 1000 };
    return (int)ret(nanosleep(&ts, NULL));
}

int sys_unix_connect(const char *path)
{
    struct sockaddr_un a = { .sun_family = AF_UNIX };
    strncpy(a.sun_path, path, sizeof a.sun_path - 1);
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0)
        return -errno;
    if (connect(fd, (struct sockaddr *)&a, sizeof a) < 0) {
        int e = errno;
        close(fd);
        return -e;
    }
    return fd;
}

void *sys_mmap_shared(int fd, size_t len, int writable)
{
    void *p = mmap(NULL, len, writable ? PROT_READ | PROT_WRITE : PROT_READ, MAP_SHARED, fd, 0);
    return p == MAP_FAILED ? NULL : p;
}

int sys_munmap(void *addr, size_t len) { return (int)ret(munmap(addr, len)); }
void sys_exit(int code) { exit(code); }
