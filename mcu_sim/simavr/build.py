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

from mobigrasp.mcu_sim.native.build import FIRMWARE_DIR, cache_root, load_cached
from mobigrasp.mcu_sim.native.build import source_hash as firmware_hash

HARNESS_DIR = FIRMWARE_DIR / "simavr"
SIMAVR_HEADER = Path("/usr/include/simavr/sim_avr.h")

CDEF = """
typedef struct {
    uint32_t isr_max_cycles[35];
    uint32_t isr_count[35];
    uint32_t irq_off_max_cycles;
    uint32_t rx_latency_max_cycles;
    uint64_t sleep_cycles;
    uint32_t stack_depth_bytes;
    uint16_t sp_min;
    uint32_t tx_overflow;
    uint32_t resets;
    uint32_t loop_max_cycles;
    uint32_t loop_count;
} sh_profile_t;
typedef struct sh sh_t;
#define SH_NEVER ...
sh_t *sh_new(const char *elf_path, uint16_t rx_head_addr, uint16_t rx_over_addr,
             uint16_t bss_end);
void sh_free(sh_t *sh);
void sh_reset(sh_t *sh);
uint64_t sh_cycle(const sh_t *sh);
int sh_state(const sh_t *sh);
int sh_booted(const sh_t *sh);
void sh_set_byte_cycles(sh_t *sh, uint32_t cycles);
void sh_set_loop_addr(sh_t *sh, uint32_t addr);
void sh_set_idle_addrs(sh_t *sh, uint16_t rx_tail, uint16_t tx_head, uint16_t tx_tail,
                       uint16_t next_telemetry, uint16_t telemetry_hz);
uint64_t sh_tx_idle_through(const sh_t *sh);
int sh_run_to(sh_t *sh, uint64_t target);
void sh_pin(sh_t *sh, uint8_t port, uint8_t bit, uint8_t level);
int sh_uart_in(sh_t *sh, uint8_t byte);
uint32_t sh_rx_line_lost(const sh_t *sh);
uint32_t sh_tx_take(sh_t *sh, uint8_t *bytes, uint64_t *cycles, uint32_t max);
uint32_t sh_tx_pending(const sh_t *sh);
uint64_t sh_tx_line_free(const sh_t *sh);
uint32_t sh_triggers_take(sh_t *sh, uint8_t *idx, uint64_t *cycles, uint32_t max);
uint32_t sh_periods_take(sh_t *sh, uint64_t *cycles, uint16_t *regs, uint32_t max);
void sh_read(const sh_t *sh, uint16_t addr, uint8_t *dst, uint16_t n);
void sh_profile(const sh_t *sh, sh_profile_t *out);
uint32_t sh_pc(const sh_t *sh);
uint32_t sh_rx_unread(const sh_t *sh);
uint32_t sh_oc1_pin_high_cycles(const sh_t *sh, uint8_t ch);
"""

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
    return cache_root() / "simavr"


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


def _rename_into_place(tmp: Path, target: Path) -> None:
    try:
        os.rename(tmp, target)
    except OSError:
        if not target.is_dir():  # not a concurrent build that won the race
            raise


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
    if not elf.is_file():
        ensure_tools()
        target.parent.mkdir(parents=True, exist_ok=True)
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
            _rename_into_place(keep, target)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
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


def harness_hash() -> str:
    """SHA-256 (hex, 16 digits) of the harness's sources, the declarations and the interpreter."""
    h = hashlib.sha256()
    for p in sorted(HARNESS_DIR.glob("*.[ch]")):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    h.update(CDEF.encode())
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

    module = load_cached(name, target, build, SimavrBuildError)
    _loaded[digest] = module
    return module


def _build_harness(name: str, target: Path) -> Path:
    import cffi

    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        ffi = cffi.FFI()
        ffi.cdef(CDEF)
        ffi.set_source(name, '#include "harness.h"',
                       sources=[str(HARNESS_DIR / "harness.c")],
                       include_dirs=[str(HARNESS_DIR)], libraries=["simavr"],
                       extra_compile_args=["-O2", "-std=gnu99", "-Wall"])
        try:
            so = Path(ffi.compile(tmpdir=str(tmp), verbose=False))
        except Exception as exc:
            raise SimavrBuildError(f"building the simavr harness failed: {exc}") from exc
        keep = tmp / "out"
        keep.mkdir()
        shutil.move(str(so), keep / so.name)
        _rename_into_place(keep, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return sorted(target.glob(f"{name}*.so"))[0]
