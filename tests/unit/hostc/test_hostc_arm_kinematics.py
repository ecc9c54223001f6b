"""The C host's joint table, kinematics (eq. (3), (11) of 000, eq. (4) of 002) and posture
(eq. (10) of 000) against host/arm_calib.py, host/kinematics.py and host/posture.py."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host import arm_calib, kinematics, posture
from mobigrasp.host.kinematics import ArmPose, Unreachable

FFI, C = hostc.lib()
SETTINGS = examples(400)
GEOMS = st.sampled_from([kinematics.PAPER_000, kinematics.PAPER_002]) | st.builds(
    kinematics.ArmGeometry, st.integers(500, 3000), st.integers(500, 3000), st.integers(1, 3000))
MRAD = st.integers(-3500, 3500)
# the arm's reach is ~280 mm: points up to 400 mm cover the reachable, the boundary and beyond
POINT_Q4 = st.tuples(*[st.integers(-6400, 6400)] * 3)
UNREACHABLE_KIND = {"target on the waist axis": C.MG_IK_ON_AXIS,
                    "out of reach": C.MG_IK_OUT_OF_REACH, "too close": C.MG_IK_TOO_CLOSE,
                    "theta": C.MG_IK_JOINT_LIMIT, "at the joint limits": C.MG_IK_MISSES}


def _geom(g):
    return FFI.new("mg_arm_geometry_t *", (g.l1_mm_q4, g.l2_mm_q4, g.l3_mm_q4))


@SETTINGS
@given(st.integers(0, 5), st.integers(-5000, 5000), st.integers(0, 3000))
def test_joint_table_and_servo_law(ch, angle, pulse):
    assert C.mg_clamp_mrad(ch, angle) == arm_calib.clamp_mrad(ch, angle)
    assert bool(C.mg_within_limits(ch, angle)) == arm_calib.within_limits(ch, angle)
    assert C.mg_mrad_to_pulse_us(ch, angle) == arm_calib.mrad_to_pulse_us(ch, angle)
    out = FFI.new("int32_t *")
    ok = C.mg_pulse_us_to_mrad(ch, pulse, out)
    if arm_calib.PULSE_MIN_US <= pulse <= arm_calib.PULSE_MAX_US:
        assert ok == 1 and out[0] == arm_calib.pulse_us_to_mrad(ch, pulse)
    else:
        assert ok == 0


@SETTINGS
@given(st.lists(st.integers(500, 2500), min_size=6, max_size=6),
       st.lists(st.integers(-5000, 5000), min_size=6, max_size=6))
def test_all_six_channels(pulses, angles):
    out = FFI.new("int32_t[6]")
    assert C.mg_pulses_to_joints_mrad(pulses, out) == 1
    assert tuple(out) == arm_calib.pulses_to_joints_mrad(tuple(pulses))
    C.mg_joints_to_pulses_us(angles, out)
    assert tuple(out) == arm_calib.joints_to_pulses_us(angles)
    C.mg_clamp_joints_mrad(angles, out)
    assert tuple(out) == arm_calib.clamp_joints_mrad(angles)


@SETTINGS
@given(GEOMS, MRAD, MRAD, MRAD, MRAD)
def test_forward_kinematics(g, t2, t3, t4, t5):
    out = FFI.new("int32_t[3]")
    C.mg_fk_mm_q4(_geom(g), t2, t3, t4, t5, out)
    assert tuple(out) == kinematics.fk_mm_q4(g, t2, t3, t4, t5)


def _ik_both(g, target, alpha):
    pose, detail = FFI.new("mg_arm_pose_t *"), FFI.new("int64_t *")
    code = C.mg_ik_pitch_mm_q4(_geom(g), target, alpha, pose, detail)
    return code, pose, detail[0], kinematics.ik_pitch_mm_q4(g, target, alpha)


def _assert_same_ik(code, pose, detail, expect):
    if isinstance(expect, ArmPose):
        assert code == C.MG_IK_OK
        assert (pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad, pose.theta5_mrad) == (
            expect.theta2_mrad, expect.theta3_mrad, expect.theta4_mrad, expect.theta5_mrad)
        return
    assert isinstance(expect, Unreachable)
    kinds = [k for prefix, k in UNREACHABLE_KIND.items() if expect.reason.startswith(prefix)]
    assert kinds == [code], expect.reason
    if code == C.MG_IK_JOINT_LIMIT:
        assert expect.reason.startswith(f"theta{detail} ")
    elif code in (C.MG_IK_OUT_OF_REACH, C.MG_IK_TOO_CLOSE, C.MG_IK_MISSES):
        assert f"{detail / 16:.1f} mm" in expect.reason


@SETTINGS
@given(GEOMS, POINT_Q4, st.integers(-3142, 3142))
def test_inverse_kinematics_any_target(g, target, alpha):
    _assert_same_ik(*_ik_both(g, target, alpha))


@SETTINGS
@given(GEOMS, st.integers(-1400, 1400), st.integers(-2800, 0), st.integers(0, 3000),
       st.integers(-3000, 0), st.integers(-3, 3), st.integers(-3, 3), st.integers(-3, 3))
def test_inverse_kinematics_near_reachable_poses(g, t5, t3, t4, t2, dx, dy, dz):
    """Targets made by FK of poses inside the limits, nudged by a few 1/16 mm: mostly reachable,
    and on the workspace boundary the reach tolerance and the limit snaps are exercised."""
    x, y, z = kinematics.fk_mm_q4(g, t2, t3, t4, t5)
    code, pose, detail, expect = _ik_both(g, (x + dx, y + dy, z + dz), t2 + t3 + t4)
    _assert_same_ik(code, pose, detail, expect)


@SETTINGS
@given(st.integers(-(1 << 20), 1 << 20), MRAD, st.integers(-4000, 4000), st.integers(0, 80),
       st.integers(0, 60), st.integers(1, 400), st.sampled_from([1, -1]), st.integers(0, 30))
def test_precise_grasp_step(slope, theta5, spoke, width, tol, max_step, yaw_sign, dz_step):
    assert C.mg_spoke_angle_mrad(slope) == kinematics.spoke_angle_mrad(slope)
    params = FFI.new("mg_precise_params_t *", (tol, max_step, yaw_sign, dz_step, 20, 40))
    out = FFI.new("mg_precise_step_t *")
    C.mg_precise_grasp_step(theta5, spoke, width, params, out)
    expect = kinematics.precise_grasp_step(theta5, spoke, width, slope_tol_mrad=tol,
                                           max_step_mrad=max_step, yaw_sign=yaw_sign,
                                           dz_step_mm=dz_step)
    assert (out.theta1_mrad, out.theta5_mrad, out.dz_mm, bool(out.aligned),
            out.d_align_mrad) == (expect.theta1_mrad, expect.theta5_mrad, expect.dz_mm,
                                  expect.aligned, expect.d_align_mrad)


POSTURE_PARAMS = st.builds(posture.PostureParams,
                           st.tuples(*[st.integers(0, 8192)] * 3) | st.just((4096, 0, 0)),
                           st.sampled_from(posture.MARGIN_MODES), st.integers(0, 300))


def _params(p):
    mode = C.MG_MARGIN_PRINTED if p.margin_mode == "printed" else C.MG_MARGIN_LIMITS
    return FFI.new("mg_posture_params_t *", (p.k_theta_q12, mode, p.max_step_mrad))


@SETTINGS
@given(GEOMS, st.tuples(st.integers(-3000, 0), st.integers(-2800, 0), st.integers(0, 3000),
                        st.integers(-1400, 1400)), POINT_Q4, POSTURE_PARAMS,
       st.none() | st.integers(-3142, 3142))
def test_posture_adjustment(g, joints, obj, params, alpha_target):
    """Eq. (10): the same new targets, d_alpha, alpha' and loss, with either margin rule."""
    out = FFI.new("mg_posture_adjustment_t *")
    C.mg_adjust_posture(_geom(g), joints, obj, _params(params), alpha_target is not None,
                        alpha_target or 0, out)
    e = posture.adjust_posture(g, joints, obj, params, alpha_target)
    assert (out.theta2_mrad, out.theta3_mrad, out.theta4_mrad, out.theta5_mrad,
            out.d_theta5_mrad, out.d_alpha_mrad, out.alpha_target_mrad, out.alpha_lost_mrad) == (
        e.theta2_mrad, e.theta3_mrad, e.theta4_mrad, e.theta5_mrad, e.d_theta5_mrad,
        e.d_alpha_mrad, e.alpha_target_mrad, e.alpha_lost_mrad)


@SETTINGS
@given(st.integers(-7000, 7000), st.tuples(*[st.integers(-4000, 4000)] * 3), POSTURE_PARAMS)
def test_distribute_alpha_with_negative_weights(d_alpha, th, params):
    """The printed margins go negative outside the paper's sign conventions: T_m < 0 rounds
    the same way (halves away from zero) in both languages."""
    out = FFI.new("int32_t[3]")
    C.mg_distribute_alpha(d_alpha, *th, _params(params), out)
    assert tuple(out) == posture.distribute_alpha(d_alpha, *th, params)
