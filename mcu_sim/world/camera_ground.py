"""The floor and the sky of a camera frame (mcu_sim/world/camera.py paints the rest on top).

With the camera above the floor every ray that points downwards meets the floor in front of the
camera, so the floor is exactly the half-plane of the image below the horizon line; rays within
0.004 rad of the horizon (floor > ~100 m away) are painted as sky. The floor is one seeded tile
repeated (markers.ground_texture), warped by homography: near rows from a 3 x 3 mosaic of the
tile around the camera's tile (OpenCV's fast path), far rows remapped at wrapped float64 texel
coordinates (OpenCV's BORDER_WRAP goes pixel by pixel).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any, Protocol

import cv2
import numpy as np

from mobigrasp.mcu_sim.world import camera_linalg as la
from mobigrasp.mcu_sim.world import markers as mk


class View(Protocol):
    """What the floor needs of the frame being painted (camera.py's painter is one): the image
    ``img`` (H x W x 3 uint8, drawn into), the camera centre ``c`` (world, m), the rotation ``R``
    whose columns are the camera axes in the world, the intrinsic matrix ``K`` and ``intr``
    (``f_px``, ``u0_px``, ``v0_px``, ``width``, ``height``)."""

    img: np.ndarray
    c: np.ndarray
    R: np.ndarray
    K: np.ndarray
    intr: Any


SKY_RGB = (196, 200, 206)

_MOSAIC_TILES = 3  # odd: the floor tile repeated 3 x 3 around the camera's tile


@lru_cache(maxsize=8)
def _ground_mosaic(seed: int) -> np.ndarray:
    """The RGBA floor tile repeated ``_MOSAIC_TILES`` times each way, contiguous (OpenCV's
    perspective warp of four channels is ~2.5x faster than of three)."""
    rgba = mk.ground_texture(seed).levels[0]
    return np.ascontiguousarray(np.tile(rgba, (_MOSAIC_TILES, _MOSAIC_TILES, 1)))


@lru_cache(maxsize=8)
def _ground_wrapped(seed: int) -> np.ndarray:
    """The RGBA floor tile with its first row and column repeated after its last: bilinear
    samples at any coordinate in [0, n] then read inside the array."""
    return np.ascontiguousarray(np.pad(mk.ground_texture(seed).levels[0], ((0, 1), (0, 1), (0, 0)),
                                       mode="wrap"))


@lru_cache(maxsize=8)
def _tile_matrix(t: float, h: float) -> np.ndarray:
    """Tile texel (col, row) -> metres about the tile centre, texel size ``t`` (read-only)."""
    A = np.array([[t, 0.0, t / 2 - h], [0.0, -t, h - t / 2], [0, 0, 1.0]])
    A.flags.writeable = False
    return A


@lru_cache(maxsize=8)
def _mosaic_shift(kn: int) -> np.ndarray:
    """Mosaic texel (col, row) -> tile texel: the camera's tile starts ``kn`` texels in
    (read-only)."""
    S = np.array([[1.0, 0.0, -kn], [0.0, 1.0, -kn], [0.0, 0.0, 1.0]])
    S.flags.writeable = False
    return S


@lru_cache(maxsize=4)
def sky_frame(width: int, height: int) -> np.ndarray:
    """A frame of sky colour (read-only: copied into frames)."""
    img = np.empty((height, width, 3), np.uint8)
    img[...] = SKY_RGB
    img.flags.writeable = False
    return img


@lru_cache(maxsize=4)
def _pixel_grid(width: int, height: int) -> np.ndarray:
    """(height, width, 2) float64 pixel coordinates (x, y)."""
    u, v = np.meshgrid(np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64))
    return np.stack([u, v], axis=-1)


def _horizon_split(p: View) -> tuple[list, list]:
    """The sky polygon (rays within 0.004 rad of the horizon or above) and the floor polygon
    (the rest) of the frame, each as a list of image points, clipped to the frame +- 1 px."""
    f, u0, v0 = p.intr.f_px, p.intr.u0_px, p.intr.v0_px
    # ray_z(u, v) = a u + b v + c; sky where ray_z >= -0.004
    a, b = p.R[2, 0] / f, p.R[2, 1] / f
    c0 = p.R[2, 2] - p.R[2, 0] * u0 / f - p.R[2, 1] * v0 / f + 0.004
    W, H = p.intr.width, p.intr.height
    rect = np.array([[-1.0, -1.0], [W + 1.0, -1.0], [W + 1.0, H + 1.0], [-1.0, H + 1.0]])
    # (plain floats for the tests and the crossing's ratio: the same IEEE operations as on
    # numpy scalars, without their per-operation cost)
    side = (rect @ np.array([a, b]) + c0).tolist()
    sky, floor = [], []
    for i in range(4):
        j = (i + 1) % 4
        (sky if side[i] >= 0 else floor).append(rect[i])
        if (side[i] >= 0) != (side[j] >= 0):
            q = rect[i] + side[i] / (side[i] - side[j]) * (rect[j] - rect[i])
            sky.append(q)
            floor.append(q)
    return sky, floor


def _near_rows_from(Hi: np.ndarray, x0: int, x1: int, y0: int, y1: int, lo: float, hi: float,
                    sign: float) -> int:
    """First row ``y`` of [y0, y1] such that every pixel of rows y..y1-1, columns x0..x1-1 reads
    the floor at tile-texel coordinates within [lo, hi] (``Hi``: pixel -> tile texel). A row
    maps to a segment of the floor, so its two end pixels decide; ``sign`` is the sign of the
    homogeneous coordinate on the floor (the other sign is behind the camera)."""
    # the box maps to a convex quadrilateral when its corners are all on the floor: when they
    # are also all within [lo, hi] so is every pixel (the usual case: the camera looks down)
    (a, b, c), (d, e, f), (g, h, i) = Hi.tolist()
    for x, y in ((x0, y0), (x1 - 1, y0), (x0, y1 - 1), (x1 - 1, y1 - 1)):
        w = g * x + h * y + i
        if not w * sign > 1e-12:
            break
        tx, ty = (a * x + b * y + c) / w, (d * x + e * y + f) / w
        if not (lo <= tx <= hi and lo <= ty <= hi):
            break
    else:
        return y0
    m = y1 - y0
    ends = np.empty((3, 2 * m))
    ends[0, :m], ends[0, m:] = x0, x1 - 1
    ends[1, :m] = ends[1, m:] = np.arange(y0, y1)
    ends[2] = 1.0
    q = Hi @ ends
    with np.errstate(divide="ignore", invalid="ignore"):
        txy = q[:2] / q[2]
        ok = (q[2] * sign > 1e-12) & np.all((txy >= lo) & (txy <= hi), axis=0)
    bad = np.flatnonzero(~(ok[:m] & ok[m:]))
    return y0 + int(bad[-1]) + 1 if len(bad) else y0


def draw_ground(p: View, seed: int) -> None:
    """Draw the repeating floor tile over the floor part of the frame, then paint the sky above
    the horizon.

    With the camera above the floor every ray that points downwards meets the floor in front of
    the camera, so the floor is exactly the half-plane of the image below the horizon line; the
    rays within 0.004 rad of the horizon (floor > ~100 m away) are painted as sky. Only the
    bounding box of the floor is drawn. Its rows whose floor lies within a mosaic of tiles
    around the camera's tile are one perspective warp of the mosaic; the farther rows (towards
    the horizon: OpenCV wraps coordinates pixel by pixel on its slow path, which cost ~20x
    more) are a remap of the tile at texel coordinates computed in float64 and wrapped here.
    """
    tex = mk.ground_texture(seed)
    t, h = tex.texel_m, tex.half_m
    n = tex.levels[0].shape[0]
    k = _MOSAIC_TILES // 2
    origin = np.array([round(p.c[0] / (2 * h)) * 2 * h, round(p.c[1] / (2 * h)) * 2 * h, 0.0])
    M = p.K @ la.columns3(p.R.T[:, 0], p.R.T[:, 1], p.R.T @ (origin - p.c))
    H_tile = M @ _tile_matrix(t, h)  # tile texel -> pixel
    sky, floor = _horizon_split(p)
    W, H = p.intr.width, p.intr.height
    x0 = y0 = 0
    x1, y1 = W, H
    if sky:
        if len(floor) < 3:
            np.copyto(p.img, sky_frame(W, H))
            return
        fl = np.array(floor)
        x0, y0 = max(0, int(np.floor(fl[:, 0].min()))), max(0, int(np.floor(fl[:, 1].min())))
        x1, y1 = min(W, int(np.ceil(fl[:, 0].max())) + 1), min(H, int(np.ceil(fl[:, 1].max())) + 1)
        if x1 - x0 < W or y1 - y0 < H:
            np.copyto(p.img, sky_frame(W, H))  # (a broadcast of the colour costs 20x more)
    if x1 > x0 and y1 > y0:
        Hi = la.inv(H_tile)
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2  # a floor pixel: the frame or the floor's middle
        if sky:
            cx, cy = fl.mean(axis=0)
        sign = 1.0 if Hi[2, 0] * cx + Hi[2, 1] * cy + Hi[2, 2] > 0 else -1.0
        ys = _near_rows_from(Hi, x0, x1, y0, y1, -k * n + 1.0, (k + 1) * n - 2.0, sign)
        if ys < y1:
            T = np.array([[1.0, 0.0, -x0], [0.0, 1.0, -ys], [0.0, 0.0, 1.0]])
            rgba = cv2.warpPerspective(_ground_mosaic(seed), T @ H_tile @ _mosaic_shift(k * n),
                                       (x1 - x0, y1 - ys),
                                       flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
            put_rgb(p.img, rgba, x0, ys)
        if ys > y0:
            pts = _pixel_grid(W, H)[y0:ys, x0:x1].reshape(-1, 1, 2)
            txy = cv2.perspectiveTransform(pts, Hi)  # 0 where the ray is parallel to the floor
            # wrap into [0, n]: txy -= n * floor(txy / n), the same products in one temporary
            wraps = txy * (1.0 / n)
            np.floor(wraps, out=wraps)
            wraps *= n
            txy -= wraps
            maps = txy.astype(np.float32).reshape(ys - y0, x1 - x0, 2)
            rgba = cv2.remap(_ground_wrapped(seed), maps, None, cv2.INTER_LINEAR,
                             borderMode=cv2.BORDER_WRAP)
            put_rgb(p.img, rgba, x0, y0)
    if len(sky) >= 3:
        pts = np.rint(np.array(sky) * 16).astype(np.int32)
        cv2.fillConvexPoly(p.img, pts, SKY_RGB, lineType=cv2.LINE_8, shift=4)


def put_rgb(img: np.ndarray, rgba: np.ndarray, x0: int, y0: int) -> None:
    """Write the RGB channels of ``rgba`` into ``img`` at column x0, row y0."""
    roi = img[y0:y0 + rgba.shape[0], x0:x0 + rgba.shape[1]]
    out = cv2.cvtColor(rgba, cv2.COLOR_RGBA2RGB, dst=roi)
    if not np.shares_memory(out, roi):  # OpenCV wrote elsewhere: copy it in
        roi[...] = out
