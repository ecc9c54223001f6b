"""Build the C firmware for this machine (cffi, API mode) into a cache keyed by the sources' hash.

The firmware sources (``firmware/fw``, ``firmware/protocol``) and ``firmware/hal_native.c`` are
compiled with ``-DFW_NATIVE`` into one extension module. The HAL's output calls are cffi
``extern "Python+C"`` functions: the firmware calls them like any C function and cffi hands
them to the Python peripheral models (``mcu_sim/native/firmware.py`` defines them). The module
lives in ``$MOBIGRASP_CACHE_DIR`` (default ``~/.cache/mobigrasp``)/``native/<hash>/``; the hash
covers every source, header, the declarations below and the interpreter, so a changed source
builds anew and an unchanged one loads in milliseconds. A build goes to a temporary folder that
is renamed into place, so concurrent first uses cannot see half a module.
"""

from __future__ import annotations

import hashlib
import re
import sys
from pathlib import Path

from mobigrasp import cbuild
from mobigrasp.resources import data_dir

FIRMWARE_DIR = data_dir("mobigrasp.firmware")
SOURCE_GLOBS = ("fw/*.c", "protocol/*.c")
NATIVE_HAL = "hal_native.c"

# What Python sees of the C, read from the headers (src/mobigrasp/cbuild.py): the program's entry
# points and globals, the PARAM and joint tables, the native HAL's extras; and hal.h, whose
# output calls are cffi "Python+C" functions implemented by the Python models, except the ones
# hal_native.c defines itself.
HEADERS = ("fw/params.h", "fw/program.h", "protocol/joints.h", "hal_native.h")
HAL_HEADER = "hal.h"
HAL_IN_C = frozenset({"hal_micros", "hal_irq_save", "hal_irq_restore"})
DEFINES = ("FW_NATIVE=1",)

# The module's own C: the headers the declarations come from.
SOURCE_PREAMBLE = "".join(f'#include "{h}"\n' for h in (HAL_HEADER, *HEADERS))


def cdef(firmware_dir: Path = FIRMWARE_DIR) -> str:
    """The cffi declarations of the native module, from its headers."""
    dirs = [firmware_dir]
    plain = cbuild.header_cdef(HEADERS, dirs, DEFINES)
    in_c, in_python = [], []
    for decl in cbuild.header_cdef((HAL_HEADER,), dirs, DEFINES).split(";"):
        name = re.search(r"(\w+)\s*\(", decl)
        if name:
            (in_c if name.group(1) in HAL_IN_C else in_python).append(decl.strip() + ";")
    return "\n".join([plain, *in_c, 'extern "Python+C" {', *in_python, "}"])


_loaded: dict[str, object] = {}


class NativeBuildError(RuntimeError):
    """The C firmware could not be compiled or loaded on this machine."""


def sources(firmware_dir: Path = FIRMWARE_DIR) -> list[Path]:
    """The C files of the native module, in a fixed order."""
    found: list[Path] = []
    for pattern in SOURCE_GLOBS:
        found += sorted(firmware_dir.glob(pattern))
    return found + [firmware_dir / NATIVE_HAL]


def source_hash(firmware_dir: Path = FIRMWARE_DIR) -> str:
    """SHA-256 (hex, 16 digits) of every file the module is built from, and of the build setup."""
    h = hashlib.sha256()
    files = sorted(p for p in firmware_dir.rglob("*")
                   if p.suffix in (".c", ".h", ".inc")
                   and "build" not in p.relative_to(firmware_dir).parts)
    for p in files:
        h.update(str(p.relative_to(firmware_dir)).encode())
        h.update(p.read_bytes())
    h.update(" ".join([*HEADERS, HAL_HEADER, *sorted(HAL_IN_C), *DEFINES]).encode())
    h.update(Path(cbuild.__file__).read_bytes())
    h.update(sys.version.encode())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    """Where built modules are kept."""
    return cbuild.cache_root() / "native"


def load(firmware_dir: Path = FIRMWARE_DIR):
    """The compiled module (``.ffi``, ``.lib``), built first if this source hash has none."""
    if not firmware_dir.is_dir():
        raise NativeBuildError(f"{firmware_dir}: no firmware sources (the native backend needs "
                               "the repository's firmware/ folder)")
    digest = source_hash(firmware_dir)
    if digest in _loaded:
        return _loaded[digest]
    name = f"_mobigrasp_fw_{digest}"
    target = cache_dir() / digest
    module = cbuild.load_cached(name, target, lambda: _build(firmware_dir, name, target),
                         NativeBuildError)
    _loaded[digest] = module
    return module


def _build(firmware_dir: Path, name: str, target: Path) -> Path:
    def configure(ffi) -> None:
        ffi.cdef(cdef(firmware_dir))
        ffi.set_source(
            name, SOURCE_PREAMBLE,
            sources=[str(p) for p in sources(firmware_dir)],
            include_dirs=[str(firmware_dir)],
            define_macros=[tuple(d.split("=")) for d in DEFINES],
            extra_compile_args=["-O2", "-Wall", "-Wno-unused-function"],
        )

    return cbuild.compile_module(name, target, configure, NativeBuildError)
