"""The C host of ``hostc/`` (the S3C2440 program) built with the machine's C compiler as a cffi
module: the units its equivalence tests call beside their Python modules.

One C module per host module (hostc/<name>.c beside host/<name>.py); the declarations are the
units' headers themselves (src/mobigrasp/cbuild.py), and the build is kept in the cache of the C
parts (``$MOBIGRASP_CACHE_DIR``, ``hostc-port/<hash>``), made once per change of the C. The
joint table is the firmware's (``firmware/protocol/joints.c``): one table for both boards.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from functools import lru_cache
from pathlib import Path

from mobigrasp import cbuild
from mobigrasp.resources import data_dir

HOSTC = data_dir("mobigrasp.hostc_sources")
PROTOCOL = data_dir("mobigrasp.firmware") / "protocol"
HEADERS = ("budget.h", "fixedpoint.h", "arm_calib.h", "kinematics.h", "posture.h",
           "odometry.h", "path_follow.h", "fuzzy.h", "retransmit.h", "mcu_watch.h", "app_link.h",
           "outgoing_guard.h", "json.h", "lockstep.h", "app.h", "lockstep_driver.h",
           "transforms.h", "coverage.h", "search.h", "ranging.h", "task_machine.h", "task_method.h",
           "task_method002.h", "task_drive.h", "task_sense.h",
           "task_adjust.h", "control_points.h", "grasp_circle.h", "anytime.h",
           "bezier.h", "candidates.h", "plan000.h", "plan001.h", "blocked_q.h",
           "escape.h", "sonar_regions.h", "replan.h", "sonar_guard.h", "task_search.h",
           "task_grasp.h", "held_fill.h",
           "app_factory.h", "task_paper.h", "task_path.h", "task_approach.h",
           "task_method000.h", "task_method001.h", "detectors.h", "config.h")
SOURCES = (HOSTC / "budget.c", HOSTC / "trig.c", HOSTC / "fixedpoint.c", HOSTC / "arm_calib.c",
           HOSTC / "kinematics.c", HOSTC / "posture.c", HOSTC / "odometry.c",
           HOSTC / "path_follow.c", HOSTC / "fuzzy.c", HOSTC / "retransmit.c",
           HOSTC / "mcu_watch.c", HOSTC / "app_link.c", HOSTC / "outgoing_guard.c",
           HOSTC / "json.c", HOSTC / "lockstep.c", HOSTC / "app.c",
           HOSTC / "lockstep_driver.c", HOSTC / "sys_posix.c", HOSTC / "transforms.c",
           HOSTC / "coverage.c", HOSTC / "search.c", HOSTC / "ranging.c",
           HOSTC / "ranging_size.c", HOSTC / "task_machine.c", HOSTC / "task_method.c",
           HOSTC / "task_method002.c", HOSTC / "task_drive.c", HOSTC / "task_sense.c",
           HOSTC / "task_adjust.c", HOSTC / "control_points.c", HOSTC / "grasp_circle.c",
           HOSTC / "anytime.c", HOSTC / "bezier.c", HOSTC / "candidates.c",
           HOSTC / "plan000.c", HOSTC / "plan001.c", HOSTC / "bezier001.c",
           HOSTC / "blocked_q.c",
           HOSTC / "escape.c", HOSTC / "sonar_regions.c", HOSTC / "replan.c",
           HOSTC / "clearance.c", HOSTC / "sonar_guard.c",
           HOSTC / "task_search.c", HOSTC / "task_grasp.c", HOSTC / "held_fill.c",
           HOSTC / "app_factory.c", HOSTC / "task_paper.c", HOSTC / "task_approach.c",
           HOSTC / "task_method000.c", HOSTC / "task_method001.c", HOSTC / "detectors.c",
           HOSTC / "grey.c", HOSTC / "label.c", HOSTC / "edge.c", HOSTC / "double_cross.c",
           HOSTC / "red_cylinder.c", HOSTC / "dark.c", HOSTC / "radial_symbol.c",
           HOSTC / "dual_plus.c", HOSTC / "spoke.c", HOSTC / "config.c",
           PROTOCOL / "joints.c",
           PROTOCOL / "frame.c", PROTOCOL / "cobs.c", PROTOCOL / "crc16.c",
           PROTOCOL / "messages.c")


class HostcPortBuildError(RuntimeError):
    """The C host's units could not be compiled or loaded on this machine."""


