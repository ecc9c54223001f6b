"""Build what the simavr backend runs, each into a cache keyed by its sources' hash.

Two artefacts: the avr-gcc ELF of the firmware (``firmware/Makefile`` with ``BUILD`` set to the
cache folder; a variant adds preprocessor definitions, which are part of its key) and the
harness around libsimavr (``firmware/simavr/harness.c``, compiled with the machine's gcc by
cffi in API mode and linked against ``libsimavr``). Debian's ``simavr``/``libsimavr-dev`` and
``gcc-avr``/``avr-libc`` are installed with apt-get when missing, as ``make firmware`` does.
Both live under ``$MOBIGRASP_CACHE_DIR`` (default ``~/.cache/mobigrasp``)``/simavr/``; a build
goes to a temporary folder renamed into place, so concurrent first uses see whole results.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from mobigrasp import cbuild
from mobigrasp.mcu_sim.native.build import FIRMWARE_DIR
from mobigrasp.mcu_sim.native.build import source_hash as firmware_hash

HARNESS_DIR = FIRMWARE_DIR / "simavr"
SIMAVR_HEADER = Path("/usr/include/simavr/sim_avr.h")

# What Python sees of the harness: its header, read by src/mobigrasp/cbuild.py.
HARNESS_HEADER = "harness.h"

_loaded: dict[str, object] = {}
_elves: dict[str, Elf] = {}


class SimavrBuildError(RuntimeError):
    """simavr, avr-gcc or the harness could not be installed, built or loaded."""


@dataclass(frozen=True)
class Elf:
    """A built firmware image and the data-space addresses of the globals the backend reads."""

    path: Path
    symbols: dict[str, int]

    def addr(self, name: str) -> int:
        """Data-space address of global ``name`` (SRAM offset, as the core's data[] has it)."""
        try:
            return self.symbols[name] - 0x800000
        except KeyError:
            raise SimavrBuildError(f"{self.path}: no symbol {name!r}") from None


def cache_dir() -> Path:
    """Where built ELFs and harness modules are kept."""
    return cbuild.cache_root() / "simavr"


def _apt_install(packages: list[str], why: str) -> None:
    print(f"simavr backend: {why} missing, installing {' '.join(packages)} with apt-get",
          file=sys.stderr)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    try:
        subprocess.run(["apt-get", "install", "-y", "-qq", *packages], check=True, env=env,
                       stdout=subprocess.DEVNULL)
    except (OSError, subprocess.CalledProcessError):
        try:
            subprocess.run(["apt-get", "update", "-qq"], check=True, env=env,
                           stdout=subprocess.DEVNULL)
            subprocess.run(["apt-get", "install", "-y", "-qq", *packages], check=True, env=env,
                           stdout=subprocess.DEVNULL)
        except (OSError, subprocess.CalledProcessError) as exc:
            raise SimavrBuildError(f"installing {' '.join(packages)} failed ({exc}); install "
                                   "them by hand") from exc


def ensure_tools() -> None:
    """avr-gcc, avr-libc and libsimavr's headers present (apt-get installs them if not)."""
    if shutil.which("avr-gcc") is None:
        _apt_install(["gcc-avr", "avr-libc"], "avr-gcc")
    if not SIMAVR_HEADER.is_file():
        _apt_install(["simavr", "libsimavr-dev"], str(SIMAVR_HEADER))


def build_elf(defines: dict[str, int | str] | None = None) -> Elf:
    """The firmware ELF built with avr-gcc (plus ``-Dname=value`` for each of ``defines``)."""
    defines = dict(sorted((defines or {}).items()))
    for k, v in defines.items():
        if not k.isidentifier() or any(c in str(v) for c in " '\"$\\"):
            raise ValueError(f"bad build definition {k}={v!r}")
    flags = " ".join(f"-D{k}={v}" for k, v in defines.items())
    digest = hashlib.sha256(f"{firmware_hash()}|{flags}".encode()).hexdigest()[:16]
    if digest in _elves:
        return _elves[digest]
    target = cache_dir() / f"elf-{digest}"
    elf = target / "mobigrasp-avr.elf"
    cbuild.build_once(target, elf.is_file, lambda: _make_elf(target, flags))
    nm = subprocess.run(["avr-nm", str(elf)], capture_output=True, text=True)
    if nm.returncode != 0:
        raise SimavrBuildError(f"avr-nm {elf} failed: {nm.stderr.strip()}")
    symbols = {}
    for line in nm.stdout.splitlines():
        parts = line.split()
        if len(parts) == 3:
            symbols[parts[2]] = int(parts[0], 16)
    out = _elves[digest] = Elf(elf, symbols)
    return out


def _make_elf(target: Path, flags: str) -> None:
    ensure_tools()
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        run = subprocess.run(
            ["make", "-s", "-C", str(FIRMWARE_DIR), f"BUILD={tmp}", f"EXTRA_CFLAGS={flags}",
             f"{tmp}/mobigrasp-avr.elf"], capture_output=True, text=True)
        if run.returncode != 0:
            raise SimavrBuildError(f"avr-gcc build failed: {run.stderr.strip()[-2000:]}")
        keep = tmp / "out"
        keep.mkdir()
        shutil.move(str(tmp / "mobigrasp-avr.elf"), keep / "mobigrasp-avr.elf")
        cbuild.rename_into_place(keep, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def harness_hash() -> str:
    """SHA-256 (hex, 16 digits) of the harness's sources, the declarations and the interpreter."""
    h = hashlib.sha256()
    for p in sorted(HARNESS_DIR.glob("*.[ch]")):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    h.update(Path(cbuild.__file__).read_bytes())
    h.update(sys.version.encode())
    return h.hexdigest()[:16]


def load_harness():
    """The compiled harness module (``.ffi``, ``.lib``), built first if this hash has none."""
    digest = harness_hash()
    if digest in _loaded:
        return _loaded[digest]
    name = f"_mobigrasp_simavr_{digest}"
    target = cache_dir() / f"harness-{digest}"

    def build() -> Path:
        ensure_tools()
        return _build_harness(name, target)

    module = cbuild.load_cached(name, target, build, SimavrBuildError)
    _loaded[digest] = module
    return module


def _build_harness(name: str, target: Path) -> Path:
    def configure(ffi) -> None:
        ffi.cdef(cbuild.header_cdef((HARNESS_HEADER,), [HARNESS_DIR]))
        ffi.set_source(name, f'#include "{HARNESS_HEADER}"',
                       sources=[str(HARNESS_DIR / "harness.c")],
                       include_dirs=[str(HARNESS_DIR)], libraries=["simavr"],
                       extra_compile_args=["-O2", "-std=gnu99", "-Wall"])

    return cbuild.compile_module(name, target, configure, SimavrBuildError)
