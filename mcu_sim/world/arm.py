"""The 6-DOF arm on the base: joint servos, forward kinematics (eq. (3) of 000) and the grasp rule.

Joint numbering per docs/conventions.md (paper 000): theta5 waist yaw, theta4 shoulder pitch
(link l1), theta3 elbow pitch (l2), theta2 wrist pitch (l3), theta1 wrist roll, theta0 gripper.
Pitch angles are from the horizontal, positive up; ``alpha = theta2 + theta3 + theta4`` is the
pitch of l3 and of the camera's optical axis.

Platform frame O_r (000, Fig. 2): origin on the waist axis at the shoulder height, Y_r forward,
X_r right, Z_r up. The camera (and the gripper fingertips, 0 mm beyond it) is at eq. (3) of 000:

    r     = l1 cos(theta4) + l2 cos(theta4 + theta3) + l3 cos(alpha)
    P_crx = r sin(theta5),  P_cry = r cos(theta5)
    P_crz = l1 sin(theta4) + l2 sin(theta4 + theta3) + l3 sin(alpha)

Mounting (not given by the papers, chosen so the gripper reaches an object in front of the
0.17 m footprint): the waist axis is ``ARM_MOUNT_FORWARD_M`` = 0.10 m ahead of the wheel-axle
midpoint; the shoulder is 0.20 m above the ground (000), h_r = 0.108 m (001) or 0.05 m (002).

Camera axes (OpenCV: x right, y down, z optical axis): z = direction of l3; with the roll at 0,
x is the arm's horizontal right direction (X_r turned by the waist) and y = z cross x. The wrist
roll theta1 turns x and y about z: x' = cos(theta1) x + sin(theta1) y, y' = z cross x'.

Grasp rule: when the gripper *closes* past the object's grip width while the fingertip is
within ``GRASP_TOL_XY_M`` = 15 mm horizontally and ``GRASP_TOL_Z_M`` = 20 mm vertically of the
grasp point and |alpha - alpha_grasp| < ``GRASP_TOL_ALPHA_RAD`` = 0.3 rad, the object is grasped;
alpha_grasp is -pi/2 (from above) for 000 and 001 and 0 (horizontal) for 002.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .actuators import N_CHANNELS, Servo, gripper_opening_m

ARM_MOUNT_FORWARD_M = 0.10
GRASP_TOL_XY_M = 0.015
GRASP_TOL_Z_M = 0.020
GRASP_TOL_ALPHA_RAD = 0.3

# Power-on posture (theta4 = pi/2, theta3 = theta2 = -pi/2; pulses 1545, 1455, 1455 us with the
# conventions table): l1 up, l2 forward, l3 and the camera looking straight down; gripper open.
HOME_JOINTS: tuple[float, ...] = (0.0, 0.0, -math.pi / 2, -math.pi / 2, math.pi / 2, 0.0)


@dataclass(frozen=True)
class ArmGeometry:
    """Link lengths (m), shoulder height above the ground (m), waist offset ahead of the axle."""

    l1: float
    l2: float
    l3: float
    h_shoulder_m: float
    mount_forward_m: float = ARM_MOUNT_FORWARD_M


ARM_BY_METHOD: dict[str, ArmGeometry] = {
    "000": ArmGeometry(0.0955, 0.089, 0.097, 0.20),
    "001": ArmGeometry(0.16, 0.16, 0.20, 0.108),
    # 002's compact robot carries its arm low (0.05 m): with theta2 <= 0 a level gripper (eq. (4)
    # of 002) is never below the shoulder and only near full stretch at its height, so the
    # shoulder sits 50 mm under the cylinder's 0.10 m grasp point (see docs/conventions.md)
    "002": ArmGeometry(0.097, 0.089, 0.0955, 0.05),
}

GRASP_ALPHA_BY_METHOD: dict[str, float] = {"000": -math.pi / 2, "001": -math.pi / 2, "002": 0.0}


def camera_point_platform(geom: ArmGeometry, joints: list[float] | tuple[float, ...]
                          ) -> tuple[float, float, float]:
    """(P_crx, P_cry, P_crz) in O_r (X right, Y forward, Z up), eq. (3) of 000."""
    t2, t3, t4, t5 = joints[2], joints[3], joints[4], joints[5]
    alpha = t2 + t3 + t4
    r = geom.l1 * math.cos(t4) + geom.l2 * math.cos(t4 + t3) + geom.l3 * math.cos(alpha)
    z = geom.l1 * math.sin(t4) + geom.l2 * math.sin(t4 + t3) + geom.l3 * math.sin(alpha)
    return r * math.sin(t5), r * math.cos(t5), z


def camera_axes_platform(joints: list[float] | tuple[float, ...]) -> np.ndarray:
    """3x3 matrix whose columns are the camera x (right), y (down), z (optical) axes in O_r."""
    t1, t5 = joints[1], joints[5]
    alpha = joints[2] + joints[3] + joints[4]
    ca, sa, c5, s5 = math.cos(alpha), math.sin(alpha), math.cos(t5), math.sin(t5)
    # x0 = (c5, -s5, 0) and y0 = z cross x0 = (sa s5, sa c5, -ca), written out; the rolled
    # x = cos(t1) x0 + sin(t1) y0 and y = z cross x = cos(t1) y0 - sin(t1) x0 in plain floats,
    # the same products and sums as the vector expressions, without a numpy call per term
    c1, s1 = math.cos(t1), math.sin(t1)
    x0, y0 = (c5, -s5, 0.0), (sa * s5, sa * c5, -ca)
    z = (ca * s5, ca * c5, sa)
    return np.array([[c1 * x0[i] + s1 * y0[i], c1 * y0[i] - s1 * x0[i], z[i]]
                     for i in range(3)])


def platform_to_world(geom: ArmGeometry, base_pose: tuple[float, float, float]) -> np.ndarray:
    """4x4 transform from O_r to the world for a base pose (x_m, y_m, heading_rad)."""
    bx, by, h = base_pose
    c, s = math.cos(h), math.sin(h)
    m = geom.mount_forward_m
    # columns: right (sin h, -cos h, 0), forward (cos h, sin h, 0), up, and the waist axis at the
    # shoulder height; one array call (built column by column it cost ~4x more)
    return np.array([[s, c, 0.0, bx + m * c],
                     [-c, s, 0.0, by + m * s],
                     [0.0, 0.0, 1.0, geom.h_shoulder_m],
                     [0.0, 0.0, 0.0, 1.0]])


class Arm:
    """Six servos plus the arm geometry; joint values are evaluated at a given time."""

    def __init__(self, geom: ArmGeometry, initial: tuple[float, ...] = HOME_JOINTS):
        if len(initial) != N_CHANNELS:
            raise ValueError(f"Arm: expected {N_CHANNELS} initial joint values, got {len(initial)}")
        self.geom = geom
        self.servos = [Servo(ch, initial[ch]) for ch in range(N_CHANNELS)]

    def set_pulse_us(self, ch: int, pulse_us: float, t_us: int) -> None:
        """Route a servo pulse to its channel (channel checked by the servo table)."""
        if not isinstance(ch, int) or not 0 <= ch < N_CHANNELS:
            raise ValueError(f"servo channel must be an int 0..{N_CHANNELS - 1}, got {ch!r}")
        self.servos[ch].set_pulse_us(pulse_us, t_us)

    def joints(self, t_us: int) -> list[float]:
        """[theta0 (closure 0..1), theta1 .. theta5 (rad)] at ``t_us``."""
        return [s.angle_at(t_us) for s in self.servos]

    def gripper_opening_m(self, t_us: int) -> float:
        """Finger opening (m) at ``t_us``."""
        return gripper_opening_m(self.servos[0].angle_at(t_us))

    def camera_pose_world(self, base_pose: tuple[float, float, float], t_us: int
                          ) -> tuple[np.ndarray, np.ndarray]:
        """(position (3,), R_wc (3, 3)) of the camera in the world; columns of R_wc = x, y, z."""
        q = self.joints(t_us)
        t = platform_to_world(self.geom, base_pose)
        p = np.array(camera_point_platform(self.geom, q))
        pos = t[:3, :3] @ p + t[:3, 3]
        r_wc = t[:3, :3] @ camera_axes_platform(q)
        return pos, r_wc

    def fingertip_world(self, base_pose: tuple[float, float, float], t_us: int,
                        joints: list[float] | None = None) -> tuple[float, float, float]:
        """World position of the fingertips (the camera point; 0 mm beyond it).

        Plain floats, no numpy: the world calls this on its ticks. ``joints`` may pass the
        joint values at ``t_us`` when the caller already has them.
        """
        q = self.joints(t_us) if joints is None else joints
        px, py, pz = camera_point_platform(self.geom, q)
        bx, by, h = base_pose
        c, s = math.cos(h), math.sin(h)
        fwd = self.geom.mount_forward_m + py
        return bx + fwd * c + px * s, by + fwd * s - px * c, self.geom.h_shoulder_m + pz


def grasp_ok(fingertip: np.ndarray, grasp_point: tuple[float, float, float], alpha: float,
             alpha_grasp: float = -math.pi / 2) -> bool:
    """The position and orientation part of the grasp rule (the closing part is the caller's).

    ``alpha_grasp`` is the gripper pitch the method grasps with: -pi/2 (from above, 000 and
    001) or 0 (horizontal, the constraint theta1 + theta2 + theta3 = 0 of eq. (4) of 002).
    """
    dx = fingertip[0] - grasp_point[0]
    dy = fingertip[1] - grasp_point[1]
    return (math.hypot(dx, dy) <= GRASP_TOL_XY_M
            and abs(fingertip[2] - grasp_point[2]) <= GRASP_TOL_Z_M
            and abs(alpha - alpha_grasp) < GRASP_TOL_ALPHA_RAD)
