"""Differential-drive base in pymunk: wheel motors -> velocity constraints -> pose -> encoders.

Pattern of pymunk's examples/tank.py: a kinematic *control body* carries the commanded velocity;
a PivotJoint and a GearJoint tie it to the robot body with ``max_bias = 0`` (velocity only, no
position correction, so no teleporting) and ``max_force`` equal to the ground friction the
wheels can transmit. The robot therefore follows the wheels unless something pushes back
harder than friction (an obstacle stops it; a light object gets pushed).

Kinematics of the two wheels (track ``l_w`` = 0.3 m, paper 000): ``v = (v_r + v_l)/2``,
``omega = (v_r - v_l)/l_w`` (counter-clockwise positive, the world convention; note eq. (8) of
000 writes the opposite sign for its w_w). The caster carries no force and is not modelled.

Geometry: the base reference point (the pose reported everywhere) is the midpoint of the wheel
axle. Collisions use the real footprint, a circle of radius ``FOOTPRINT_RADIUS_M`` = 0.17 m
centred on that point; the safety circle R_r = 0.2 m of paper 001 is a planning margin around it.

Encoders: 1024 quadrature counts per wheel revolution, wheel radius 0.040 m
(docs/conventions.md). Counts are cumulative integers computed from each wheel's ground-contact
displacement (the body's motion projected on the heading, plus/minus the turn times l_w/2), so a
base held by an obstacle produces no counts even while its motors turn (no wheel slip model).
"""

from __future__ import annotations

import math

import pymunk
from pymunk._chipmunk_cffi import lib as _lib

from .actuators import DcMotor
from .obstacles import COLL_BASE

# chipmunk entry points bound once (cffi attribute look-ups are not free in the hot loop)
_GET_POS, _GET_ANGLE = _lib.cpBodyGetPosition, _lib.cpBodyGetAngle
_SET_VEL, _SET_W, _STEP = _lib.cpBodySetVelocity, _lib.cpBodySetAngularVelocity, _lib.cpSpaceStep

WHEEL_TRACK_M = 0.300
WHEEL_RADIUS_M = 0.040
ENCODER_TICKS_PER_REV = 1024
TICKS_PER_M = ENCODER_TICKS_PER_REV / (2 * math.pi * WHEEL_RADIUS_M)
FOOTPRINT_RADIUS_M = 0.17
SAFETY_RADIUS_M = 0.20
BASE_MASS_KG = 6.0
GROUND_MU = 0.8
GRAVITY_MPS2 = 9.81
PHYSICS_DT_US = 1000


