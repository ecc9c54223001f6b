"""Vision-based approaching adjustment of paper 000 (§III.B, after the Bezier approach).

"Implemented by endeavouring to move toward the centre of the object": once the Bezier curve has
brought the platform near the object, the object position measured by the eye-in-hand camera
(dual "+" symbol, §III.A) drives the base straight at it until it is within grasp range, facing
it. When the object is out of sight the platform stops (000: "The mobile platform has to stop
until the object is seen again") and the caller lets the arm search.

Measurement, §III.A of 000: D_is = D_act · f / d_pixel with
d_pixel = √((u1 − u2)² + (v1 − v2)²) between the centres of the two "+" symbols
(:func:`plus_pair_distance_mm`). The object position in the platform frame O_r (X_r right,
Y_r forward, eq. (2) of 000) comes from the kinematics helper; here it is an input in Q4 mm.

Control law (integer): bearing β = atan2(X_r, Y_r) (right positive, like θ5), range
ρ = |(X_r, Y_r)|. Yaw rate ω = −K_β·β (counter-clockwise positive, so an object to the right turns
the base clockwise); forward speed v = K_ρ·(ρ − ρ_grasp)·cos β, clamped to ±``v_max_mm_s``, and
zero while |β| is larger than ``turn_first_mrad`` (face the object first: driving while turning
swings the camera and the object leaves the view). Done when |ρ − ρ_grasp| <= ``tol_mm`` and
|β| <= ``bearing_tol_mrad``. Wheel speeds by eq. (8) of 000 (:func:`wheel_speeds`).
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control.path_follow import wheel_speeds
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, div_round, isqrt

STEP_OPS = OpCounts(alu=30, muls=6, divs=2, luts=4, branches=8)


def plus_pair_distance_mm(u1_q4: int, v1_q4: int, u2_q4: int, v2_q4: int,
                          f_px: int = 611, d_act_um: int = 47_300) -> int:
    """D_is = D_act·f/d_pixel of 000 §III.A, pixel centres in Q4 (1/16 px); mm, rounded.

    Raises ValueError when the two centres coincide (no distance can be measured).
    """
    d_q4 = isqrt((int(u1_q4) - int(u2_q4)) ** 2 + (int(v1_q4) - int(v2_q4)) ** 2)
    if d_q4 <= 0:
        raise ValueError("plus_pair_distance_mm: the two '+' centres coincide")
    return div_round(int(d_act_um) * int(f_px) * 16, d_q4 * 1000)


@dataclass(frozen=True)
class AdjustParams:
    """Close-approach parameters (ours: 000 gives no numbers for this step)."""

    grasp_range_mm: int = 150  # object this far ahead of the waist axis: within reach
    tol_mm: int = 15
    bearing_tol_mrad: int = 40
    turn_first_mrad: int = 250
    v_max_mm_s: int = 80
    k_range_q12: int = 6144  # 1.5 /s
    k_bearing_q12: int = 8192  # 2 /s


@dataclass(frozen=True)
class AdjustCommand:
    """Wheel speeds (mm/s), done flag, and what was measured."""

    left_mm_s: int
    right_mm_s: int
    done: bool
    lost: bool
    range_mm: int = 0
    bearing_mrad: int = 0


class ApproachAdjust:
    """One step per camera measurement; ``lost_steps`` counts steps without the object."""

    def __init__(self, params: AdjustParams = AdjustParams()) -> None:
        self.p = params
        self.lost_steps = 0

    def step(self, obj_platform_q4: tuple[int, int] | None) -> AdjustCommand:
        """Command for the object at platform (X_r, Y_r) in Q4 mm, or None when not seen."""
        if obj_platform_q4 is None:
            self.lost_steps += 1
            return AdjustCommand(0, 0, False, True)
        self.lost_steps = 0
        xr, yr = int(obj_platform_q4[0]), int(obj_platform_q4[1])
        bearing = atan2_mrad(xr, yr)
        rng = isqrt(xr * xr + yr * yr) >> 4
        err = rng - self.p.grasp_range_mm
        if abs(err) <= self.p.tol_mm and abs(bearing) <= self.p.bearing_tol_mrad:
            return AdjustCommand(0, 0, True, False, rng, bearing)
        v = 0
        if abs(bearing) <= self.p.turn_first_mrad:
            v = (self.p.k_range_q12 * err >> 12) * cos_q12(bearing) >> 12
            v = max(-self.p.v_max_mm_s, min(self.p.v_max_mm_s, v))
        w = -(self.p.k_bearing_q12 * bearing >> 12)
        left, right = wheel_speeds(v, w, self.p.v_max_mm_s)
        return AdjustCommand(left, right, False, False, rng, bearing)
