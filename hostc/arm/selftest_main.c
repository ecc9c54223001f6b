/* The entry of the ARM build while it holds the kernels alone: `--self-test` runs the
 * self-test, `--self-test-io TTY SOCKET FILE` its part with peers (selftest.c); anything else is
 * a usage error (exit 2). */
#include <string.h>

#include "../selftest.h"
#include "../sys.h"

int main(int argc, char **argv)
{
    static const char usage[] =
        "usage: mobigrasp-host --self-test | --self-test-io TTY SOCKET FILE\n";
    if (argc == 2 && strcmp(argv[1], "--self-test") == 0)
        return hostc_selftest();
    if (argc == 5 && strcmp(argv[1], "--self-test-io") == 0)
        return hostc_selftest_io(argv[2], argv[3], argv[4]);
    sys_write(2, usage, sizeof usage - 1);
    return 2;
}
