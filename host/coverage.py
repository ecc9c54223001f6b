"""Stations of the wandering search: an Archimedean spiral that covers a disc once.

000 §II: the robot "firstly wanders in the environment to search object"; the paper does not
say how. Here the base, after its look-around at the start (Fig. 5 cycles, host/search.py),
drives a counter-clockwise Archimedean spiral r = r0 + pitch * phi / 2 pi through the
stations returned below, the camera sweeping a strip of half-width ``view_mm`` (the
detector's reliable range) on both sides. With pitch <= 2 view_mm the strips of successive
turns touch, the look-around covers the disc of radius view_mm at the start, and the first
leg (straight ahead, out to r0 = min(pitch, radius - view_mm)) joins the two: no ground is left between passes and no
ground is driven over twice. The spiral ends after the turn whose inner edge
(r - view_mm) has passed ``radius_mm`` all around, so the whole disc of that radius is seen.
Stations are ``chord_mm`` apart along the spiral (the polygon lies within
chord^2 / (8 r) of the curve). Integer mm and mrad in the frame of the start (x ahead, y
left).
"""

from __future__ import annotations

from mobigrasp.host.control.path_follow import wrap_mrad
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, isqrt, sin_q12

TWO_PI_MRAD = 6283


def spiral_stations(pitch_mm: int, radius_mm: int, view_mm: int,
                    chord_mm: int) -> list[tuple[int, int]]:
    """Stations (x_mm, y_mm) from the start (excluded) out to the disc of ``radius_mm``."""
    if pitch_mm <= 0 or view_mm <= 0 or chord_mm <= 0 or radius_mm < 0:
        raise ValueError(f"pitch, view and chord must be > 0 and radius >= 0, got {pitch_mm}, "
                         f"{view_mm}, {chord_mm}, {radius_mm}")
    if pitch_mm > 2 * view_mm:
        raise ValueError(f"pitch_mm {pitch_mm} leaves a gap between the strips of half-width "
                         f"view_mm {view_mm}")
    if radius_mm <= view_mm:
        return []  # the look-around at the start sees it all
    r0 = min(pitch_mm, radius_mm - view_mm)  # a small disc: one turn at its edge's inner strip
    # the turn that starts at phi_last sees beyond radius_mm all around once it is done
    phi_last = max(0, (radius_mm - view_mm - r0) * TWO_PI_MRAD // pitch_mm)
    phi_end = phi_last + TWO_PI_MRAD
    stations: list[tuple[int, int]] = []
    phi = 0
    while True:
        r = r0 + pitch_mm * phi // TWO_PI_MRAD
        stations.append((r * cos_q12(phi) >> 12, r * sin_q12(phi) >> 12))
        if phi >= phi_end:
            return stations
        phi = min(phi_end, phi + max(1, chord_mm * 1000 // r))


def leg_to(pose: tuple[int, int, int], station: tuple[int, int]) -> tuple[int, int]:
    """(turn_mrad, drive_mm) from ``pose`` (x_mm, y_mm, heading_mrad) to ``station``: the
    turn in [-pi, pi), left positive."""
    dx, dy = station[0] - pose[0], station[1] - pose[1]
    return wrap_mrad(atan2_mrad(dy, dx) - pose[2]), isqrt(dx * dx + dy * dy)


def to_odometry(origin: tuple[int, int, int], xy: tuple[int, int]) -> tuple[int, int]:
    """A point of the start's frame in odometry, the start being ``origin`` (x, y, heading)."""
    c, s = cos_q12(origin[2]), sin_q12(origin[2])
    return (origin[0] + ((xy[0] * c - xy[1] * s) >> 12),
            origin[1] + ((xy[0] * s + xy[1] * c) >> 12))
