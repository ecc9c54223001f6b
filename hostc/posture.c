/* Posture adjustment, 000 section III.B.2 and eq. (10) (host/posture.py, whose docstring gives
 * the margins as printed and the "limits" reading of them). */
#include "posture.h"

#include "arm_calib.h"
#include "fixedpoint.h"

void mg_margins_mrad(int32_t d_alpha_mrad, int32_t theta2_mrad, int32_t theta3_mrad,
                     int32_t theta4_mrad, int32_t mode, int32_t out[3])
{
    const int32_t th[3] = {theta2_mrad, theta3_mrad, theta4_mrad};
    if (mode == MG_MARGIN_LIMITS) {
        for (int32_t i = 0; i < 3; i++)
            out[i] = d_alpha_mrad > 0 ? mg_joint_hi_mrad(i + 2) - th[i]
                                      : th[i] - mg_joint_lo_mrad(i + 2);
    } else if (d_alpha_mrad > 0) { /* as printed: theta2m = pi - theta2, -theta3, -theta4 */
        out[0] = MG_PI_MRAD - theta2_mrad, out[1] = -theta3_mrad, out[2] = -theta4_mrad;
    } else { /* theta2, pi + theta3, pi + theta4 */
        out[0] = theta2_mrad, out[1] = MG_PI_MRAD + theta3_mrad, out[2] = MG_PI_MRAD + theta4_mrad;
    }
}

void mg_distribute_alpha(int32_t d_alpha_mrad, int32_t theta2_mrad, int32_t theta3_mrad,
                         int32_t theta4_mrad, const mg_posture_params_t *p, int32_t out[3])
{
    int32_t m[3];
    mg_margins_mrad(d_alpha_mrad, theta2_mrad, theta3_mrad, theta4_mrad, p->margin_mode, m);
    int64_t w[3], t_m = 0;
    for (int i = 0; i < 3; i++) {
        w[i] = (int64_t)p->k_theta_q12[i] * m[i];
        t_m += w[i];
    }
    out[0] = out[1] = out[2] = 0;
    if (t_m == 0 || d_alpha_mrad == 0)
        return; /* no room: no pitch change */
    int32_t sum = 0, biggest = 0;
    for (int i = 0; i < 3; i++) {
        out[i] = (int32_t)mg_div_round64((int64_t)d_alpha_mrad * w[i], t_m);
        sum += out[i];
        const int64_t size = w[i] < 0 ? -w[i] : w[i];
        const int64_t top = w[biggest] < 0 ? -w[biggest] : w[biggest];
        if (size > top)
            biggest = i; /* the first of equal ones */
    }
    out[biggest] += d_alpha_mrad - sum; /* the rounding remainder, so the sum is d_alpha */
}

int32_t mg_desired_alpha_mrad(const mg_arm_geometry_t *g, int32_t theta2_mrad,
                              int32_t theta3_mrad, int32_t theta4_mrad,
                              const int32_t object_mm_q4[3])
{
    /* alpha': the pitch of the line from the camera (eq. (3), waist facing the object) to it */
    int32_t cam[3];
    mg_fk_mm_q4(g, theta2_mrad, theta3_mrad, theta4_mrad, 0, cam);
    const int64_t ox = object_mm_q4[0], oy = object_mm_q4[1];
    const int64_t rho = mg_isqrt(ox * ox + oy * oy);
    return mg_atan2_mrad((int64_t)object_mm_q4[2] - cam[2], rho - cam[1]);
}

static int32_t cap(int32_t v, int32_t c)
{
    return c == 0 ? v : v < -c ? -c : v > c ? c : v;
}

void mg_adjust_posture(const mg_arm_geometry_t *g, const int32_t joints_mrad[4],
                       const int32_t object_mm_q4[3], const mg_posture_params_t *p,
                       int32_t has_alpha_target, int32_t alpha_target_mrad,
                       mg_posture_adjustment_t *out)
{
    const int32_t th2 = joints_mrad[0], th3 = joints_mrad[1], th4 = joints_mrad[2];
    const int32_t th5 = joints_mrad[3];
    const int32_t ox = object_mm_q4[0], oy = object_mm_q4[1];
    int32_t d5 = 0;
    if (ox != 0 || oy != 0) /* d_theta5 = atan2(P_orx, P_ory) - theta5, wrapped to [-pi, pi) */
        d5 = (int32_t)mg_floor_mod((int64_t)mg_atan2_mrad(ox, oy) - th5 + MG_PI_MRAD,
                                   2 * MG_PI_MRAD) - MG_PI_MRAD;
    d5 = cap(d5, p->max_step_mrad);
    const int32_t alpha = th2 + th3 + th4;
    const int32_t a_target = has_alpha_target
                                 ? alpha_target_mrad
                                 : mg_desired_alpha_mrad(g, th2, th3, th4, object_mm_q4);
    const int32_t d_alpha = a_target - alpha;
    int32_t d[3];
    mg_distribute_alpha(d_alpha, th2, th3, th4, p, d);
    out->theta2_mrad = mg_clamp_mrad(2, th2 + cap(d[0], p->max_step_mrad));
    out->theta3_mrad = mg_clamp_mrad(3, th3 + cap(d[1], p->max_step_mrad));
    out->theta4_mrad = mg_clamp_mrad(4, th4 + cap(d[2], p->max_step_mrad));
    out->theta5_mrad = mg_clamp_mrad(5, th5 + d5);
    out->d_theta5_mrad = d5;
    out->d_alpha_mrad = d_alpha;
    out->alpha_target_mrad = a_target;
    out->alpha_lost_mrad
        = d_alpha - ((out->theta2_mrad + out->theta3_mrad + out->theta4_mrad) - alpha);
}
