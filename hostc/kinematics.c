/* Arm kinematics, host/kinematics.py: FK by eq. (3) of 000, IK by eq. (11) of 000 generalised
 * to any pitch alpha_T of the last link (eq. (4) of 002 at alpha_T = 0). See the Python module
 * for the derivation: the wrist point A = r - l3 cos alpha_T, B = P_orz - l3 sin alpha_T,
 * th3 = -acos((A^2 + B^2 - l1^2 - l2^2) / (2 l1 l2)), th4 by atan2 of the exact sine and cosine
 * numerators, th2 = alpha_T - th3 - th4, th5 = atan2(P_orx, P_ory). Products of two Q4 lengths
 * and the atan2 numerators take 64 bits. */
#include "kinematics.h"

#include "arm_calib.h"
#include "fixedpoint.h"

#define Q4 16
#define PI_URAD 3141593

static int64_t round_q12(int64_t v)
{
    return (v + 2048) >> 12;
}

static int64_t iabs(int64_t v)
{
    return v < 0 ? -v : v;
}

void mg_fk_mm_q4(const mg_arm_geometry_t *g, int32_t theta2_mrad, int32_t theta3_mrad,
                 int32_t theta4_mrad, int32_t theta5_mrad, int32_t out_mm_q4[3])
{
    const int32_t t43 = theta4_mrad + theta3_mrad, alpha = t43 + theta2_mrad;
    const int64_t r = round_q12((int64_t)g->l1_mm_q4 * mg_cos_q12(theta4_mrad)
                                + (int64_t)g->l2_mm_q4 * mg_cos_q12(t43)
                                + (int64_t)g->l3_mm_q4 * mg_cos_q12(alpha));
    const int64_t z = round_q12((int64_t)g->l1_mm_q4 * mg_sin_q12(theta4_mrad)
                                + (int64_t)g->l2_mm_q4 * mg_sin_q12(t43)
                                + (int64_t)g->l3_mm_q4 * mg_sin_q12(alpha));
    out_mm_q4[0] = (int32_t)round_q12(r * mg_sin_q12(theta5_mrad));
    out_mm_q4[1] = (int32_t)round_q12(r * mg_cos_q12(theta5_mrad));
    out_mm_q4[2] = (int32_t)z;
}

/* an angle within snap_mrad outside a joint limit is put on the limit */
static int32_t snap_to_limit(int32_t ch, int32_t angle_mrad, int32_t snap_mrad)
{
    const int32_t lo = mg_joint_lo_mrad(ch), hi = mg_joint_hi_mrad(ch);
    if (lo - snap_mrad <= angle_mrad && angle_mrad < lo)
        return lo;
    if (hi < angle_mrad && angle_mrad <= hi + snap_mrad)
        return hi;
    return angle_mrad;
}

