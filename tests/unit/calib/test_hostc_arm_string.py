"""The board's memcpy, memmove and memset (hostc/arm/string.c) as the ARMv4T ELF runs them under
unicorn, against the machine's C library on random buffers: every alignment of source and
destination, lengths across the word and eight-word steps, overlaps both ways, and the bytes
around the area left as they were. A word-aligned copy costs the timing model about a cycle a
byte, not the byte loop's ~9."""

import ctypes

import numpy as np
import pytest

from mobigrasp.calib import armhost, program

LIBC = ctypes.CDLL(None)
LIBC.memcpy.restype = LIBC.memmove.restype = LIBC.memset.restype = ctypes.c_void_p
LIBC.memcpy.argtypes = LIBC.memmove.argtypes = (ctypes.c_void_p, ctypes.c_void_p,
                                                 ctypes.c_size_t)
LIBC.memset.argtypes = (ctypes.c_void_p, ctypes.c_int, ctypes.c_size_t)
AREA = 512  # bytes of one test area (the emulated one and the host's)
BASE = program.HEAP_BASE + program.IO


@pytest.fixture(scope="module")
def arm9():
    return program.ProgramArm9(program.Elf.read(armhost.build_elf()))


def _cases(seed: int, n_cases: int):
    """(destination offset, source offset, length) with every alignment pair and lengths from
    0 to past several eight-word blocks."""
    rng = np.random.default_rng(seed)
    for k in range(n_cases):
        d_off = 64 + int(rng.integers(0, 8))
        s_off = 64 + int(rng.integers(0, 8)) if k % 2 else d_off + int(rng.integers(-70, 70))
        n = int(rng.integers(0, 40)) if k % 3 == 0 else int(rng.integers(40, 300))
        yield rng, d_off, max(s_off, 0), n


def _run(arm9, fn: str, data: bytes, *args) -> bytes:
    arm9.write(BASE, data)
    arm9.call(fn, *args, timed=False)
    return arm9.read(BASE, AREA)


def _libc_copy(fn, data: bytes, d_off: int, s_off: int, n: int) -> bytes:
    buf = ctypes.create_string_buffer(data, AREA)
    addr = ctypes.addressof(buf)
    fn(addr + d_off, addr + s_off, n)
    return buf.raw


def test_memcpy_and_memmove_equal_the_c_library_on_random_buffers(arm9):
    for rng, d_off, s_off, n in _cases(1, 400):
        data = rng.integers(0, 256, AREA, dtype=np.uint8).tobytes()
        if s_off + n <= AREA and d_off + n <= AREA:
            want = _libc_copy(LIBC.memmove, data, d_off, s_off, n)
            assert _run(arm9, "memmove", data, BASE + d_off, BASE + s_off, n) == want, (
                "memmove", d_off, s_off, n)
        # memcpy: the source in the area's second half, never overlapping
        src = AREA // 2 + (s_off % 8)
        n_cp = min(n, AREA - src, src - d_off)
        if n_cp >= 0:
            want = _libc_copy(LIBC.memcpy, data, d_off, src, n_cp)
            assert _run(arm9, "memcpy", data, BASE + d_off, BASE + src, n_cp) == want, (
                "memcpy", d_off, src, n_cp)


def test_memset_equals_the_c_library_on_random_buffers(arm9):
    rng = np.random.default_rng(2)
    for k in range(300):
        data = rng.integers(0, 256, AREA, dtype=np.uint8).tobytes()
        d_off = 64 + int(rng.integers(0, 8))
        n = int(rng.integers(0, 40)) if k % 3 == 0 else int(rng.integers(40, 300))
        c = int(rng.choice([0, 0xFF, -1, 0x1A5, int(rng.integers(0, 256))]))
        buf = ctypes.create_string_buffer(data, AREA)
        LIBC.memset(ctypes.addressof(buf) + d_off, c, n)
        want = buf.raw
        assert _run(arm9, "memset", data, BASE + d_off, c, n) == want, (d_off, c, n)


def test_a_word_aligned_copy_costs_about_a_cycle_a_byte(arm9):
    n = 4096
    arm9.write(BASE, bytes(range(256)) * (2 * n // 256))
    _, t = arm9.call("memcpy", BASE + n, BASE, n)
    assert arm9.read(BASE + n, n) == arm9.read(BASE, n)
    # a cold cache: the source's 128 line fills (and the stack's) on top
    assert (t.cycles - t.fill_cycles) / n < 1.0 and n // 32 <= t.read_misses <= n // 32 + 2, t
