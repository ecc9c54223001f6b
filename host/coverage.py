"""Stations of the wandering search: concentric rings that cover a disc once.

000 §II: the robot "firstly wanders in the environment to search object"; the paper does not
say how. Here the base, after its look-around at the start (Fig. 5 cycles, host/search.py),
drives rings around the start through the stations returned below, the camera sweeping a
strip of half-width ``view_mm`` (the detector's reliable range) on both sides. The look-around
sees the disc of view_mm; each ring lies as far out as the strip allows, a_k = a_(k-1) + 2
view_mm (a_0 = 0), the last at radius - view_mm: the inner edge of every ring's strip meets the
outer edge of the one inside it, the last ring's strip reaches ``radius_mm``, and no ring is
driven twice. The first ring's strip reaches 3 view_mm less its sides' sagitta (3.2 m for the
default 4.5 m disc; rings evenly spaced, a_k = k (radius - view_mm) / n, reached 2.8 m, and
targets 2.9 m away were seen on the second ring only, after the 150 s time limit of v2 scenes,
docs/cosim.md). A ring starts and closes on the start's x axis (its heading at the start); the
step out to the next ring is radial. (An Archimedean spiral of pitch
2 view_mm covers the same disc with ~20 % more path for 4.5 m: its last turn overshoots.)
A ring is a polygon of sides about ``chord_mm`` whose sides touch its circle at their
midpoints (its vertices chord^2 / (8 a) outside it, which the spacing allows for). The last
ring may lie ``edge_mm`` inside the disc's edge instead of ``view_mm``: a last ring that sweeps
its outer side alone sees farther that way (000: 0.9 m; docs/task.md "000: the last ring
nearer the edge"); the rings inside it are laid as before. Integer mm and mrad in the frame of
the start (x ahead, y left).
"""

from __future__ import annotations

from mobigrasp.host.control.path_follow import wrap_mrad
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, isqrt, sin_q12

TWO_PI_MRAD = 6283


def ring_stations(radius_mm: int, view_mm: int, chord_mm: int,
                  edge_mm: int = 0) -> list[tuple[int, int]]:
    """Stations (x_mm, y_mm) from the start (excluded) round the rings out to ``radius_mm``;
    the last ring at ``radius_mm - edge_mm`` (``edge_mm`` 0: ``view_mm``)."""
    if view_mm <= 0 or chord_mm <= 0 or radius_mm < 0 or edge_mm < 0:
        raise ValueError(f"view and chord must be > 0, radius and edge >= 0, got {view_mm}, "
                         f"{chord_mm}, {radius_mm}, {edge_mm}")
    if radius_mm <= view_mm:
        return []  # the look-around at the start sees it all
    span = radius_mm - (edge_mm or view_mm)
    rings: list[tuple[int, int, int]] = []
    inner = 0  # the ring inside's radius (its sides' midpoints: its reach outward); the start
    while inner < span:
        a = min(span, inner + 2 * view_mm)
        ring = _ring(a, chord_mm)
        # vertices outside the circle by the sagitta: a ring's reach inward is from them
        while ring[0] - inner > 2 * view_mm:
            a -= ring[0] - inner - 2 * view_mm
            ring = _ring(a, chord_mm)
        if a <= inner:
            raise ValueError(f"rings of {chord_mm} mm sides cannot cover {radius_mm} mm with "
                             f"a {view_mm} mm strip")
        rings.append(ring)
        inner = a
    stations: list[tuple[int, int]] = []
    for a_v, _, m in rings:
        for j in range(m + 1):
            phi = TWO_PI_MRAD * j // m
            stations.append((a_v * cos_q12(phi) >> 12, a_v * sin_q12(phi) >> 12))
    return stations


def _ring(a: int, chord_mm: int) -> tuple[int, int, int]:
    """(vertex radius, radius of the sides' midpoints, sides) of the polygon whose sides
    (at most about ``chord_mm``) touch the circle of radius ``a`` at their midpoints."""
    m = max(6, -(-TWO_PI_MRAD * a // (1000 * chord_mm)))
    a_v = a * 4096 // cos_q12(TWO_PI_MRAD // (2 * m))
    return a_v, a, m


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
