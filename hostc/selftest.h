/* The host's self-test (selftest.c): every kernel on built-in inputs, one checksum line each on
 * standard output, then the OS services of sys.h. Returns 0 when all of it ran. */
#ifndef HOSTC_SELFTEST_H
#define HOSTC_SELFTEST_H

int hostc_selftest(void);

#endif
