"""Integer RGB -> grey conversion, the first stage of every detector.

Luma with the BT.601 weights scaled by 256 so the sum of weights is exactly 256:
``Y = (77 R + 150 G + 29 B) >> 8``. A white pixel (255, 255, 255) maps to 255 and the
result always fits in ``uint8``, so no clamp is needed. On the ARM920T each pixel costs three
byte loads, three 16-bit multiplies, two adds, one shift and one byte store.
"""

from __future__ import annotations

import cv2
import numpy as np

from mobigrasp.host.budget import OpCounts

W_R = 77
W_G = 150
W_B = 29
SHIFT = 8  # W_R + W_G + W_B == 1 << SHIFT
# (77 R + 150 G + 29 B - 127.5) / 256 per pixel, rounded by OpenCV to the integer luma
# (to_grey), into the first of three output channels (the other two rows are zero)
_GREY_MATRIX = np.array([[W_R / 256, W_G / 256, W_B / 256, -127.5 / 256], [0.0, 0.0, 0.0, 0.0],
                         [0.0, 0.0, 0.0, 0.0]], np.float32)


def grey_cost(height: int, width: int) -> OpCounts:
    """Operation counts of :func:`to_grey` on an ``height x width`` RGB frame."""
    n = int(height) * int(width)
    return OpCounts(
        pixels_read=3 * n,
        pixels_written=n,
        muls=3 * n,
        alu=3 * n + n // 4,  # 2 adds + 1 shift per pixel, loop counter amortised over 4x unroll
        branches=n // 4,
        bytes_streamed=3 * n,
    )


def to_grey(rgb: np.ndarray) -> tuple[np.ndarray, OpCounts]:
    """Integer luma of an ``(H, W, 3)`` uint8 RGB frame.

    Returns the ``(H, W)`` uint8 grey image and the operation counts.
    Raises ``ValueError`` if ``rgb`` is not a non-empty ``(H, W, 3)`` uint8 array.
    """
    if not isinstance(rgb, np.ndarray):
        raise ValueError(f"to_grey: expected a numpy array, got {type(rgb).__name__}")
    if rgb.dtype != np.uint8:
        raise ValueError(f"to_grey: expected dtype uint8, got {rgb.dtype}")
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"to_grey: expected shape (H, W, 3), got {rgb.shape}")
    h, w = rgb.shape[:2]
    if h == 0 or w == 0:
        raise ValueError(f"to_grey: empty frame {rgb.shape}")
    # One OpenCV pass over the interleaved frame, no uint16 temporaries (host speed only). The
    # three 150 kB uint16 planes of the numpy version made the allocator map fresh pages on
    # most frames of a run (~40 page faults per detector call); without page faults numpy was
    # ~10 % faster, but in a replay of paper000-exp1's detector calls this pass takes 13-25 %
    # less CPU overall. cv2.transform computes 77/256 R + 150/256 G + 29/256 B - 127.5/256 in
    # floating point and rounds to nearest. Every term is a multiple of 1/512 below 256, exact
    # in float32 (17 significant bits) in any order of summation, and the sum is
    # (77 R + 150 G + 29 B - 127.5) / 256 = k + (j - 127.5) / 256 with j = (77 R + 150 G + 29 B)
    # mod 256: never a tie, so the rounding gives k = (77 R + 150 G + 29 B) >> 8 exactly
    # (tests/test_vision_002_grey.py checks all 2^24 colours).
    # The matrix has three rows: OpenCV's 8-bit transform has a SIMD fixed-point path (10
    # fractional bits) only for three channels in and out; one output channel goes pixel by
    # pixel in float. The weights and the offset + 1/2 are multiples of 1/1024, so the fixed
    # point is exact too: (308 R + 600 G + 116 B + 2) >> 10 with 4 j + 2 < 1024 is again
    # (77 R + 150 G + 29 B) >> 8 (the test of all 2^24 colours runs this code). Three channels
    # out and the first extracted cost about half the CPU of the one-channel pass.
    grey = cv2.extractChannel(cv2.transform(rgb, _GREY_MATRIX), 0)
    return grey, grey_cost(h, w)


def noise_sigma(grey: np.ndarray, row_step: int = 4) -> tuple[int, OpCounts]:
    """Sensor noise estimate in grey levels (integer, rounded) from the median absolute
    difference of horizontal neighbours on every ``row_step``-th row.

    For Gaussian noise of σ the difference of two pixels has σ√2 and its median absolute value
    is 0.6745 σ√2 = 0.954 σ, so σ ≈ median · 1.048 (here: (median · 67 + 32) >> 6). Smooth
    surfaces and a minority of edges leave the median at the noise. On the board: a 256-bin
    histogram of the differences and a walk to its middle.
    """
    if not isinstance(grey, np.ndarray) or grey.dtype != np.uint8 or grey.ndim != 2:
        raise ValueError("noise_sigma: expected an (H, W) uint8 grey image")
    rows = grey[::row_step]
    if rows.shape[1] < 2:
        return 0, OpCounts()
    d = cv2.absdiff(rows[:, 1:], rows[:, :-1])
    hist = np.bincount(d.ravel(), minlength=256)
    half = (d.size + 1) // 2
    median = int(np.searchsorted(np.cumsum(hist), half))
    n = d.size
    ops = OpCounts(pixels_read=2 * n, alu=3 * n + 512, branches=n // 4 + 256)
    return (median * 67 + 32) >> 6, ops
