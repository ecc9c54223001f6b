/* hostc/sys.h: the OS services of the C host's drivers. Implementations: sys_posix.c (libc,
 * native build) and arm/sys_arm.c (raw EABI syscalls, static ARMv4T ELF with its own _start).
 * Returns: >= 0 success, -errno on failure. */
#ifndef HOSTC_SYS_H
#define HOSTC_SYS_H
#include <stddef.h>
#include <stdint.h>
#define SYS_O_RDONLY 0
#define SYS_O_WRONLY 01
#define SYS_O_RDWR 02
#define SYS_O_CREAT 0100
#define SYS_O_TRUNC 01000
#define SYS_O_NOCTTY 0400
#define SYS_O_NONBLOCK 04000
#define SYS_POLLIN 0x1
#define SYS_POLLOUT 0x4
#define SYS_POLLERR 0x8
#define SYS_POLLHUP 0x10
struct sys_pollfd { int32_t fd; int16_t events; int16_t revents; };
long sys_read(int fd, void *buf, size_t n);
long sys_write(int fd, const void *buf, size_t n);
int sys_open(const char *path, int flags, int mode);
int sys_close(int fd);
int sys_tty_raw(int fd);                 /* raw 8N1, 115200, no echo (termios via ioctl) */
int sys_ioctl(int fd, uint32_t request, void *arg); /* a device's request (V4L2) */
int sys_poll(struct sys_pollfd *fds, unsigned nfds, int timeout_ms);
int64_t sys_monotonic_us(void);          /* CLOCK_MONOTONIC */
int sys_sleep_us(uint32_t us);
int sys_unix_connect(const char *path);  /* AF_UNIX SOCK_STREAM socket + connect: fd */
void *sys_mmap_shared(int fd, size_t len, int writable);  /* MAP_SHARED; NULL on failure */
int sys_munmap(void *addr, size_t len);
void sys_exit(int code) __attribute__((noreturn));
#endif
