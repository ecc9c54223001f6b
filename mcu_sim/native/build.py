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
import importlib.util
import os
import shutil
import sys
import tempfile
from pathlib import Path

FIRMWARE_DIR = Path(__file__).resolve().parents[2] / "firmware"
SOURCE_GLOBS = ("fw/*.c", "protocol/*.c")
NATIVE_HAL = "hal_native.c"

# What Python sees of the C: the program's entry points and globals (fw/program.h), the
# native HAL's extras (hal_native.c) and the HAL output calls it implements.
CDEF = """
typedef struct { uint8_t buf[128]; volatile uint8_t head; volatile uint8_t tail;
                 uint32_t overruns; } byte_ring_t;
typedef struct { uint32_t frames_ok, crc_errors, oversize, unknown_type, bad_version,
                 truncated, cobs_errors, garbage_bytes, bytes_in, recovered; } frame_stats_t;
typedef struct { uint8_t buf[70]; uint8_t len; uint8_t skipping; uint8_t start;
                 frame_stats_t stats; } frame_parser_t;
typedef struct { uint8_t tag[64]; uint16_t crc[64]; uint8_t result[64]; int16_t newest;
                 uint32_t duplicates; uint32_t reused; } dup_filter_t;
typedef struct { int32_t latched_q8[6]; int32_t pending_q8[6]; int32_t target_q8[6];
                 int32_t step_q8[6]; int16_t min_us[6]; int16_t max_us[6]; } servo_bank_t;
typedef struct { int16_t target_mmps; int32_t target_q8; int32_t integral;
                 int32_t last_count; int16_t duty; } wheel_pi_t;
typedef struct { uint16_t range_mm[5]; uint8_t index; volatile uint32_t rise_us;
                 volatile uint32_t fall_us; volatile uint8_t have_rise;
                 volatile uint8_t have_fall; uint32_t next_slot_us; volatile uint8_t active; }
    sonar_task_t;
typedef struct { uint32_t bad_frames, not_ready, unexpected, tx_dropped, limit_hits,
                 watchdog_trips, telemetry_sent; } fw_counters_t;
typedef struct { uint8_t drive_enabled, handshake, stopped, limit_flag, reset_flag,
                 watchdog_tripped; } fw_flags_t;

extern byte_ring_t fw_rx;
extern frame_parser_t fw_parser;
extern dup_filter_t fw_dup;
extern servo_bank_t fw_servos;
extern wheel_pi_t fw_wheels[2];
extern sonar_task_t fw_sonar;
extern volatile int32_t fw_enc_count[2];
extern fw_flags_t fw_flags;
extern fw_counters_t fw_counters;
extern uint8_t fw_tx_seq;
extern uint32_t fw_last_valid_us;
extern int32_t params_values[20];
extern uint32_t native_now_us;

void fw_setup(void);
void fw_isr_timer1_ovf(void);
void fw_isr_echo(uint8_t index, uint8_t level);
uint32_t fw_loop(void);
uint32_t fw_next_unprompted_send_us(uint8_t *off);
uint32_t fw_corrupt_frames(void);
void native_encoder_edges(uint8_t side, int32_t edges);
void native_usart_rx_bytes(const uint8_t *data, uint32_t n);
uint32_t native_state_size(void);
void native_state_save(uint8_t *dst);
void native_state_load(const uint8_t *src);
uint8_t params_get(uint16_t id, int32_t *value);
uint8_t params_check(uint16_t id, int32_t value);
void params_set(uint16_t id, int32_t value);
void params_reset(void);
int32_t joint_pulse_us(uint8_t ch, int32_t value);
void joint_mech_limits_us(uint8_t ch, int16_t *lo, int16_t *hi);
int32_t mrad_slew_to_us(int32_t slew_mrad_per_s);
void params_row(uint8_t i, uint16_t *id, int32_t *def, int32_t *lo, int32_t *hi,
                uint8_t *writable, uint8_t *safety);

extern "Python+C" {
    void hal_servo_timers_config(uint8_t tccra, uint16_t icr);
    void hal_servo_timers_start(uint8_t tccrb);
    void hal_servo_ocr(uint8_t ch, uint16_t ocr);
    void hal_wheel_start(uint8_t side);
    void hal_wheel_direction(uint8_t side, uint8_t reverse);
    void hal_wheel_ocr(uint8_t side, uint8_t ocr);
    uint8_t hal_uart_send(const uint8_t *data, uint8_t n);
    uint32_t hal_uart_rx_lost(void);
    void hal_sonar_trigger(uint8_t index);
    uint8_t hal_boot_param(uint16_t id, int32_t *value);
}
"""

# The module's own C: the headers the declarations above come from.
SOURCE_PREAMBLE = """
#include "hal.h"
#include "fw/params.h"
#include "fw/program.h"
#include "protocol/joints.h"
extern uint32_t native_now_us;
void native_encoder_edges(uint8_t side, int32_t edges);
void native_usart_rx_bytes(const uint8_t *data, uint32_t n);
uint32_t native_state_size(void);
void native_state_save(uint8_t *dst);
void native_state_load(const uint8_t *src);
"""

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
                   if p.suffix in (".c", ".h", ".inc") and "build" not in p.parts)
    for p in files:
        h.update(str(p.relative_to(firmware_dir)).encode())
        h.update(p.read_bytes())
    h.update(CDEF.encode())
    h.update(SOURCE_PREAMBLE.encode())
    h.update(sys.version.encode())
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """$MOBIGRASP_CACHE_DIR, default ``~/.cache/mobigrasp``: every built C part is kept below."""
    root = os.environ.get("MOBIGRASP_CACHE_DIR")
    return Path(root) if root else Path.home() / ".cache" / "mobigrasp"


def cache_dir() -> Path:
    """Where built modules are kept."""
    return cache_root() / "native"


def load_cached(name: str, target: Path, build, error: type[Exception] = RuntimeError):
    """The extension module ``name`` from the folder ``target`` of the cache, built there first
    by ``build() -> Path`` (the .so) when the folder has none; ``error`` when it cannot load."""
    built = sorted(target.glob(f"{name}*.so")) if target.is_dir() else []
    if not built:
        built = [build()]
    spec = importlib.util.spec_from_file_location(name, built[0])
    if spec is None or spec.loader is None:
        raise error(f"{built[0]}: cannot be loaded as a module")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


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
    module = load_cached(name, target, lambda: _build(firmware_dir, name, target),
                         NativeBuildError)
    _loaded[digest] = module
    return module


def _build(firmware_dir: Path, name: str, target: Path) -> Path:
    try:
        import cffi
    except ImportError as exc:  # pragma: no cover - cffi is a dependency
        raise NativeBuildError("the native backend needs cffi (pip install cffi)") from exc
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        ffi = cffi.FFI()
        ffi.cdef(CDEF)
        ffi.set_source(
            name, SOURCE_PREAMBLE,
            sources=[str(p) for p in sources(firmware_dir)],
            include_dirs=[str(firmware_dir)],
            define_macros=[("FW_NATIVE", "1")],
            extra_compile_args=["-O2", "-Wall", "-Wno-unused-function"],
        )
        try:
            so = Path(ffi.compile(tmpdir=str(tmp), verbose=False))
        except Exception as exc:
            raise NativeBuildError(f"building the native firmware failed: {exc}") from exc
        keep = tmp / "out"
        keep.mkdir()
        shutil.move(str(so), keep / so.name)
        try:
            os.rename(keep, target)
        except OSError:
            if not target.is_dir():  # not a concurrent build that won the race
                raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return sorted(target.glob(f"{name}*.so"))[0]
