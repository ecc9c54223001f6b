/* hostc/sys.h on Linux ARM EABI without a C library: each call is one system call, `swi 0`
 * with its number in r7 and up to six arguments in r0-r5; the kernel returns the result or
 * -errno in r0, which is what sys.h returns. Numbers from the kernel's EABI table
 * (arch/arm/tools/syscall.tbl); only calls present since Linux 2.6.16 are used, so the
 * mini2440's 2.6 kernels run the binary too (clock_gettime, not clock_gettime64: the monotonic
 * clock's 32-bit seconds last 68 years from boot). ARMv4T: no BLX, returns are `bx lr`. */
#include "../sys.h"

enum {
    NR_EXIT = 1, NR_READ = 3, NR_WRITE = 4, NR_OPEN = 5, NR_CLOSE = 6, NR_IOCTL = 54,
    NR_MUNMAP = 91, NR_NANOSLEEP = 162, NR_POLL = 168, NR_MMAP2 = 192, NR_EXIT_GROUP = 248,
    NR_CLOCK_GETTIME = 263, NR_SOCKET = 281, NR_CONNECT = 283
};

static long syscall6(long nr, long a, long b, long c, long d, long e, long f)
{
    register long r0 __asm__("r0") = a;
    register long r1 __asm__("r1") = b;
    register long r2 __asm__("r2") = c;
    register long r3 __asm__("r3") = d;
    register long r4 __asm__("r4") = e;
    register long r5 __asm__("r5") = f;
    register long r7 __asm__("r7") = nr;
    __asm__ volatile("swi 0"
                     : "+r"(r0)
                     : "r"(r1), "r"(r2), "r"(r3), "r"(r4), "r"(r5), "r"(r7)
                     : "memory");
    return r0;
}

#define SYSCALL3(nr, a, b, c) syscall6((nr), (long)(a), (long)(b), (long)(c), 0, 0, 0)

long sys_read(int fd, void *buf, size_t n) { return SYSCALL3(NR_READ, fd, buf, n); }

long sys_write(int fd, const void *buf, size_t n) { return SYSCALL3(NR_WRITE, fd, buf, n); }

int sys_open(const char *path, int flags, int mode)
{
    return (int)SYSCALL3(NR_OPEN, path, flags, mode);
}

int sys_close(int fd) { return (int)SYSCALL3(NR_CLOSE, fd, 0, 0); }

int sys_ioctl(int fd, uint32_t request, void *arg)
{
    return (int)SYSCALL3(NR_IOCTL, fd, request, arg);
}

/* the kernel's struct termios (include/uapi/asm-generic/termbits.h, ARM's) and its flags */
struct k_termios {
    uint32_t c_iflag, c_oflag, c_cflag, c_lflag;
    uint8_t c_line;
    uint8_t c_cc[19];
};
enum {
    TCGETS = 0x5401, TCSETS = 0x5402,
    IGNBRK = 01, BRKINT = 02, PARMRK = 010, ISTRIP = 040, INLCR = 0100, IGNCR = 0200,
    ICRNL = 0400, IXON = 02000, IXOFF = 010000, OPOST = 01,
    ISIG = 01, ICANON = 02, ECHO = 010, ECHONL = 0100, IEXTEN = 0100000,
    CBAUD = 010017, B115200 = 010002, CSIZE = 060, CS8 = 060, CSTOPB = 0100, CREAD = 0200,
    PARENB = 0400, CLOCAL = 04000, VTIME = 5, VMIN = 6
};
#define CRTSCTS 020000000000u

/* cfmakeraw's flags, 115200 baud, one stop bit, no parity, the receiver on, modem lines and
 * RTS/CTS ignored (the link to the ATmega128 is TXD, RXD and ground); read returns as soon as
 * one byte is there */
int sys_tty_raw(int fd)
{
    struct k_termios t;
    long r = SYSCALL3(NR_IOCTL, fd, TCGETS, &t);
    if (r < 0)
        return (int)r;
    t.c_iflag &= ~(uint32_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON |
                             IXOFF);
    t.c_oflag &= ~(uint32_t)OPOST;
    t.c_lflag &= ~(uint32_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    t.c_cflag &= ~((uint32_t)(CBAUD | CSIZE | CSTOPB | PARENB) | CRTSCTS);
    t.c_cflag |= (uint32_t)(B115200 | CS8 | CREAD | CLOCAL);
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    return (int)SYSCALL3(NR_IOCTL, fd, TCSETS, &t);
}

/* struct sys_pollfd has the layout of the kernel's struct pollfd */
int sys_poll(struct sys_pollfd *fds, unsigned nfds, int timeout_ms)
{
    return (int)SYSCALL3(NR_POLL, fds, nfds, timeout_ms);
}

struct k_timespec { int32_t tv_sec, tv_nsec; };

int64_t sys_monotonic_us(void)
{
    struct k_timespec ts;
    long r = SYSCALL3(NR_CLOCK_GETTIME, 1 /* CLOCK_MONOTONIC */, &ts, 0);
    if (r < 0)
        return r;
    return (int64_t)ts.tv_sec * 1000000 + (int32_t)((uint32_t)ts.tv_nsec / 1000u);
}

int sys_sleep_us(uint32_t us)
{
    struct k_timespec ts;
    ts.tv_sec = (int32_t)(us / 1000000u);
    ts.tv_nsec = (int32_t)(us - (uint32_t)ts.tv_sec * 1000000u) * 1000;
    return (int)SYSCALL3(NR_NANOSLEEP, &ts, 0, 0);
}

/* struct sockaddr_un: sa_family_t, then the path, NUL-terminated */
struct k_sockaddr_un {
    uint16_t sun_family;
    char sun_path[108];
};
enum { AF_UNIX = 1, SOCK_STREAM = 1, ENAMETOOLONG = 36 };

int sys_unix_connect(const char *path)
{
    struct k_sockaddr_un addr;
    size_t n = 0;
    while (path[n] != '\0') {
        if (n + 1 >= sizeof addr.sun_path)
            return -ENAMETOOLONG;
        addr.sun_path[n] = path[n];
        n++;
    }
    addr.sun_path[n] = '\0';
    addr.sun_family = AF_UNIX;
    long fd = SYSCALL3(NR_SOCKET, AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0)
        return (int)fd;
    long r = SYSCALL3(NR_CONNECT, fd, &addr, sizeof addr.sun_family + n + 1);
    if (r < 0) {
        SYSCALL3(NR_CLOSE, fd, 0, 0);
        return (int)r;
    }
    return (int)fd;
}

enum { PROT_READ = 1, PROT_WRITE = 2, MAP_SHARED = 1 };

/* mmap2's offset is in 4096-byte pages; the whole object from offset 0 here. A result in the
 * last page of the address space is -errno. */
void *sys_mmap_shared(int fd, size_t len, int writable)
{
    long r = syscall6(NR_MMAP2, 0, (long)len, writable ? PROT_READ | PROT_WRITE : PROT_READ,
                      MAP_SHARED, fd, 0);
    if ((unsigned long)r >= (unsigned long)-4095)
        return NULL;
    return (void *)r;
}

int sys_munmap(void *addr, size_t len) { return (int)SYSCALL3(NR_MUNMAP, addr, len, 0); }

void sys_exit(int code)
{
    SYSCALL3(NR_EXIT_GROUP, code, 0, 0);
    for (;;)
        SYSCALL3(NR_EXIT, code, 0, 0);
}
