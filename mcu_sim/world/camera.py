"""The eye-in-hand camera (the OV9653 of paper 000): pinhole projection and a 320x240 RGB renderer.

Camera axes are OpenCV's: ``R_wc`` has as columns the camera x (right), y (down) and z (optical
axis, forward) expressed in world coordinates (x east, y north, z up); a world point ``p`` is at
``R_wc.T @ (p - cam_pos_w)`` in the camera. Pixel centres are at integer coordinates, so the
pinhole image ``u = f x / z + u0`` of a point lies in pixel ``round(u)``.

Rendering (painter's order): background, the seeded textured ground (a homography warp of one
repeating tile), then objects far to near by the distance of their reference point, each as
back-face-culled solid faces (``cv2.fillConvexPoly`` at 1/16 px) and planar textures (marker
card, guidance board) warped by homography from a mip level that matches their projected size.
Every polygon is clipped against the near plane in camera coordinates first, so nothing behind
the camera is drawn. Then motion blur, brightness and Gaussian noise, all seeded.

Speed (same picture): the ground and sky are drawn by camera_ground.py, only below the horizon;
a texture opaque over the whole frame (a marker card seen from close above) makes everything
painted before it unnecessary, so it is not painted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world.camera_ground import draw_ground as _draw_ground
from mobigrasp.mcu_sim.world.camera_ground import put_rgb as _put_rgb
from mobigrasp.mcu_sim.world.camera_ground import sky_frame as _sky_frame
from mobigrasp.mcu_sim.world.camera_linalg import columns3, svd_values
from mobigrasp.mcu_sim.world.camera_scene import (
    Item,
    Scene,
    Target,
    inside_colour,
    solids_of_scene,
)

Z_NEAR_M = 0.01
_NOISE_BANK_SIZE = 1 << 21
_LIGHT = np.array([0.35, 0.25, 0.90]) / np.linalg.norm([0.35, 0.25, 0.90])


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics in pixels (000: f = 611; 002: f = 350, (u0, v0) = (160, 120))."""

    f_px: float = 611.0
    u0_px: float = 160.0
    v0_px: float = 120.0
    width: int = 320
    height: int = 240

    def __post_init__(self) -> None:
        if not (math.isfinite(self.f_px) and self.f_px > 0):
            raise ValueError(f"Intrinsics.f_px must be a positive number, got {self.f_px!r}")
        for name in ("u0_px", "v0_px"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"Intrinsics.{name} must be finite, got {getattr(self, name)!r}")
        for name in ("width", "height"):
            v = getattr(self, name)
            if not isinstance(v, int) or not 8 <= v <= 4096:
                raise ValueError(f"Intrinsics.{name} must be an int in [8, 4096], got {v!r}")

    def matrix(self) -> np.ndarray:
        """The 3x3 camera matrix K."""
        return np.array([[self.f_px, 0.0, self.u0_px], [0.0, self.f_px, self.v0_px],
                         [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class CameraOptions:
    """Image degradations, applied after rendering in this order: blur, brightness, noise.

    noise_std: Gaussian noise sigma in grey levels, per channel; blur_px: length of a linear
    motion-blur streak in pixels along ``blur_angle_rad`` (0 = image x); brightness: gain.
    """

    noise_std: float = 0.0
    blur_px: float = 0.0
    brightness: float = 1.0
    blur_angle_rad: float = 0.0

    def __post_init__(self) -> None:
        checks = (
            ("noise_std", 0.0, 128.0), ("blur_px", 0.0, 40.0), ("brightness", 0.01, 10.0),
            ("blur_angle_rad", -10.0, 10.0),
        )
        for name, lo, hi in checks:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not lo <= v <= hi:
                raise ValueError(f"CameraOptions.{name} must be a number in [{lo}, {hi}], "
                                 f"got {v!r}")


@dataclass(frozen=True)
class Frame:
    """A rendered frame: same fields as ``host.hal.CameraFrame`` (seq, capture_us, rgb)."""

    seq: int
    capture_us: int
    rgb: np.ndarray


def look_rotation(yaw_rad: float, pitch_rad: float, roll_rad: float = 0.0) -> np.ndarray:
    """R_wc of a camera whose optical axis has heading ``yaw_rad`` (CCW from +x) and elevation
    ``pitch_rad`` (negative looks down, -pi/2 straight down), rolled by ``roll_rad`` about it
    (positive turns the camera x axis towards its y axis, i.e. the image content CCW)."""
    cy, sy, cp, sp = math.cos(yaw_rad), math.sin(yaw_rad), math.cos(pitch_rad), math.sin(pitch_rad)
    fwd = np.array([cp * cy, cp * sy, sp])
    right = np.array([sy, -cy, 0.0])
    down = np.cross(fwd, right)
    cr, sr = math.cos(roll_rad), math.sin(roll_rad)
    x, y = cr * right + sr * down, -sr * right + cr * down
    return np.column_stack([x, y, fwd])


_EYE3 = np.eye(3)
_ORTHO_TOL = 1e-6 + 1e-5 * np.abs(_EYE3)  # atol + rtol * |b| of np.allclose(a, b, atol=1e-6)


def _cross3(a, b) -> np.ndarray:
    """np.cross of two 3-vectors, the same products and differences without its overhead."""
    a0, a1, a2 = (float(x) for x in a)
    b0, b1, b2 = (float(x) for x in b)
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _check_pose(cam_pos_w, R_wc) -> tuple[np.ndarray, np.ndarray]:
    # ndarray methods and plain floats instead of np.all / np.abs / np.linalg.det, whose
    # dispatch costs more than the 3x3 work (called once per rendered frame)
    c = np.asarray(cam_pos_w, dtype=float)
    R = np.asarray(R_wc, dtype=float)
    if c.shape != (3,) or not np.isfinite(c).all():
        raise ValueError(f"cam_pos_w must be 3 finite numbers, got shape {c.shape}")
    if R.shape != (3, 3) or not np.isfinite(R).all():
        raise ValueError(f"R_wc must be a finite 3x3 matrix, got shape {R.shape}")
    # np.allclose(R.T @ R, I, atol=1e-6) without its per-call overhead: the same comparison
    if not (abs(R.T @ R - _EYE3) <= _ORTHO_TOL).all():
        raise ValueError("R_wc must be a proper rotation (orthonormal, det +1)")
    # orthonormal to 1e-6, so the determinant is +-1 to within ~1e-5: its sign by the cofactor
    # expansion is the sign np.linalg.det gives
    (a, b, cc), (d, e, f), (g, h, i) = R.tolist()
    if a * (e * i - f * h) - b * (d * i - f * g) + cc * (d * h - e * g) < 0:
        raise ValueError("R_wc must be a proper rotation (orthonormal, det +1)")
    return c, R


def project(points_w: np.ndarray, cam_pos_w, R_wc, intr: Intrinsics) -> np.ndarray:
    """Pinhole image (N, 2) of world points (N, 3); NaN for points not in front of the camera."""
    p = np.asarray(points_w, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points_w must have shape (N, 3), got {p.shape}")
    c, R = _check_pose(cam_pos_w, R_wc)
    pc = (p - c) @ R
    out = np.full((len(p), 2), np.nan)
    ok = pc[:, 2] > Z_NEAR_M
    out[ok, 0] = intr.f_px * pc[ok, 0] / pc[ok, 2] + intr.u0_px
    out[ok, 1] = intr.f_px * pc[ok, 1] / pc[ok, 2] + intr.v0_px
    return out


def _clip_near(pc: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman clip of a convex polygon (K, 3) in camera coords to z >= Z_NEAR_M."""
    inside = pc[:, 2] >= Z_NEAR_M
    if inside.all():
        return pc
    if not inside.any():
        return pc[:0]
    out = []
    k = len(pc)
    for i in range(k):
        a, b = pc[i], pc[(i + 1) % k]
        ia, ib = a[2] >= Z_NEAR_M, b[2] >= Z_NEAR_M
        if ia:
            out.append(a)
        if ia != ib:
            t = (Z_NEAR_M - a[2]) / (b[2] - a[2])
            out.append(a + t * (b - a))
    return np.array(out)


def _face_colours(it: Item) -> list[tuple[int, ...]]:
    """Shaded colour of every face of ``it`` (a fixed light, so computed once per item, and
    once per (normal, colour) across items: a moving target's items are rebuilt each frame)."""
    if it.colours is None:
        it.colours = [_shade(normal.tobytes(), normal, rgb) for _, normal, rgb in it.faces]
    return it.colours


_SHADES: dict = {}


def _shade(key: bytes, normal: np.ndarray, rgb) -> tuple[int, ...]:
    colour = _SHADES.get((key, tuple(rgb)))
    if colour is None:
        shade = 0.62 + 0.38 * max(0.0, float(np.dot(normal, _LIGHT)))
        colour = tuple(int(round(min(255.0, ch * shade))) for ch in rgb)
        if len(_SHADES) < 4096:
            _SHADES[(key, tuple(rgb))] = colour
    return colour


class _Painter:
    """Draws into one image for one camera pose."""

    def __init__(self, img: np.ndarray, c: np.ndarray, R: np.ndarray, intr: Intrinsics) -> None:
        self.img, self.c, self.R, self.intr = img, c, R, intr
        self.K = intr.matrix()
        self.light = _LIGHT
        # the principal point as an array: what numpy makes of the list [u0, v0] in every sum
        self._uv0 = np.array([intr.u0_px, intr.v0_px])

    def _image_poly(self, poly_w: np.ndarray) -> tuple[np.ndarray | None, bool]:
        pc_all = (poly_w - self.c) @ self.R
        pc = _clip_near(pc_all)  # pc_all itself when nothing is clipped
        if len(pc) < 3:
            return None, False
        uv = pc[:, :2] / pc[:, 2:3] * self.intr.f_px + self._uv0
        return uv, pc is not pc_all and (len(pc) != len(pc_all) or not np.array_equal(pc, pc_all))

    def item_faces(self, it: Item) -> None:
        """The solid convex faces of one item, culled when seen from behind, shaded by a fixed
        light. Vertices are moved to the camera frame and rounded to 1/16 px in one product
        each; only faces that cross the near plane are clipped and rounded on their own."""
        if it.verts is None:
            return
        visible = np.einsum("ij,ij->i", it.normals, self.c - it.centres) > 0.0
        if not visible.any():
            return
        vc = (it.verts - self.c) @ self.R
        z = vc[:, 2]
        if z.min() >= Z_NEAR_M:
            # all in front: no division by zero, nothing invalid, so no errstate (entering one
            # costs as much as the arithmetic here); an item wholly beside the frame paints
            # nothing
            uv = vc[:, :2] / z[:, None] * self.intr.f_px + self._uv0
            lo, hi = uv.min(axis=0), uv.max(axis=0)
            if (hi[0] < -2.0 or hi[1] < -2.0 or lo[0] > self.intr.width + 1.0
                    or lo[1] > self.intr.height + 1.0):
                return
            pts_all = np.clip(np.rint(uv * 16), -(2**26), 2**26).astype(np.int32)
        else:
            with np.errstate(divide="ignore", invalid="ignore"):
                uv = vc[:, :2] / z[:, None] * self.intr.f_px + self._uv0
                # rows behind the camera turn into garbage here; no face that uses them takes
                # them
                pts_all = np.clip(np.rint(uv * 16), -(2**26), 2**26).astype(np.int32)
        starts = it.starts.tolist()  # plain ints and floats: cheaper in the per-face loop
        z_min = np.minimum.reduceat(z, it.starts[:-1]).tolist()
        colours = _face_colours(it)
        fill, img = cv2.fillConvexPoly, self.img
        for i in np.flatnonzero(visible).tolist():
            a, b = starts[i], starts[i + 1]
            if z_min[i] >= Z_NEAR_M:
                pts = pts_all[a:b]
            else:
                pc = _clip_near(vc[a:b])
                if len(pc) < 3:
                    continue
                fuv = pc[:, :2] / pc[:, 2:3] * self.intr.f_px + self._uv0
                pts = np.clip(np.rint(fuv * 16), -(2**26), 2**26).astype(np.int32)
            # (lineType, shift) passed by position: keyword parsing costs ~1 us of a ~5 us call,
            # and an item has tens of faces
            fill(img, pts, colours[i], cv2.LINE_8, 4)

    def texture(self, tex: mk.PlanarTexture, origin_w, ex_w, ey_w, plan=None) -> None:
        """Warp an RGBA planar texture (plane through origin_w spanned by unit ex_w, ey_w);
        ``plan``: what :meth:`texture_plan` returned for the same arguments, if at hand."""
        if plan is None:
            plan = self.texture_plan(tex, origin_w, ex_w, ey_w)
        if plan is not None:
            self._draw_texture(*plan)

    def texture_plan(self, tex: mk.PlanarTexture, origin_w, ex_w, ey_w) -> tuple | None:
        """Where and how :meth:`texture` warps: (src level, homography, patch box, supersampling,
        image polygon, clipped, level), or None when nothing of it is in view."""
        normal, corners = _texture_geom(tex, origin_w, ex_w, ey_w)
        if float(np.dot(normal, self.c - origin_w)) <= 0.0:
            return None  # seen from behind
        uv, clipped = self._image_poly(corners)
        if uv is None:
            return None
        H_, W_ = self.img.shape[:2]
        lo, hi = np.floor(uv.min(axis=0)), np.ceil(uv.max(axis=0)) + 1
        x0, y0 = max(0, int(lo[0])), max(0, int(lo[1]))
        x1, y1 = min(W_, int(hi[0])), min(H_, int(hi[1]))
        if x1 <= x0 or y1 <= y0:
            return None
        pc0 = self.R.T @ (origin_w - self.c)
        M = self.K @ columns3(self.R.T @ ex_w, self.R.T @ ey_w, pc0)
        level, ss = 0, 1
        if len(tex.levels) > 1 and pc0[2] > Z_NEAR_M:
            # Anisotropic filtering, as a GPU does it: the singular values of the texel -> pixel
            # Jacobian at the patch centre give the least and most minified directions; we
            # supersample by their ratio (<= 4) and take the mip level that makes the most
            # minified direction about one texel per subpixel, so thin print seen obliquely
            # neither aliases nor smears sideways.
            ss, level = _filtering(_texel_jacobian(M, tex.texel_m), len(tex.levels),
                                   (x1 - x0) * (y1 - y0))
        src = tex.levels[level]
        H = _patch_matrix(ss, x0, y0) @ M @ _texel_matrix(tex.half_m, src.shape[0])
        return src, H, (x0, y0, x1, y1), ss, uv, clipped, level

    def covers_frame(self, tex: mk.PlanarTexture, origin_w, ex_w, ey_w, plan) -> bool:
        """True when the warped texture is opaque (alpha 255) on every pixel of the frame, so
        that whatever was drawn before it is overwritten: the rays through the frame's corners,
        pushed out by a pixel, all meet its plane in front of the camera within the disc about
        its centre where every texel of the level in use (and its neighbours) is opaque."""
        if plan is None or plan[5]:
            return False
        r_safe = _opaque_radius_m(tex, plan[6])
        if r_safe <= 0.0:
            return False
        rays = self.R @ _corner_rays(self.intr)
        normal = _texture_geom(tex, origin_w, ex_w, ey_w)[0]
        denom = normal @ rays
        if not (denom < 0.0).all():  # seen from the front, the plane is ahead along these rays
            return False
        hit = self.c[:, None] + rays * (float(normal @ (origin_w - self.c)) / denom)
        d = hit - np.asarray(origin_w, dtype=float)[:, None]
        r2 = (ex_w @ d) ** 2 + (ey_w @ d) ** 2
        return bool((r2 <= r_safe * r_safe).all())

    def _draw_texture(self, src, H, box, ss, uv, clipped, level, opaque: bool = False) -> None:
        """Warp and paint one texture (``texture_plan``'s plan). ``opaque``: the plan is one
        :meth:`covers_frame` accepted, so every pixel of the frame gets alpha 255: the RGB is
        written straight into the frame, which is what the mask and the (empty) rim below
        would paint."""
        x0, y0, x1, y1 = box
        warped = cv2.warpPerspective(src, H, (ss * (x1 - x0), ss * (y1 - y0)),
                                     flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                                     borderValue=(0, 0, 0, 0))
        if ss > 1:  # exact block mean for an integer factor
            warped = cv2.resize(warped, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA)
        if opaque and not clipped and (x0, y0, x1, y1) == (0, 0) + self.img.shape[1::-1]:
            _put_rgb(self.img, warped, 0, 0)
            return
        roi = self.img[y0:y1, x0:x1]
        mask = None
        if clipped:
            mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
            pts = np.rint((uv - [x0, y0]) * 16).clip(-(2**26), 2**26).astype(np.int32)
            cv2.fillConvexPoly(mask, pts, 1, lineType=cv2.LINE_8, shift=4)
        # split the channels with OpenCV (contiguous outputs: a strided numpy view would be
        # copied by OpenCV on every call, and numpy comparisons on the whole patch cost more)
        rgb = cv2.cvtColor(warped, cv2.COLOR_RGBA2RGB)
        alpha = cv2.extractChannel(warped, 3)
        if mask is not None:
            alpha *= mask
        # opaque texels are copied, transparent ones skipped; only the anti-aliased rim blends
        # (cv2.copyTo writes into the ROI view in place)
        cv2.copyTo(rgb, cv2.compare(alpha, 255, cv2.CMP_EQ), roi)
        rim_xy = cv2.findNonZero(cv2.inRange(alpha, 1, 254))  # None when there is no rim
        if rim_xy is not None:
            _blend_rim(self.img, x0, y0, rgb, alpha, rim_xy.reshape(-1, 2))


def _blend_rim(img: np.ndarray, x0: int, y0: int, rgb: np.ndarray, alpha: np.ndarray,
               rim_xy: np.ndarray) -> None:
    """Blend the patch pixels at ``rim_xy`` ((x, y) in the patch at column x0, row y0 of the
    frame) over the frame: ``(under * (255 - a) + over * a + 127) // 255`` per channel, exact
    in uint16 (at most 255 * 255 + 127). The pixels are gathered by flat index and the channels
    computed as one flat run (per-pixel fancy indexing and a (n, 1) by (n, 3) broadcast cost
    ~2x more); each rim pixel is written once, so the order does not matter."""
    dst = img.view()
    dst.shape = (-1, 3)  # (an assignment to shape never copies: the writes reach the frame)
    rx, ry = rim_xy[:, 0], rim_xy[:, 1]
    w = rgb.shape[1]
    flat = ry * w + rx  # in the patch
    at = flat + (ry * (img.shape[1] - w) + (y0 * img.shape[1] + x0))  # in the frame
    a = alpha.reshape(-1).take(flat).astype(np.uint16).repeat(3)
    mixed = dst.take(at, axis=0).reshape(-1).astype(np.uint16)
    mixed *= 255 - a
    over = rgb.reshape(-1, 3).take(flat, axis=0).reshape(-1).astype(np.uint16)
    over *= a
    mixed += over
    mixed += 127
    mixed //= 255
    dst[at] = mixed.astype(np.uint8).reshape(-1, 3)


_TEX_GEOM: dict = {}


def _texture_geom(tex: mk.PlanarTexture, origin_w, ex_w, ey_w) -> tuple[np.ndarray, np.ndarray]:
    """(unit normal, the four corners (4, 3)) of a placed texture: they do not depend on the
    camera, so they are computed once per placement. Cached on the identity of the arrays (an
    item of a scene is cached and read-only, so a standing target hits; a moving target's new
    arrays miss and are computed as before); the entry holds them, so no id is reused."""
    key = (id(tex), id(origin_w), id(ex_w), id(ey_w))
    hit = _TEX_GEOM.get(key)
    if (hit is not None and hit[0] is tex and hit[1] is origin_w and hit[2] is ex_w
            and hit[3] is ey_w):
        return hit[4], hit[5]
    h = tex.half_m
    normal = _cross3(ex_w, ey_w)
    corners = np.array([origin_w + sx * h * ex_w + sy * h * ey_w
                        for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    if len(_TEX_GEOM) >= 256:
        _TEX_GEOM.clear()
    _TEX_GEOM[key] = (tex, origin_w, ex_w, ey_w, normal, corners)
    return normal, corners


def _texel_jacobian(M: np.ndarray, texel_m: float) -> np.ndarray:
    """The Jacobian of the homography ``M`` (texture plane metres -> pixels) at the plane's
    origin, times ``texel_m`` (pixels per level-0 texel). Column k is
    ``(M[:2, k] * w - M[:2, 2] * M[2, k]) / w**2 * texel_m`` with ``w = M[2, 2]``, written in
    plain floats: the same IEEE products, differences and quotients element by element
    (``w**2`` is pow() for a float as for a numpy scalar), without ~10 small array calls."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, w) = M.tolist()
    w2 = w**2
    return np.array([[(m00 * w - m02 * m20) / w2 * texel_m, (m01 * w - m02 * m21) / w2 * texel_m],
                     [(m10 * w - m12 * m20) / w2 * texel_m, (m11 * w - m12 * m21) / w2 * texel_m]])


def _filtering(J: np.ndarray, n_levels: int, box_px: int) -> tuple[int, int]:
    """(supersampling factor, mip level) for the texel Jacobian ``J`` (see texture_plan)."""
    sv = svd_values(J)  # pixels per level-0 texel
    r_min, r_max = 1.0 / max(sv[0], 1e-9), 1.0 / max(sv[1], 1e-9)  # texels per pixel
    ss = int(min(4, max(1, round(r_max / max(r_min, 1e-9)))))
    ss = min(ss, max(1, int(math.sqrt(250_000 / max(1, box_px)))))
    level = math.floor(math.log2(max(1.0, r_max / ss)))
    return ss, int(min(n_levels - 1, max(0, level)))


@lru_cache(maxsize=512)
def _patch_matrix(ss: int, x0: int, y0: int) -> np.ndarray:
    """Frame pixel -> supersampled patch pixel for a patch at (x0, y0): the product
    ``_supersample_matrix(ss) @ T`` (T the translation by -x0, -y0), kept per (ss, x0, y0)
    (read-only): a patch box recurs from frame to frame, and the product is the same numbers."""
    T = np.array([[1.0, 0, -x0], [0, 1.0, -y0], [0, 0, 1.0]])
    P = _supersample_matrix(ss) @ T
    P.flags.writeable = False
    return P


@lru_cache(maxsize=64)
def _texel_matrix(half_m: float, n: int) -> np.ndarray:
    """Texel (col, row) of an n x n level -> metres in the texture plane (read-only)."""
    t = 2.0 * half_m / n
    A = np.array([[t, 0.0, t / 2 - half_m], [0.0, -t, half_m - t / 2], [0, 0, 1.0]])
    A.flags.writeable = False
    return A


@lru_cache(maxsize=8)
def _supersample_matrix(ss: int) -> np.ndarray:
    """Patch pixel -> supersampled pixel centre for the factor ``ss`` (read-only)."""
    S = np.array([[ss, 0.0, (ss - 1) / 2], [0.0, ss, (ss - 1) / 2], [0, 0, 1.0]])
    S.flags.writeable = False
    return S


@lru_cache(maxsize=8)
def _corner_rays(intr: Intrinsics) -> np.ndarray:
    """Camera-frame rays (3, 4) through the frame's corners pushed out by a pixel (read-only)."""
    f, u0, v0 = intr.f_px, intr.u0_px, intr.v0_px
    W, H = intr.width, intr.height
    rays = np.array([[(-1.0 - u0) / f, (W - u0) / f, (W - u0) / f, (-1.0 - u0) / f],
                     [(-1.0 - v0) / f, (-1.0 - v0) / f, (H - v0) / f, (H - v0) / f],
                     [1.0, 1.0, 1.0, 1.0]])
    rays.flags.writeable = False
    return rays


_OPAQUE_R: dict = {}


def _opaque_radius_m(tex: mk.PlanarTexture, level: int) -> float:
    """Radius about the texture's centre within which a bilinear sample of mip ``level`` reads
    opaque texels only: the nearest centre of a not fully opaque texel (or the texture's edge),
    less two texels of the level. Cached per texture object and level."""
    key = (id(tex), level)
    hit = _OPAQUE_R.get(key)
    if hit is not None and hit[0] is tex:
        return hit[1]
    lev = tex.levels[level]
    n = lev.shape[0]
    t = 2.0 * tex.half_m / n
    centres = (np.arange(n) + 0.5) * t - tex.half_m
    bad = lev[..., 3] < 255
    r_bad = tex.half_m
    if bad.any():
        rows, cols = np.nonzero(bad)
        r_bad = min(r_bad, float(np.sqrt(centres[cols] ** 2 + centres[rows] ** 2).min()))
    r = r_bad - 2.0 * t
    if len(_OPAQUE_R) < 256:
        _OPAQUE_R[key] = (tex, r)
    return r


@lru_cache(maxsize=1)
def _noise_bank() -> np.ndarray:
    """One fixed bank of N(0, 1) samples; each frame reads a seeded random window of it, which
    is ~10x cheaper than drawing 230k normals per frame and still deterministic per seed."""
    return np.random.default_rng(0x0E9653).standard_normal(
        _NOISE_BANK_SIZE + 320 * 240 * 3, dtype=np.float32)


@lru_cache(maxsize=32)
def _motion_kernel(length_px: float, angle_rad: float) -> np.ndarray:
    r = int(math.ceil(length_px / 2))
    k = np.zeros((2 * r + 1, 2 * r + 1), np.float32)
    n = max(8, int(length_px * 16))
    for s in np.linspace(-length_px / 2, length_px / 2, n):
        x, y = r + s * math.cos(angle_rad), r + s * math.sin(angle_rad)
        ix, iy = int(math.floor(x)), int(math.floor(y))
        fx, fy = x - ix, y - iy
        for dx, dy, w in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)),
                          (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
            if 0 <= ix + dx <= 2 * r and 0 <= iy + dy <= 2 * r:
                k[iy + dy, ix + dx] += w
    return k / k.sum()


def apply_options(img: np.ndarray, options: CameraOptions, rng: np.random.Generator) -> np.ndarray:
    """Motion blur, brightness gain and Gaussian noise (in that order), seeded by ``rng``."""
    out = img
    if options.blur_px > 0.0:
        out = cv2.filter2D(out, -1, _motion_kernel(options.blur_px, options.blur_angle_rad),
                           borderType=cv2.BORDER_REPLICATE)
    if options.brightness != 1.0:
        out = cv2.convertScaleAbs(out, alpha=float(options.brightness))
    if options.noise_std > 0.0:
        bank = _noise_bank()
        n = out.size
        if n > len(bank) // 2:  # frames larger than 320x240x3 draw their own samples
            bank = rng.standard_normal(2 * n, dtype=np.float32)
        start = int(rng.integers(0, len(bank) - n))
        f = out.astype(np.float32)
        f += bank[start:start + n].reshape(out.shape) * np.float32(options.noise_std)
        np.clip(f, 0.0, 255.0, out=f)
        out = np.rint(f).astype(np.uint8)
    return out


def render(scene: Scene, cam_pos_w, R_wc, intr: Intrinsics = Intrinsics(),
           options: CameraOptions = CameraOptions(), rng: np.random.Generator | None = None,
           t_us: int = 0) -> np.ndarray:
    """Render what the camera at ``cam_pos_w`` with axes ``R_wc`` sees: uint8 (H, W, 3) RGB.

    Deterministic: the same arguments and the same ``rng`` state give byte-identical frames.
    With ``rng=None`` the noise is seeded from ``(scene.seed, t_us)``.
    """
    img = render_clean(scene, cam_pos_w, R_wc, intr)
    if rng is None:
        rng = np.random.default_rng([scene.seed & 0xFFFFFFFF, int(t_us) & 0xFFFFFFFFFFFF])
    return apply_options(img, options, rng)


def render_clean(scene: Scene, cam_pos_w, R_wc, intr: Intrinsics = Intrinsics()) -> np.ndarray:
    """The frame :func:`render` draws before :func:`apply_options` (a function of the scene,
    the pose and the intrinsics only: a caller may reuse it while they stay the same)."""
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be a Scene, got {type(scene).__name__}")
    c, R = _check_pose(cam_pos_w, R_wc)
    img = np.empty((intr.height, intr.width, 3), np.uint8)
    inside = inside_colour(scene.target, c)
    if inside is not None:  # the camera inside the object: its surface fills the view
        img[...] = inside
        return img
    p = _Painter(img, c, R, intr)
    items = solids_of_scene(scene)
    if len(items) > 1:
        items = sorted(items, key=lambda it: -_norm(it.ref_w - c))
    # painter's order: the ground, then per item its faces and its textures; a texture opaque
    # over the whole frame hides everything painted before it, which is then not painted
    ops: list = [None]
    for it in items:
        ops.append(it)
        ops.extend((args, p.texture_plan(*args)) for args in it.textures)
    start = 0
    for i in range(len(ops) - 1, 0, -1):
        if isinstance(ops[i], tuple) and p.covers_frame(*ops[i][0], ops[i][1]):
            start = i
            break
    for op in ops[start:]:
        if op is None:
            if c[2] > 0.0:
                _draw_ground(p, scene.seed)
            else:
                np.copyto(img, _sky_frame(intr.width, intr.height))
        elif isinstance(op, Item):
            p.item_faces(op)
        elif op[1] is not None:
            # the first op painted is the one that covers the frame, when one does
            p._draw_texture(*op[1], opaque=start > 0 and op is ops[start])
    return img


def _norm(v: np.ndarray) -> float:
    """``float(np.linalg.norm(v))`` of a float64 vector: the square root of ``v.dot(v)``, as
    np.linalg.norm computes it, without its dispatch."""
    return math.sqrt(v.dot(v))


def render_frame(seq: int, capture_us: int, scene: Scene, cam_pos_w, R_wc,
                 intr: Intrinsics = Intrinsics(), options: CameraOptions = CameraOptions(),
                 rng: np.random.Generator | None = None) -> Frame:
    """:func:`render` stamped with its simulated capture time, ready for the host's Camera."""
    return Frame(int(seq), int(capture_us),
                 render(scene, cam_pos_w, R_wc, intr, options, rng, t_us=capture_us))


__all__ = ["Intrinsics", "CameraOptions", "Frame", "Scene", "Target", "look_rotation",
           "project", "render", "render_clean", "render_frame", "apply_options", "Z_NEAR_M"]
