"""Drawing geometry of every marker the papers use, in metres, and their texture generators.

Physical numbers from the papers; the rest is our drawing choice, documented in docs/markers.md.

- Paper 000 (§III.A, Fig. 2-3): the object is slender; its top carries a *radial symbol* with
  dual outer rings of outer diameter L = 109 mm and a dual "+" symbol whose centres are
  D_act = 47.3 mm apart. The spoke (arm) width of a "+" is chosen so that the precise-grasp
  window w_T in [20, 40] px (§IV) is met with the camera 0.09-0.18 m above the top (f = 611 px).
- Paper 002 (§2.1, §5): the approach guidance marker is a *double cross*: two crosses with a dark
  centre and four spokes of equal width and equal gap; the object is a red cylinder with two
  black rings D = 14.5 mm apart.

Texture frame: a planar marker texture of ``n`` x ``n`` texels covers the square [-h, h]^2 of its
own plane; column index grows along the marker's +x axis, row index grows along its -y axis (so
the texture reads upright seen from the front/top). Texel ``i`` has its centre at
``-h + (i + 0.5) * h * 2 / n``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from mobigrasp.mcu_sim.world.texture_cache import cached_levels

# ---- paper 000: object and radial symbol on its top ------------------------------------------
L_M = 0.109  # outer diameter of the dual outer rings (000 §IV: L = 109 mm)
D_ACT_M = 0.0473  # distance between the centres of the two "+" (000 §IV: D_act = 47.3 mm)
OBJECT_TOP_Z_M = 0.10  # height of the object's top above the ground
OBJECT_BODY_RADIUS_M = 0.020  # slender body: a 40 mm cylinder fits the 60 mm gripper opening
CARD_RADIUS_M = 0.060  # white top card carrying the symbol (5.5 mm margin outside the rings)
OUTER_RING_R_OUT_M = L_M / 2  # 54.5 mm
OUTER_RING_R_IN_M = 0.0425  # outer ring 12 mm wide: still ~1.5 px tall seen at 1.2 m, 14 deg
INNER_RING_R_OUT_M = 0.0385  # 4 mm white gap between the rings
INNER_RING_R_IN_M = 0.0345  # inner ring 4 mm wide
PLUS_HALF_SPAN_M = 0.0085  # each "+" spans 17 mm tip to tip (2.35 mm clear of the inner ring)
PLUS_ARM_WIDTH_M = 0.006  # spoke width: 20-40 px at 0.18-0.09 m with f = 611 px

# ---- paper 002: red cylinder and double-cross guidance board ----------------------------------
RED_CYL_RADIUS_M = 0.025
RED_CYL_HEIGHT_M = 0.12
RING_SPACING_M = 0.0145  # 002 §5: D = 1.45 cm between the two black rings (centre to centre)
RING_BAND_M = 0.003  # width of each black ring band
RING_MID_Z_M = 0.060  # the rings sit symmetrically about this height
CROSS_RADIUS_M = 0.050  # radius of one cross (spoke length from the centre)
CROSS_CENTRE_RADIUS_M = 0.008  # dark centre disc of a cross (002 step 1: "centre is darker")
CROSS_SPACING_M = 0.130  # distance between the two cross centres (horizontal on the board)
BOARD_WIDTH_M = 0.30
BOARD_HEIGHT_M = 0.14
BOARD_BOTTOM_Z_M = 0.16  # above the cylinder top (0.12 m) so the cylinder never hides it
BOARD_BEHIND_M = 0.15  # board centre this far behind the cylinder axis (against heading)
BOARD_CENTRE_Z_M = BOARD_BOTTOM_Z_M + BOARD_HEIGHT_M / 2

RED_RGB = (200, 30, 30)
BLACK_RGB = (20, 20, 20)
WHITE_RGB = (235, 235, 230)
BODY_RGB = (170, 130, 90)

_SUPERSAMPLE = 3


@dataclass(frozen=True)
class PlanarTexture:
    """An RGBA texture covering [-half_m, half_m]^2 of a plane, with its mip pyramid."""

    half_m: float
    levels: tuple[np.ndarray, ...]  # uint8 (n, n, 4), level k has n / 2**k texels a side

    @property
    def texel_m(self) -> float:
        """Edge length of a level-0 texel in metres."""
        return 2.0 * self.half_m / self.levels[0].shape[0]


def _coverage(n: int, half_m: float, inside) -> np.ndarray:
    """Anti-aliased coverage in [0, 1] of ``inside(x, y)`` on the n x n texel grid."""
    s = _SUPERSAMPLE
    step = 2.0 * half_m / (n * s)
    c = -half_m + (np.arange(n * s) + 0.5) * step
    x = c[None, :]
    y = -c[:, None]  # rows grow along -y
    cov = inside(x, y).astype(np.float32)
    return cov.reshape(n, s, n, s).mean(axis=(1, 3))


def _rgba(cov_dark: np.ndarray, alpha: np.ndarray, dark=BLACK_RGB, light=WHITE_RGB) -> np.ndarray:
    out = np.empty(cov_dark.shape + (4,), np.uint8)
    for k in range(3):
        out[..., k] = np.rint(light[k] + (dark[k] - light[k]) * cov_dark)
    out[..., 3] = np.rint(255 * alpha)
    return out


def _pyramid(tex: np.ndarray, min_size: int = 8) -> tuple[np.ndarray, ...]:
    levels = [tex]
    while levels[-1].shape[0] // 2 >= min_size:
        t = levels[-1].astype(np.uint16)
        n = t.shape[0] // 2
        t = t[: 2 * n, : 2 * n].reshape(n, 2, n, 2, 4).sum(axis=(1, 3))
        levels.append(((t + 2) // 4).astype(np.uint8))
    return tuple(levels)


def plus_inside(x, y, cx: float, cy: float, rot_rad: float = 0.0):
    """True inside a "+" of half span PLUS_HALF_SPAN_M and arm width PLUS_ARM_WIDTH_M."""
    c, s = np.cos(rot_rad), np.sin(rot_rad)
    dx, dy = x - cx, y - cy
    a, b = c * dx + s * dy, -s * dx + c * dy
    w = PLUS_ARM_WIDTH_M / 2
    h = PLUS_HALF_SPAN_M
    return ((np.abs(a) <= h) & (np.abs(b) <= w)) | ((np.abs(b) <= h) & (np.abs(a) <= w))


def plus_centres_m() -> tuple[tuple[float, float], tuple[float, float]]:
    """Centres of the two "+" in the object's top frame (x along the object's heading)."""
    return (D_ACT_M / 2, 0.0), (-D_ACT_M / 2, 0.0)


def radial_symbol_inside(x, y):
    """Dark part of the 000 top symbol: dual outer rings plus the dual "+"."""
    r = np.hypot(x, y)
    rings = ((r <= OUTER_RING_R_OUT_M) & (r >= OUTER_RING_R_IN_M)) | (
        (r <= INNER_RING_R_OUT_M) & (r >= INNER_RING_R_IN_M)
    )
    (x1, y1), (x2, y2) = plus_centres_m()
    return rings | plus_inside(x, y, x1, y1) | plus_inside(x, y, x2, y2)


@lru_cache(maxsize=4)
def radial_symbol_texture(n: int = 512) -> PlanarTexture:
    """Top card of the 000 object: white disc of radius CARD_RADIUS_M with the symbol
    (generated once, then read from the texture cache: mcu_sim/world/texture_cache.py)."""
    half = CARD_RADIUS_M

    def build():
        dark = _coverage(n, half, radial_symbol_inside)
        alpha = _coverage(n, half, lambda x, y: np.hypot(x, y) <= CARD_RADIUS_M)
        return _pyramid(_rgba(dark, alpha))

    return PlanarTexture(half, cached_levels(__file__, "radial_symbol", (n,), build))


def cross_inside(x, y, cx: float, cy: float):
    """One 002 cross: four dark 45-degree spokes (equal width and gap) and a dark centre disc."""
    dx, dy = x - cx, y - cy
    r = np.hypot(dx, dy)
    ang = np.mod(np.arctan2(dy, dx) + np.pi / 8, np.pi / 2)  # spokes centred on 0, 90, 180, 270
    spoke = (ang < np.pi / 4) & (r <= CROSS_RADIUS_M)
    return spoke | (r <= CROSS_CENTRE_RADIUS_M)


def cross_centres_m() -> tuple[tuple[float, float], tuple[float, float]]:
    """Centres of the two crosses on the board (x to the board's right seen from the front)."""
    return (-CROSS_SPACING_M / 2, 0.0), (CROSS_SPACING_M / 2, 0.0)


@lru_cache(maxsize=4)
def double_cross_texture(n: int = 512) -> PlanarTexture:
    """Front face of the 002 guidance board: white rectangle with the two crosses."""
    half = BOARD_WIDTH_M / 2
    (x1, y1), (x2, y2) = cross_centres_m()

    def build():
        dark = _coverage(n, half,
                         lambda x, y: cross_inside(x, y, x1, y1) | cross_inside(x, y, x2, y2))
        alpha = _coverage(n, half,
                          lambda x, y: (np.abs(x) <= half) & (np.abs(y) <= BOARD_HEIGHT_M / 2))
        return _pyramid(_rgba(dark, alpha))

    return PlanarTexture(half, cached_levels(__file__, "double_cross", (n,), build))


def red_cylinder_bands() -> tuple[tuple[float, float, tuple[int, int, int]], ...]:
    """Colour bands of the red cylinder's side from bottom to top: (z0_m, z1_m, rgb)."""
    z_lo = RING_MID_Z_M - RING_SPACING_M / 2
    z_hi = RING_MID_Z_M + RING_SPACING_M / 2
    b = RING_BAND_M / 2
    return (
        (0.0, z_lo - b, RED_RGB),
        (z_lo - b, z_lo + b, BLACK_RGB),
        (z_lo + b, z_hi - b, RED_RGB),
        (z_hi - b, z_hi + b, BLACK_RGB),
        (z_hi + b, RED_CYL_HEIGHT_M, RED_RGB),
    )


@lru_cache(maxsize=8)
def ground_texture(seed: int, n: int = 256, tile_m: float = 2.048) -> PlanarTexture:
    """Seeded low-contrast floor texture (one tile, repeated): smooth grey-brown blotches.

    Blotches are >= 5 cm so that minification far away does not alias into marker-like detail.
    """
    rng = np.random.default_rng(seed)
    coarse = rng.normal(0.0, 1.0, (16, 16)).astype(np.float32)
    # periodic upsampling by FFT keeps the tile seamless under BORDER_WRAP
    spec = np.fft.rfft2(coarse)
    big = np.zeros((n, n // 2 + 1), np.complex64)
    big[:8, :9] = spec[:8, :9]
    big[-8:, :9] = spec[-8:, :9]
    field = np.fft.irfft2(big, s=(n, n))
    field = field / (np.abs(field).max() + 1e-9)
    fine = rng.normal(0.0, 1.0, (n, n)).astype(np.float32)
    base = np.array([150.0, 142.0, 128.0], np.float32)
    tex = np.empty((n, n, 4), np.uint8)
    for k in range(3):
        tex[..., k] = np.clip(base[k] + 22.0 * field + 4.0 * fine, 0, 255).astype(np.uint8)
    tex[..., 3] = 255
    return PlanarTexture(tile_m / 2, (tex,))
