"""The C kernels of ``hostc/`` built with the host's C compiler through cffi, as numpy calls.

The build goes to a cache folder keyed by the hash of the sources (``$XDG_CACHE_HOME`` or
``~/.cache``, ``mobigrasp/hostc-<hash>``), so it is made once per change of the C. Each wrapper
takes and returns the arrays of its Python counterpart in host/vision/.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np

HOSTC = Path(__file__).resolve().parents[1] / "hostc"
SOURCES = ("grey.c", "dark.c", "label.c")
CDEF = """
void mg_grey(const uint8_t *rgb, uint8_t *grey, int32_t n_px);
int32_t mg_dark_mask(const uint8_t *grey, uint8_t *mask, int32_t n_px, uint32_t *hist);
int32_t mg_label(const uint8_t *mask, int32_t w, int32_t h, int32_t *labels,
                 int32_t *block_lab, int32_t *parent, int32_t *stats);
"""


def source_hash() -> str:
    """Hash of the C sources and header (the cache key of both builds)."""
    h = hashlib.sha256()
    for name in ("kernels.h", *SOURCES):
        h.update(name.encode() + b"\0" + (HOSTC / name).read_bytes())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    """Where the builds are kept."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "mobigrasp"


@lru_cache(maxsize=1)
def lib():
    """The compiled module's ``(ffi, lib)``, built on first use."""
    from cffi import FFI

    name = f"_mg_hostc_{source_hash()}"
    out = cache_dir() / f"hostc-{source_hash()}"
    out.mkdir(parents=True, exist_ok=True)
    built = list(out.glob(f"{name}*.so"))
    if not built:
        ffi = FFI()
        ffi.cdef(CDEF)
        ffi.set_source(name, '#include "kernels.h"', sources=[str(HOSTC / s) for s in SOURCES],
                       include_dirs=[str(HOSTC)], extra_compile_args=["-std=c99", "-O2"])
        built = [Path(ffi.compile(tmpdir=str(out), verbose=False))]
    spec = importlib.util.spec_from_file_location(name, built[0])
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod.ffi, mod.lib


def _ptr(ffi, a: np.ndarray, ctype: str):
    return ffi.cast(ctype, ffi.from_buffer(a))


def grey(rgb: np.ndarray) -> np.ndarray:
    """(H, W) uint8 grey of an (H, W, 3) uint8 frame."""
    ffi, c = lib()
    rgb = np.ascontiguousarray(rgb)
    out = np.empty(rgb.shape[:2], np.uint8)
    c.mg_grey(_ptr(ffi, rgb, "uint8_t *"), _ptr(ffi, out, "uint8_t *"), out.size)
    return out


def dark_mask(grey_img: np.ndarray) -> tuple[np.ndarray, int]:
    """(mask 0/1 uint8, threshold) of a grey image."""
    ffi, c = lib()
    g = np.ascontiguousarray(grey_img)
    mask = np.empty_like(g)
    hist = np.empty(256, np.uint32)
    t = c.mg_dark_mask(_ptr(ffi, g, "uint8_t *"), _ptr(ffi, mask, "uint8_t *"), g.size,
                       _ptr(ffi, hist, "uint32_t *"))
    return mask, int(t)


def label_scratch_words(h: int, w: int) -> tuple[int, int]:
    """Words of the block-label and parent scratch buffers of :func:`label` (stats: 5 per
    parent entry)."""
    blocks = ((w + 1) // 2) * ((h + 1) // 2)
    return blocks, blocks + 1


def label(mask: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """(n_labels, labels int32, stats int32 (n, 5)) of a 0/1 mask, 8-connected."""
    ffi, c = lib()
    m = np.ascontiguousarray(mask)
    h, w = m.shape
    nb, npar = label_scratch_words(h, w)
    labels = np.empty((h, w), np.int32)
    block_lab = np.empty(nb, np.int32)
    parent = np.empty(npar, np.int32)
    stats = np.empty((npar, 5), np.int32)
    n = c.mg_label(_ptr(ffi, m, "uint8_t *"), w, h, _ptr(ffi, labels, "int32_t *"),
                   _ptr(ffi, block_lab, "int32_t *"), _ptr(ffi, parent, "int32_t *"),
                   _ptr(ffi, stats, "int32_t *"))
    return int(n), labels, stats[:n].copy()
