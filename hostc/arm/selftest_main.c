/* The entry of the ARM build while it holds the kernels alone: `--self-test` runs the
 * self-test (selftest.c); anything else is a usage error (exit 2). */
#include <string.h>

#include "../selftest.h"
#include "../sys.h"

int main(int argc, char **argv)
{
    static const char usage[] = "usage: mobigrasp-host --self-test\n";
    if (argc == 2 && strcmp(argv[1], "--self-test") == 0)
        return hostc_selftest();
    sys_write(2, usage, sizeof usage - 1);
    return 2;
}