class DiffDriveBase:
    """The robot body, its two motors and encoders, added to an existing space."""

    def __init__(self, space: pymunk.Space, x_m: float, y_m: float, heading_rad: float,
                 track_m: float = WHEEL_TRACK_M, radius_m: float = FOOTPRINT_RADIUS_M):
        self.space = space
        self.track_m = track_m
        self.radius_m = radius_m
        self.left = DcMotor()
        self.right = DcMotor()
        self.control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        self.control.position = (x_m, y_m)
        self.control.angle = heading_rad
        moment = pymunk.moment_for_circle(BASE_MASS_KG, 0, radius_m)
        self.body = pymunk.Body(BASE_MASS_KG, moment)
        self.body.position = (x_m, y_m)
        self.body.angle = heading_rad
        self.shape = pymunk.Circle(self.body, radius_m)
        self.shape.collision_type = COLL_BASE
        self.shape.friction = 0.3
        # The robot's own shape must not stop its sonar rays.
        self.shape.filter = pymunk.ShapeFilter(group=1, categories=0b1)
        traction_n = GROUND_MU * BASE_MASS_KG * GRAVITY_MPS2
        self.pivot = pymunk.PivotJoint(self.control, self.body, (0, 0), (0, 0))
        self.pivot.max_bias = 0
        self.pivot.max_force = traction_n
        self.gear = pymunk.GearJoint(self.control, self.body, 0.0, 1.0)
        self.gear.max_bias = 0
        # Yaw torque the wheels can apply: traction at half the track.
        self.gear.max_force = traction_n * track_m / 2
        space.add(self.control, self.body, self.shape, self.pivot, self.gear)
        self._ptrs = (self.body._body, self.control._body, space._space)
        self.left_m = 0.0
        self.right_m = 0.0
        self.steps = 0  # physics steps run so far (collision callbacks read it for their time)
        # Set whenever bodies/shapes were added or removed: the next step then goes through
        # Space.step so pymunk's own bookkeeping runs (see run_steps).
        self.space_changed = True

    # ---- inputs -------------------------------------------------------------------------
    def set_duty(self, left: int, right: int) -> None:
        """Motor duties -255..255 (clamped; non-integers counted and dropped by the motors)."""
        self.left.set_duty(left)
        self.right.set_duty(right)

    # ---- stepping -----------------------------------------------------------------------
    def pre_step(self, dt_us: int) -> None:
        """Advance the motors over one step and command the control body (before space.step)."""
        vl = self.left.advance(dt_us)
        vr = self.right.advance(dt_us)
        self.command_wheels(vl, vr)

    def command_wheels(self, vl_mps: float, vr_mps: float) -> None:
        """Set the control body velocity for wheel surface speeds (m/s)."""
        v = 0.5 * (vl_mps + vr_mps)
        a = self.body.angle
        self.control.velocity = (v * math.cos(a), v * math.sin(a))
        self.control.angular_velocity = (vr_mps - vl_mps) / self.track_m

    def post_step(self, x0: float, y0: float, a0: float) -> None:
        """Integrate wheel ground-contact travel from the pose change of one step."""
        x1, y1 = self.body.position
        a1 = self.body.angle
        am = 0.5 * (a0 + a1)
        d = (x1 - x0) * math.cos(am) + (y1 - y0) * math.sin(am)
        half_turn = 0.5 * (a1 - a0) * self.track_m
        self.left_m += d - half_turn
        self.right_m += d + half_turn

    def run_steps(self, n: int, dt_us: int = PHYSICS_DT_US) -> None:
        """Run ``n`` physics steps of ``dt_us``: motors, control body, space.step, encoders.

        The same work as pre_step / space.step / post_step, inlined and calling chipmunk through
        pymunk's cffi ``lib`` because this loop is the world's hot path (about 100 000 iterations
        per wall second at the 100x target; the Python property wrappers cost 3x more). After
        anything was added to or removed from the space (``space_changed``), the first step goes
        through ``Space.step`` so pymunk's bookkeeping runs. The duties cannot change inside one
        call, so the motor lag is a constant factor per step.
        """
        if n <= 0:
            return
        body_p, control_p, space_p = self._ptrs
        tl, tr = self.left.target_speed_mps(), self.right.target_speed_mps()
        kl = 0.0 if self.left.stuck else self.left.decay(dt_us)
        kr = 0.0 if self.right.stuck else self.right.decay(dt_us)
        vl, vr = self.left.speed_mps, self.right.speed_mps
        track, half_track = self.track_m, 0.5 * self.track_m
        dt_s = dt_us * 1e-6
        cos, sin = math.cos, math.sin
        get_pos, get_angle = _GET_POS, _GET_ANGLE
        set_vel, set_w, step = _SET_VEL, _SET_W, _STEP
        lm, rm = self.left_m, self.right_m
        p = get_pos(body_p)
        x0, y0 = p.x, p.y
        a0 = get_angle(body_p)
        for i in range(n):
            self.steps += 1
            vl = tl + (vl - tl) * kl
            vr = tr + (vr - tr) * kr
            v = 0.5 * (vl + vr)
            set_vel(control_p, (v * cos(a0), v * sin(a0)))
            set_w(control_p, (vr - vl) / track)
            if i == 0 and self.space_changed:
                self.space.step(dt_s)
                self.space_changed = False
            else:
                step(space_p, dt_s)
            p = get_pos(body_p)
            x1, y1 = p.x, p.y
            a1 = get_angle(body_p)
            am = 0.5 * (a0 + a1)
            d = (x1 - x0) * cos(am) + (y1 - y0) * sin(am)
            ht = (a1 - a0) * half_track
            lm += d - ht
            rm += d + ht
            x0, y0, a0 = x1, y1, a1
        self.left.speed_mps, self.right.speed_mps = vl, vr
        self.left_m, self.right_m = lm, rm

    # ---- outputs ------------------------------------------------------------------------
    def encoder_ticks(self) -> tuple[int, int]:
        """Cumulative quadrature counts (left, right); forward travel counts up."""
        return math.floor(self.left_m * TICKS_PER_M), math.floor(self.right_m * TICKS_PER_M)

    def pose(self) -> tuple[float, float, float]:
        """(x_m, y_m, heading_rad) of the wheel-axle midpoint."""
        bp = self._ptrs[0]
        p = _GET_POS(bp)
        return p.x, p.y, _GET_ANGLE(bp)

    def velocity(self) -> tuple[float, float]:
        """(forward speed m/s, yaw rate rad/s) of the body."""
        v = _lib.cpBodyGetVelocity(self.body._body)
        a = _lib.cpBodyGetAngle(self.body._body)
        return (v.x * math.cos(a) + v.y * math.sin(a),
                _lib.cpBodyGetAngularVelocity(self.body._body))


def new_space() -> pymunk.Space:
    """A top-down space (no gravity: the plane is the ground) with a fixed solver setup."""
    space = pymunk.Space()
    space.iterations = 10
    space.gravity = (0.0, 0.0)
    # pymunk's default slop (0.1) is in space units: 10 cm here. Allow 1 mm of overlap.
    space.collision_slop = 0.001
    return space