int32_t mg_ik_pitch_mm_q4(const mg_arm_geometry_t *g, const int32_t target_mm_q4[3],
                          int32_t alpha_t_mrad, mg_arm_pose_t *pose, int64_t *detail)
{
    const int64_t x = target_mm_q4[0], y = target_mm_q4[1], z = target_mm_q4[2];
    *detail = 0;
    if (x == 0 && y == 0)
        return MG_IK_ON_AXIS;
    int64_t theta5_u = mg_atan2_urad(x, y); /* th5 = atan2(P_orx, P_ory) */
    int64_t r = mg_isqrt(x * x + y * y);    /* = P_ory / cos th5 */
    /* behind the waist axis: reach over the shoulder with the waist turned by pi and r < 0 */
    if (iabs(theta5_u) > 1000 * (int64_t)(mg_joint_hi_mrad(5) + MG_LIMIT_SNAP_MRAD)) {
        theta5_u -= theta5_u > 0 ? PI_URAD : -PI_URAD;
        r = -r;
    }
    const int32_t theta5 = mg_urad_to_mrad(theta5_u);
    const int64_t l1 = g->l1_mm_q4, l2 = g->l2_mm_q4, l3 = g->l3_mm_q4;
    const int64_t a = r - round_q12(l3 * mg_cos_q12(alpha_t_mrad));
    const int64_t b = z - round_q12(l3 * mg_sin_q12(alpha_t_mrad));
    const int64_t d2 = a * a + b * b;
    int64_t num = d2 - l1 * l1 - l2 * l2; /* cos th3 = num / den */
    const int64_t den = 2 * l1 * l2;
    /* a target within REACH_TOL of the boundary is taken onto it rather than refused */
    if (den < num && num <= (2 * (l1 + l2) + MG_REACH_TOL_MM_Q4) * MG_REACH_TOL_MM_Q4 + den)
        num = den;
    else if (-den > num
             && num >= -den - (2 * iabs(l1 - l2) + MG_REACH_TOL_MM_Q4) * MG_REACH_TOL_MM_Q4)
        num = -den;
    if (num > den || num < -den) {
        *detail = mg_isqrt(d2);
        return num > den ? MG_IK_OUT_OF_REACH : MG_IK_TOO_CLOSE;
    }
    const int64_t sin_den = mg_isqrt(den * den - num * num); /* |sin th3| den */
    const int64_t theta3_u = -(int64_t)mg_atan2_urad(sin_den, num); /* elbow in [-pi, 0] */
    /* k1 = l1 + l2 cos th3, k2 = l2 sin th3, both times den */
    const int64_t k1 = l1 * den + l2 * num, k2 = -l2 * sin_den;
    const int64_t theta4_u = mg_atan2_urad(k1 * b - k2 * a, k1 * a + k2 * b);
    const int32_t theta3 = snap_to_limit(3, mg_urad_to_mrad(theta3_u), MG_LIMIT_SNAP_MRAD);
    const int32_t theta4 = snap_to_limit(4, mg_urad_to_mrad(theta4_u), MG_LIMIT_SNAP_MRAD);
    mg_arm_pose_t p;
    p.theta2_mrad = snap_to_limit(2, alpha_t_mrad - theta3 - theta4, MG_ALPHA_SNAP_MRAD);
    p.theta3_mrad = theta3;
    p.theta4_mrad = theta4;
    p.theta5_mrad = snap_to_limit(5, theta5, MG_LIMIT_SNAP_MRAD);
    const int32_t val[4] = {p.theta2_mrad, p.theta3_mrad, p.theta4_mrad, p.theta5_mrad};
    for (int32_t ch = 2; ch <= 5; ch++)
        if (!mg_within_limits(ch, val[ch - 2])) {
            *detail = ch;
            *pose = p; /* the pose outside the limits, for the reason's text */
            return MG_IK_JOINT_LIMIT;
        }
    /* the snap may move the point: the pose returned is within 1 mm of the target */
    int32_t q[3];
    mg_fk_mm_q4(g, p.theta2_mrad, p.theta3_mrad, p.theta4_mrad, p.theta5_mrad, q);
    const int64_t ex = q[0] - x, ey = q[1] - y, ez = q[2] - z;
    const int64_t err2 = ex * ex + ey * ey + ez * ez;
    if (err2 > Q4 * Q4) {
        *detail = mg_isqrt(err2);
        return MG_IK_MISSES;
    }
    *pose = p;
    return MG_IK_OK;
}

int32_t mg_spoke_angle_mrad(int32_t slope_q12)
{
    return mg_urad_to_mrad(mg_atan2_urad(slope_q12, 4096));
}

void mg_precise_grasp_step(int32_t theta5_mrad, int32_t spoke_mrad, int32_t width_px,
                           const mg_precise_params_t *p, mg_precise_step_t *out)
{
    /* the "+" has four spokes a quarter turn apart: fold into [-pi/4, pi/4) */
    const int32_t q = MG_HALF_PI_MRAD;
    const int32_t ang = (int32_t)mg_floor_mod((int64_t)spoke_mrad + q / 2, q) - q / 2;
    int32_t step = p->yaw_sign * ang;
    step = step < -p->max_step_mrad ? -p->max_step_mrad
           : step > p->max_step_mrad ? p->max_step_mrad : step;
    const int32_t slope_ok = (ang < 0 ? -ang : ang) <= p->slope_tol_mrad;
    const int32_t dz = width_px < p->w_min_px   ? -p->dz_step_mm
                       : width_px > p->w_max_px ? p->dz_step_mm : 0;
    out->theta1_mrad = MG_HALF_PI_MRAD; /* th1 rotates by pi/2 above the object */
    out->theta5_mrad = mg_clamp_mrad(5, theta5_mrad + (slope_ok ? 0 : step));
    out->dz_mm = dz;
    out->aligned = slope_ok && dz == 0;
    out->d_align_mrad = slope_ok ? 0 : step;
    out->slope_ok = slope_ok;
    out->angle_mrad = ang;
}