def source_hash() -> str:
    """Hash of the units' sources and of every header they may include."""
    h = hashlib.sha256()
    headers = sorted((*HOSTC.glob("*.h"), *PROTOCOL.glob("*.h")))
    for path in (*headers, *SOURCES, Path(cbuild.__file__)):
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    return h.hexdigest()[:16]


@lru_cache(maxsize=1)
def lib():
    """The compiled units' ``(ffi, lib)``, built on first use."""
    digest = source_hash()
    return cbuild.cffi_library(f"_mg_hostc_port_{digest}", cbuild.cache_root() / "hostc-port"
                               / digest, HEADERS, SOURCES, [HOSTC, PROTOCOL],
                               HostcPortBuildError)


def ops_tuple(ops) -> tuple[int, ...]:
    """A C ``mg_ops_t`` as host.budget.OpCounts.as_tuple() gives its counts."""
    return (ops.pixels_read, ops.pixels_written, ops.alu, ops.branches, ops.muls, ops.muls32,
            ops.divs, ops.luts, ops.float_ops, ops.float_divs, ops.bytes_streamed)


# the program: every module of hostc/ (the self-test's kernels too) and the protocol codec
EXE_SOURCES = (*sorted(HOSTC.glob("*.c")), *sorted(PROTOCOL.glob("*.c")))
# the program's own modules beside the units (the rest of EXE_SOURCES are the vision kernels)
PROGRAM = (HOSTC / "main.c", HOSTC / "task.c", HOSTC / "task_idle.c", HOSTC / "linux_driver.c",
           HOSTC / "camera.c", HOSTC / "camera_raw.c", HOSTC / "camera_v4l2.c")


def executable(cc: str | None = None) -> Path:
    """The C host as a program for this machine (``mobigrasp-host-c``, the options of
    ``mobigrasp host``), built with the machine's compiler on first use into the cache."""
    digest = hashlib.sha256((source_hash() + "".join(
        p.name + p.read_text() for p in EXE_SOURCES)).encode()).hexdigest()[:16]
    target = cbuild.cache_root() / "hostc-exe" / digest
    exe = target / "mobigrasp-host-c"
    cbuild.build_once(target, exe.is_file, lambda: _compile_executable(target, exe.name, cc))
    return exe


def _compile_executable(target: Path, name: str, cc: str | None) -> None:
    compiler = cc or os.environ.get("CC") or "cc"
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        done = subprocess.run([compiler, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror",
                               f"-I{HOSTC}", f"-I{PROTOCOL}", "-o", str(tmp / name),
                               *map(str, EXE_SOURCES)], capture_output=True, text=True,
                              check=False)
        if done.returncode != 0:
            raise HostcPortBuildError(f"building {name} failed: {done.stderr.strip()}")
        cbuild.rename_into_place(tmp, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


INPROC = HOSTC / "inproc"


@lru_cache(maxsize=1)
def program_lib():
    """The C host program for the simulator's process (``hostc/inproc/inproc.h``: the program of
    ``executable()`` without its ``main``, one GRANT at a time) as a cffi module, ``(ffi, lib)``,
    built on first use into the cache."""
    sources = (*(p for p in EXE_SOURCES if p.name != "main.c"), INPROC / "inproc.c")
    h = hashlib.sha256(source_hash().encode())
    for path in (*sources, *sorted(INPROC.glob("*.h"))):
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    digest = h.hexdigest()[:16]
    return cbuild.cffi_library(f"_mg_hostc_program_{digest}",
                               cbuild.cache_root() / "hostc-program" / digest, ("inproc.h",),
                               sources, [INPROC, HOSTC, PROTOCOL], HostcPortBuildError)


def program_methods(argv: list[str], timeout_s: float = 60.0) -> tuple[str, ...]:
    """The method table of the C host program started as ``argv`` (the native executable, or
    the ARM ELF under qemu-arm), as the program itself prints it (``--list-methods``)."""
    done = subprocess.run([*argv, "--list-methods"], capture_output=True, text=True,
                          timeout=timeout_s, check=False)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise HostcPortBuildError(f"{' '.join(argv)} --list-methods failed: {last}")
    return tuple(line for line in done.stdout.splitlines() if line)
