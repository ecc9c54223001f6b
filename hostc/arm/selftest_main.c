/* The program's entry while hostc/ has no main of its own: the self-test options
 * (selftest.h) and a usage error (exit 2) for anything else. */
#include "../selftest.h"
#include "../sys.h"

int main(int argc, char **argv)
{
    static const char usage[] = "usage: mobigrasp-host " HOSTC_SELFTEST_USAGE "\n";
    int code = hostc_selftest_main(argc, argv);
    if (code >= 0)
        return code;
    sys_write(2, usage, sizeof usage - 1);
    return 2;
}
