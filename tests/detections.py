"""Typed detector results for task tests: each detector's own result dataclass, with the fields
a test does not care about set to plausible values (host/vision/registry.py names the types)."""

from __future__ import annotations

import math

from mobigrasp.host.vision.double_cross import DoubleCrossResult
from mobigrasp.host.vision.dual_plus import DualPlus
from mobigrasp.host.vision.held_fill import HeldFill
from mobigrasp.host.vision.radial_symbol import RadialSymbol
from mobigrasp.host.vision.red_cylinder import RedCylinderResult, RedRoi
from mobigrasp.host.vision.spoke import Spoke


def radial(u_q4: int, v_q4: int, y_oc_mm: int, diameter_q4: int = 0) -> RadialSymbol:
    return RadialSymbol(u_q4, v_q4, diameter_q4, y_oc_mm, 0, 0)


def dual_plus(u1_q4: int, v1_q4: int, u2_q4: int, v2_q4: int, dist_mm: int,
              d_pixel_q4: int = 0) -> DualPlus:
    return DualPlus(u1_q4, v1_q4, u2_q4, v2_q4, d_pixel_q4, d_pixel_q4, dist_mm, dist_mm, 0,
                    0, 0)


def red_cylinder(u_c_q4: int, v_c_q4: int, d_pixel_q4: int, width_q4: int = 0,
                 ring1_v_q4: int = 0, ring2_v_q4: int = 0,
                 roi: tuple = (0, 0, 0, 0)) -> RedCylinderResult:
    return RedCylinderResult(u_c_q4, v_c_q4, ring1_v_q4, ring2_v_q4, d_pixel_q4, width_q4, roi)


def red_roi(u_c_q4: int, v_c_q4: int, roi: tuple = (150, 100, 20, 40), area_px: int = 600,
            touches_edge: bool = False) -> RedRoi:
    return RedRoi(u_c_q4, v_c_q4, roi, area_px, touches_edge)


def double_cross(um_q4: int, vm_q4: int, d_pixel_q4: int = 0, e_mrad: int = 0
                 ) -> DoubleCrossResult:
    half = d_pixel_q4 // 2
    return DoubleCrossResult(um_q4 - half, vm_q4, um_q4 + half, vm_q4, um_q4, vm_q4, d_pixel_q4,
                             e_mrad, (0, 0))


def spoke(angle_mrad: int, width_q4: int, slope_q12: int = 0) -> Spoke:
    return Spoke(0, 0, (), slope_q12, angle_mrad, width_q4)


def held_fill(rgb: tuple[int, int, int], fill_permille: int = 990) -> HeldFill:
    return HeldFill(rgb, fill_permille)


def oblique_board(dist_mm: float, bearing_rad: float, off_face_rad: float, f_px: int = 350,
                  u0_px: int = 160, v_q4: int = 120 * 16
                  ) -> tuple[DoubleCrossResult, tuple[float, float]]:
    """The double cross as the detector reports a board whose centre is ``dist_mm`` from the
    camera, ``bearing_rad`` right of its axis, turned ``off_face_rad`` (its normal from the line
    of sight, counter-clockwise seen from above): both crosses projected by a float pinhole,
    the marker centre weighted by their depths (host/vision/double_cross.py), in the camera's
    level plane. Also the cylinder's axis (x right, z along the axis, mm): 150 mm before the
    board's face (docs/markers.md)."""
    cx, cz = dist_mm * math.sin(bearing_rad), dist_mm * math.cos(bearing_rad)
    normal = bearing_rad + math.pi + off_face_rad  # of the face, toward the camera's side
    nx, nz = math.sin(normal), math.cos(normal)
    ends = [(cx + s * 65.0 * nz, cz - s * 65.0 * nx) for s in (-1, 1)]  # along the board
    us = sorted(((u0_px + f_px * x / z) * 16, z) for x, z in ends)
    (u1, z1), (u2, z2) = us
    um = (u1 * z1 + u2 * z2) / (z1 + z2)
    d = round(u2) - round(u1)
    return (DoubleCrossResult(round(u1), v_q4, round(u2), v_q4, round(um), v_q4, d, 0, (5, 5)),
            (cx + 150.0 * nx, cz + 150.0 * nz))
