"""How the task moves the base: poses, the close approach, turning in place, path followers.

- :func:`close_in` is the close approach of 000 (vision-based approaching adjustment, §III.B):
  integer proportional law driving until the object is ``grasp_r_mm`` ahead of the waist axis
  and straight ahead; facing the object first, since turning in place swings the waist sideways.
- :func:`path_follower` wraps a planned Bezier curve in host.control.path_follow's integer
  :class:`PathFollower` (eq. (8) feed-forward plus Kanayama feedback); the planners themselves
  are called by the methods that use them (method000.py: eq. (9), method001.py: eq. (17)).

Wheel speeds are (left, right) mm/s, positive forward; counter-clockwise turns have right > left.
"""

from __future__ import annotations

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control.path_follow import PathFollower, Trajectory, wheel_speeds
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, div_round, isqrt, sin_q12
from mobigrasp.host.odometry import Pose


def wrap_mrad(a: int) -> int:
    """An angle wrapped to [-pi, pi) mrad."""
    return (a + 3142) % 6283 - 3142


def make_pose(x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int) -> Pose:
    """An odometry Pose from the task's inputs (mm, mrad, mm/s)."""
    return Pose(int(x_mm) * 1000, int(y_mm) * 1000, int(heading_mrad), int(v_mmps), 0)


def close_in(obj_platform_q4: tuple[int, int], grasp_r_mm: int, tol_mm: int,
             bearing_tol_mrad: int, vmax_mmps: int) -> tuple[tuple[int, int], bool, dict]:
    """Close approach toward an object at platform (X_r, Y_r) Q4 mm: (wheels, done, detail)."""
    xr, yr = obj_platform_q4
    bearing = atan2_mrad(xr, yr)  # right positive, as theta5
    dist = isqrt(xr * xr + yr * yr) // 16
    err = dist - grasp_r_mm
    detail = {"dist_mm": dist, "bearing_mrad": bearing, "err_mm": err}
    if abs(err) <= tol_mm and abs(bearing) <= bearing_tol_mrad:
        return (0, 0), True, detail
    v = max(-vmax_mmps, min(vmax_mmps, 2 * err))
    if abs(bearing) > 4 * bearing_tol_mrad:
        v = 0  # face the object first
    omega = -2 * bearing  # object to the right -> turn clockwise (negative yaw rate)
    return wheel_speeds(v, omega, vmax_mmps), False, detail


def turn_in_place(direction: int, wheel_mmps: int) -> tuple[int, int]:
    """Wheels turning the base on the spot: direction +1 counter-clockwise, -1 clockwise."""
    return (-direction * wheel_mmps, direction * wheel_mmps)


def state_m(x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int):
    """The planners' state in SI units: ((x, y) m, heading rad, (vx, vy) m/s)."""
    return ((x_mm / 1000.0, y_mm / 1000.0), heading_mrad / 1000.0,
            velocity_m(v_mmps, heading_mrad))


def velocity_m(v_mmps: int, heading_mrad: int) -> tuple[float, float]:
    """The planners' velocity (m/s) along the heading, a whole number of their 1/16 mm per s
    (v cos, v sin in Q12 / 256, rounded): they round it back to those counts exactly, as a
    board program passes them."""
    c, s = cos_q12(heading_mrad), sin_q12(heading_mrad)
    return div_round(v_mmps * c, 256) / 16_000, div_round(v_mmps * s, 256) / 16_000


def path_follower(curve, now_us: int, v_limit_mmps: int) -> tuple[PathFollower, OpCounts]:
    """A follower of a planned curve (host.control.path_follow) and the ops of its timing."""
    traj = Trajectory.from_curve(curve)
    return PathFollower(traj, now_us, v_limit_mmps), traj.ops


