/* sys.h on libc: the native build of the C host (the machine's gcc, any POSIX system). The
 * flag and poll constants of sys.h are Linux's values; they are translated here so the same
 * code runs where libc's differ. Every failure is returned as -errno. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* CRTSCTS */
#include "sys.h"

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

static int open_flags(int flags)
{
    int f = (flags & SYS_O_RDWR) ? O_RDWR : (flags & SYS_O_WRONLY) ? O_WRONLY : O_RDONLY;
    if (flags & SYS_O_CREAT)
        f |= O_CREAT;
    if (flags & SYS_O_TRUNC)
        f |= O_TRUNC;
    if (flags & SYS_O_NOCTTY)
        f |= O_NOCTTY;
    if (flags & SYS_O_NONBLOCK)
        f |= O_NONBLOCK;
    return f;
}

long sys_read(int fd, void *buf, size_t n)
{
    ssize_t got;
    do
        got = read(fd, buf, n);
    while (got < 0 && errno == EINTR);
    return got < 0 ? -(long)errno : (long)got;
}

long sys_write(int fd, const void *buf, size_t n)
{
    ssize_t put;
    do
        put = write(fd, buf, n);
    while (put < 0 && errno == EINTR);
    return put < 0 ? -(long)errno : (long)put;
}

int sys_open(const char *path, int flags, int mode)
{
    int fd = open(path, open_flags(flags), (mode_t)mode);
    return fd < 0 ? -errno : fd;
}

int sys_close(int fd)
{
    return close(fd) < 0 ? -errno : 0;
}

int sys_ioctl(int fd, uint32_t request, void *arg)
{
    return ioctl(fd, (unsigned long)request, arg) < 0 ? -errno : 0;
}

int sys_tty_raw(int fd)
{
    struct termios t;
    if (tcgetattr(fd, &t) < 0)
        return -errno;
    /* cfmakeraw's settings, spelled out (it is not POSIX): 8N1, no echo, no translation, no
     * flow control (the link is TXD, RXD and ground), a read waits for one byte at least; as
     * arm/sys_arm.c sets them */
    t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON
                             | IXOFF);
    t.c_oflag &= ~(tcflag_t)OPOST;
    t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
#ifdef CRTSCTS
    t.c_cflag &= ~(tcflag_t)CRTSCTS;
#endif
    t.c_cflag |= CS8 | CLOCAL | CREAD;
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    if (cfsetispeed(&t, B115200) < 0 || cfsetospeed(&t, B115200) < 0)
        return -errno;
    return tcsetattr(fd, TCSANOW, &t) < 0 ? -errno : 0;
}

int sys_poll(struct sys_pollfd *fds, unsigned nfds, int timeout_ms)
{
    struct pollfd p[16];
    if (nfds > 16)
        return -EINVAL;
    for (unsigned i = 0; i < nfds; i++) {
        p[i].fd = fds[i].fd;
        p[i].events = (short)(((fds[i].events & SYS_POLLIN) ? POLLIN : 0)
                              | ((fds[i].events & SYS_POLLOUT) ? POLLOUT : 0));
        p[i].revents = 0;
    }
    int n;
    do
        n = poll(p, (nfds_t)nfds, timeout_ms);
    while (n < 0 && errno == EINTR);
    if (n < 0)
        return -errno;
    for (unsigned i = 0; i < nfds; i++)
        fds[i].revents = (int16_t)(((p[i].revents & POLLIN) ? SYS_POLLIN : 0)
                                   | ((p[i].revents & POLLOUT) ? SYS_POLLOUT : 0)
                                   | ((p[i].revents & POLLERR) ? SYS_POLLERR : 0)
                                   | ((p[i].revents & POLLHUP) ? SYS_POLLHUP : 0));
    return n;
}

int64_t sys_monotonic_us(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) < 0)
        return -errno;
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

int sys_sleep_us(uint32_t us)
{
    struct timespec ts = {(time_t)(us / 1000000u), (long)(us % 1000000u) * 1000L};
    while (nanosleep(&ts, &ts) < 0)
        if (errno != EINTR)
            return -errno;
    return 0;
}

int sys_unix_connect(const char *path)
{
    struct sockaddr_un addr;
    size_t len = strlen(path);
    if (len >= sizeof addr.sun_path)
        return -ENAMETOOLONG;
    memset(&addr, 0, sizeof addr);
    addr.sun_family = AF_UNIX;
    memcpy(addr.sun_path, path, len + 1);
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0)
        return -errno;
    if (connect(fd, (const struct sockaddr *)&addr, sizeof addr) < 0) {
        int err = errno;
        close(fd);
        return -err;
    }
    return fd;
}

void *sys_mmap_shared(int fd, size_t len, int writable)
{
    void *p = mmap(NULL, len, PROT_READ | (writable ? PROT_WRITE : 0), MAP_SHARED, fd, 0);
    return p == MAP_FAILED ? NULL : p;
}

int sys_munmap(void *addr, size_t len)
{
    return munmap(addr, len) < 0 ? -errno : 0;
}

void sys_exit(int code)
{
    _exit(code);
}
