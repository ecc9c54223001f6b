/* The host's self-test (selftest.c): every kernel on built-in inputs, one checksum line each on
 * standard output, then the OS services of sys.h. Returns 0 when all of it ran. */
#ifndef HOSTC_SELFTEST_H
#define HOSTC_SELFTEST_H

int hostc_selftest(void);

/* The OS services that need a peer: the terminal tty made raw, "ping\n" written to it and its
 * answer read; "hello" sent on the Unix socket sock and its answer read; the first 4096 bytes of
 * file summed through a shared mapping and byte 100 set to 0x5a through it. One line each;
 * returns 0 when every call succeeded. */
int hostc_selftest_io(const char *tty, const char *sock, const char *file);

/* The program's self-test options: `--self-test` runs hostc_selftest, `--self-test-io TTY
 * SOCKET FILE` hostc_selftest_io; their exit code, or -1 when argv asks for neither (main goes
 * on with its own options). */
#define HOSTC_SELFTEST_USAGE "--self-test | --self-test-io TTY SOCKET FILE"
int hostc_selftest_main(int argc, char **argv);

#endif
