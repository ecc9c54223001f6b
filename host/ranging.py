"""Monocular ranging of papers 000 and 002 from a known physical size, in integers.

Paper 002 (§4): the two black rings of the red cylinder are D = 14.5 mm apart; with their pixel
spacing d_pixel, ``D_OC = D f / d_pixel`` (f = 350 px, (u0, v0) = (160, 120)), and

    X_OC = D_OC cos θv sin θh,  Y_OC = D_OC cos θv cos θh,  Z_OC = D_OC sin θv,
    θv = θ1 + θ2 + θ3 - arctan((v0 - v_c) / f),  θh = θ4 + arctan((u0 - u_c) / f)

in 002's joint numbering (θ1..θ3 pitches, θ4 waist). Mapped to docs/conventions.md: 002's
θ1 + θ2 + θ3 is our α (camera pitch, positive up) and its θ4 our θ5 (waist, positive to the
right, X right). With those signs a target above the image centre (v_c < v0) is *higher*, so
θv = α + arctan((v0 - v_c)/f), and a target right of centre is further right, so
θh = θ5 + arctan((u_c - u0)/f). The printed signs hold for a pitch measured downwards and an X
to the left; :func:`range_002` implements the equations with our signs.

The printed equations treat D_OC as the distance along the ray and d_pixel as if the rings
were seen square on. :func:`locate_ring_pair` does the exact pinhole geometry for a vertical
segment (the rings' front points) seen by a camera pitched by α: the segment's image length is
``f D (cos α + y_n sin α) / Z_c`` (y_n = (v - v0)/f, Z_c the depth), which gives the point's
forward, right and up offsets; then the cylinder radius (from the red width at the same scale:
R = width D / (2 d_pixel)) moves the point from the front surface to the axis. This is the
one the 002 task uses at run time (host/task/method002.py ``object_position``: the point plus
the camera point of eq. (3) is the grasp's target, X_OR = X_OC + X_CR ...) and the accuracy
harness judges; ``range_002`` is the paper's printed form, for comparison only (not used at
run time).

Paper 000: ``Y_oc = L f / (d_p + d_rp)`` (L = 109 mm) and ``D_is = D_act f / d_pixel``
(D_act = 47.3 mm), f = 611 px: :func:`range_from_size_mm`.

All positions are in millimetres, camera-centred, in platform-aligned axes (X right, Y forward,
Z up) after the waist yaw, unless a name says otherwise; pixel quantities are Q4.
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts

D_RING_UM = 14_500  # 002 §5: D = 1.45 cm between the rings
F_PX_002 = 350
U0_PX = 160
V0_PX = 120
T_D_PX = 45  # 002 §5: d_pixel > T_d means the object is within reach


def range_from_size_mm(size_um: int, f_px: int, size_px_q4: int) -> int:
    """Pinhole range ``size * f / size_px`` in mm (size in µm, pixel size in Q4); >0 required."""
    if size_px_q4 <= 0:
        raise ValueError(f"range_from_size_mm: pixel size must be > 0, got {size_px_q4} (Q4)")
    return fp.div_round(int(size_um) * int(f_px) * 16, int(size_px_q4) * 1000)


@dataclass(frozen=True)
class Range002:
    """002 §4 literally: D_OC, the two deviation angles, and (X_OC, Y_OC, Z_OC) in mm."""

    d_oc_mm: int
    theta_v_mrad: int
    theta_h_mrad: int
    x_oc_mm: int
    y_oc_mm: int
    z_oc_mm: int


def range_002(d_pixel_q4: int, u_c_q4: int, v_c_q4: int, alpha_mrad: int, theta5_mrad: int,
              f_px: int = F_PX_002, u0_px: int = U0_PX, v0_px: int = V0_PX,
              d_um: int = D_RING_UM) -> Range002:
    """The ranging equations of 002 §4 with conventions.md signs (module docstring)."""
    d_oc = range_from_size_mm(d_um, f_px, d_pixel_q4)
    th_v = int(alpha_mrad) + fp.atan2_mrad(16 * v0_px - v_c_q4, 16 * f_px)
    th_h = int(theta5_mrad) + fp.atan2_mrad(u_c_q4 - 16 * u0_px, 16 * f_px)
    cv, sv = fp.cos_q12(th_v), fp.sin_q12(th_v)
    ch, sh = fp.cos_q12(th_h), fp.sin_q12(th_h)
    horiz = fp.mul_q12(d_oc, cv)
    return Range002(d_oc, th_v, th_h, fp.mul_q12(horiz, sh), fp.mul_q12(horiz, ch),
                    fp.mul_q12(d_oc, sv))


def range_002_ops() -> OpCounts:
    """Cost of :func:`range_002`: one division, two atan2, four sin/cos, a few Q12 products."""
    return (OpCounts(divs=1, muls32=2, alu=10) + fp.atan2_ops().scaled(2)
            + fp.sin_ops().scaled(4) + fp.mul_q12_ops(4))


@dataclass(frozen=True)
class RingPairFix:
    """Exact position of the cylinder axis point between the rings, camera-centred, mm.

    ``x_mm`` right, ``y_mm`` forward, ``z_mm`` up (after the waist yaw θ5); ``dist_mm`` the
    straight-line distance; ``bearing_mrad`` the horizontal bearing from the platform heading
    (right positive); ``radius_mm`` the cylinder radius estimated from the image.
    """

    x_mm: int
    y_mm: int
    z_mm: int
    dist_mm: int
    bearing_mrad: int
    radius_mm: int


def locate_ring_pair(d_pixel_q4: int, u_q4: int, v_q4: int, width_q4: int, alpha_mrad: int,
                     theta5_mrad: int, f_px: int = F_PX_002, u0_px: int = U0_PX,
                     v0_px: int = V0_PX, d_um: int = D_RING_UM) -> RingPairFix:
    """Axis point between the two rings from their spacing, the image column/row of their
    midpoint and the red width (all Q4 px), camera pitch α and waist yaw θ5 (mrad)."""
    if d_pixel_q4 <= 0:
        raise ValueError(f"locate_ring_pair: d_pixel must be > 0, got {d_pixel_q4} (Q4)")
    fq = 16 * int(f_px)  # f in Q4 px
    xn = int(u_q4) - 16 * int(u0_px)  # x_n * f, Q4
    yn = int(v_q4) - 16 * int(v0_px)
    sa, ca = fp.sincos_q12(alpha_mrad)
    # ray (xn, yn, f) in platform axes before yaw, Q16 (Q12 x Q4): right, forward, up
    fwd = ca * fq + sa * yn
    up = sa * fq - ca * yn
    right = xn << 12
    # depth Z_c = f D fwd / (f d_pixel) in µm; the point is Z_c * ray / f
    zc_um = fp.div_round(int(d_um) * fwd, int(d_pixel_q4) << 12)  # (D * fwd/f) / (d/f)
    x_um = fp.div_round(zc_um * right, fq << 12)
    y_um = fp.div_round(zc_um * fwd, fq << 12)
    z_um = fp.div_round(zc_um * up, fq << 12)
    # front surface -> axis: radius from the width at the rings' scale, along the horizontal ray
    radius_um = fp.div_round(int(width_q4) * int(d_um), 2 * int(d_pixel_q4))
    h_um = fp.isqrt(x_um * x_um + y_um * y_um)
    if h_um > 0:
        x_um += fp.div_round(x_um * radius_um, h_um)
        y_um += fp.div_round(y_um * radius_um, h_um)
    # waist yaw: θ5 > 0 turns the camera to the right (clockwise seen from above)
    s5, c5 = fp.sincos_q12(theta5_mrad)
    xr = fp.mul_q12(x_um, c5) + fp.mul_q12(y_um, s5)
    yr = fp.mul_q12(y_um, c5) - fp.mul_q12(x_um, s5)
    dist_um = fp.isqrt(xr * xr + yr * yr + z_um * z_um)
    return RingPairFix(fp.div_round(xr, 1000), fp.div_round(yr, 1000), fp.div_round(z_um, 1000),
                       fp.div_round(dist_um, 1000), fp.atan2_mrad(xr, yr),
                       fp.div_round(radius_um, 1000))


# One 64-bit division as the ARM9 does it: libgcc's __aeabi_ldivmod, a shift-subtract loop
# (ARMv4T has no CLZ), about 320 cycles on the ring pair's operands (docs/budget.md)
_DIV64_OPS = OpCounts(alu=260, branches=20)


def locate_ring_pair_ops() -> OpCounts:
    """Cost of :func:`locate_ring_pair` as hostc/ranging.c runs it: twelve 64-bit divisions
    (and the one inside atan2 of 64-bit operands), 64-bit products as 32-bit MUL pairs, two
    digit-by-digit roots of ~45-bit numbers on register pairs (twice a 32-bit round)."""
    return (_DIV64_OPS.scaled(13) + OpCounts(muls32=24, alu=60) + fp.sin_ops().scaled(4)
            + fp.atan2_ops() + fp.isqrt_ops(1 << 44).scaled(4))


def platform_bearing_mrad(cam_x_mm: int, cam_y_mm: int, bearing_mrad: int, dist_mm: int) -> int:
    """Bearing of a target from the platform origin (right positive) given its bearing and
    horizontal distance seen from the camera at (cam_x_mm, cam_y_mm) of the platform (eq. (3) of
    000): the parallax correction for 002's e when the camera is ahead of the waist."""
    s, c = fp.sincos_q12(bearing_mrad)
    x_um = 1000 * int(cam_x_mm) + fp.mul_q12(1000 * int(dist_mm), s)  # µm keep short ranges
    y_um = 1000 * int(cam_y_mm) + fp.mul_q12(1000 * int(dist_mm), c)
    return fp.atan2_mrad(x_um, y_um)
