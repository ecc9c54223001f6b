"""The C host's portable code builds warning-free for the board and needs nothing of libc but
the few string functions: every module compiled with the machine's gcc and with
arm-none-eabi-gcc -mcpu=arm920t -marm -ffreestanding, -Wall -Wextra -Werror -std=c99, and the
ARM objects' undefined symbols (what the link would take from libc and libgcc) checked: no
soft-float helper (no float or double in the port), no allocation, no stdio."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from c_build_cache import built

from mobigrasp import hostc

FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", f"-I{hostc.HOSTC}",
         f"-I{hostc.PROTOCOL}", "-c"]
ARM = ["arm-none-eabi-gcc", "-mcpu=arm920t", "-marm", "-ffreestanding"]
# the libc and libgcc the portable code may take: the string functions, and the EABI integer
# division and 64-bit shift helpers of a core without divide instructions; besides, the OS
# services (sys.h) and the self-test's options (selftest.c, built with the vision kernels)
ALLOWED = re.compile(r"^(memcpy|memset|memmove|memcmp|strlen|strcmp|strncmp|"
                     r"__aeabi_(u?idiv|u?idivmod|u?ldivmod|llsl|llsr|lasr|lmul)|sys_\w+|"
                     r"hostc_selftest_main)$")
PORTABLE = sorted({s for s in hostc.PROGRAM + hostc.SOURCES if s.name != "sys_posix.c"})


def _undefined(objs: list[Path]) -> set[str]:
    out = subprocess.run(["arm-none-eabi-nm", *map(str, objs)], capture_output=True,
                         text=True, check=True).stdout
    defined, undefined = set(), set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 2 and parts[0] == "U":
            undefined.add(parts[1])
        elif len(parts) == 3:
            defined.add(parts[2])
    return undefined - defined


@pytest.mark.parametrize("compiler", [["gcc"], ARM], ids=["gcc", "arm920t"])
def test_portable_modules_build_warning_free(compiler):
    def make(folder: Path) -> None:
        for src in PORTABLE:
            done = subprocess.run([*compiler, *FLAGS, str(src), "-o",
                                   str(folder / (src.stem + ".o"))],
                                  capture_output=True, text=True, check=False)
            assert done.returncode == 0, f"{src.name}: {done.stderr}"

    # the objects of the same sources, flags and compiler come from the cache (a build that
    # failed left none there)
    folder = built("portable-" + compiler[0], compiler[:1],
                   [*compiler, *FLAGS, *(s.name for s in PORTABLE)], make,
                   sources=(hostc.HOSTC, hostc.PROTOCOL))
    objs = [folder / (src.stem + ".o") for src in PORTABLE]
    if compiler is ARM:
        needs = _undefined(objs)
        assert {s for s in needs if not ALLOWED.match(s)} == set()
        assert not {s for s in needs if s.startswith(("__aeabi_d", "__aeabi_f"))}
