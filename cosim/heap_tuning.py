"""Keep freed heap memory in the process: glibc's malloc settings for a simulation run.

Both processes of a run allocate and free frame-sized arrays many times a second: the rendered
320x240 RGB frame (230 kB) and its copies, the host's copy out of the frame ring, grey images,
masks and label maps in the detectors. glibc serves a block above its mmap threshold (128 kB at
start, raised only as such blocks are freed) with a fresh ``mmap`` and returns it with
``munmap``, and gives the top of the heap back to the kernel when more than 128 kB of it is free,
so the pages of those arrays were faulted in again, zeroed by the kernel, frame after frame.
With the thresholds below they stay in the heap and are reused: less wall time per run
(docs/cosim.md, "Measured", *malloc*); the trace is the same (malloc never decides anything
modelled). The cost is up to ~160 MB of
freed memory a process may keep.

Where the C library has no ``mallopt`` (not glibc) nothing is changed.
"""

from __future__ import annotations

import ctypes
from typing import Any

# mallopt parameters (glibc malloc.h) and the values a run uses
M_TRIM_THRESHOLD = -1
M_TOP_PAD = -2
M_MMAP_THRESHOLD = -3
RUN_SETTINGS = {
    M_MMAP_THRESHOLD: 8 << 20,  # blocks below 8 MiB come from the heap (a frame is 230 kB)
    M_TRIM_THRESHOLD: 128 << 20,  # free memory at the heap's top is kept up to 128 MiB
    M_TOP_PAD: 32 << 20,  # the heap grows by 32 MiB at a time
}


def _libc() -> Any:
    try:
        return ctypes.CDLL(None)
    except OSError:
        return None


def keep_freed_memory(libc: Any = None) -> dict[int, int]:
    """Apply :data:`RUN_SETTINGS` with ``mallopt``; returns the settings glibc accepted (empty
    where there is no ``mallopt``). Idempotent; call it once the process has started."""
    libc = _libc() if libc is None else libc
    mallopt = getattr(libc, "mallopt", None) if libc is not None else None
    if mallopt is None:
        return {}
    done = {}
    for param, value in RUN_SETTINGS.items():
        if mallopt(ctypes.c_int(param), ctypes.c_int(value)) == 1:  # 1: accepted, 0: refused
            done[param] = value
    return done
