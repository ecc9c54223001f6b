"""Small float64 linear algebra of the camera, bit for bit what numpy's public calls give.

The renderer decomposes a 2x2 matrix and inverts a 3x3 one per frame; np.linalg.svd and
np.linalg.inv spend ~4x the LAPACK work itself on argument checks and an ``errstate`` context.
These call the same gufuncs (numpy.linalg._umath_linalg) with the same signature, so the
results are the same numbers; anything not finite (a singular or non-finite input) is computed
again by the public function, which raises as it always did. The direct call's floating-point
errors are not reported, so that error path prints no RuntimeWarning of its own first.
"""

from __future__ import annotations

import math

import numpy as np

try:
    from numpy.linalg import _umath_linalg as _LINALG
except ImportError:  # pragma: no cover - a numpy without the module: the public functions
    _LINALG = None


def svd_values(a: np.ndarray) -> list[float]:
    """``np.linalg.svd(a, compute_uv=False).tolist()`` of a float64 matrix."""
    if _LINALG is not None:
        # a non-finite result goes to the public function, which raises: no warning first
        with np.errstate(all="ignore"):
            s = _LINALG.svd(a, signature="d->d").tolist()
        if all(math.isfinite(v) for v in s):
            return s
    return np.linalg.svd(a, compute_uv=False).tolist()


def inv(a: np.ndarray) -> np.ndarray:
    """``np.linalg.inv(a)`` of a float64 matrix."""
    if _LINALG is not None:
        # a non-finite result goes to the public function, which raises: no warning first
        with np.errstate(all="ignore"):
            r = _LINALG.inv(a, signature="d->d")
        if np.isfinite(r).all():
            return r
    return np.linalg.inv(a)


def columns3(a, b, c) -> np.ndarray:
    """``np.column_stack([a, b, c])`` of three 3-vectors: the same C-ordered float64 copy,
    without column_stack's per-call overhead."""
    m = np.empty((3, 3))
    m[:, 0], m[:, 1], m[:, 2] = a, b, c
    return m
