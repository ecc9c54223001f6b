/* Camera -> platform transform, eqs. (1)-(3) of 000 (host/transforms.py). */
#include "transforms.h"

#include "arm_calib.h"

/* OpenCV camera axes -> the level camera in platform axes: x -> X, y -> -Z, z -> Y (Q12) */
static const mg_mat_q12 c_cv_to_level = {{MG_ONE_Q12, 0, 0}, {0, 0, MG_ONE_Q12},
                                         {0, -MG_ONE_Q12, 0}};

void mg_paper_cam_to_cv(const int32_t p[3], int32_t out[3])
{
    const int32_t x = p[0], y = p[1], z = p[2];
    out[0] = -x, out[1] = -z, out[2] = y;
}

void mg_r_c_r_q12(int32_t alpha_mrad, int32_t theta5_mrad, mg_mat_q12 out)
{
    mg_mat_q12 rz, rx, m;
    mg_rot_z_q12(-theta5_mrad, rz);
    mg_rot_x_q12(alpha_mrad, rx);
    mg_matmul_q12(rz, rx, m);
    mg_matmul_q12(m, c_cv_to_level, out);
}

void mg_camera_position_mm(const mg_arm_geometry_t *g, int32_t theta2_mrad,
                           int32_t theta3_mrad, int32_t theta4_mrad, int32_t theta5_mrad,
                           int32_t out_mm[3])
{
    int32_t q4[3];
    mg_fk_mm_q4(g, theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad, q4);
    for (int i = 0; i < 3; i++)
        out_mm[i] = (q4[i] + 8) >> 4;
}

void mg_camera_to_platform_mm(const int32_t p_cv_mm[3], const mg_arm_geometry_t *g,
                              int32_t theta2_mrad, int32_t theta3_mrad, int32_t theta4_mrad,
                              int32_t theta5_mrad, int32_t out_mm[3])
{
    mg_mat_q12 r;
    int32_t rot[3], cr[3];
    mg_r_c_r_q12(theta2_mrad + theta3_mrad + theta4_mrad, theta5_mrad, r);
    mg_matvec_q12(r, p_cv_mm, rot);
    mg_camera_position_mm(g, theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad, cr);
    for (int i = 0; i < 3; i++)
        out_mm[i] = rot[i] + cr[i];
}

void mg_platform_offset_to_platform_mm(const int32_t offset_mm[3], const mg_arm_geometry_t *g,
                                       int32_t theta2_mrad, int32_t theta3_mrad,
                                       int32_t theta4_mrad, int32_t theta5_mrad,
                                       int32_t out_mm[3])
{
    int32_t cr[3];
    mg_camera_position_mm(g, theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad, cr);
    for (int i = 0; i < 3; i++)
        out_mm[i] = offset_mm[i] + cr[i];
}

int mg_camera_to_platform_from_servo_us(const int32_t p_cv_mm[3], const mg_arm_geometry_t *g,
                                        const int32_t servo_us[6], int32_t out_mm[3])
{
    int32_t j[MG_N_CHANNELS];
    if (!mg_pulses_to_joints_mrad(servo_us, j))
        return 0;
    mg_camera_to_platform_mm(p_cv_mm, g, j[2], j[3], j[4], j[5], out_mm);
    return 1;
}

mg_ops_t mg_camera_to_platform_ops(void)
{
    /* two rotations, seven mat-vec products (two 3x3 products and one mat-vec), eq. (3) */
    const mg_ops_t rest = {0, 0, 20, 0, 0, 12, 0, 0, 0, 0, 0};
    return mg_ops_add(mg_ops_add(mg_ops_add(mg_ops_scaled(mg_rot_ops(), 2),
                                            mg_ops_scaled(mg_matvec_ops(), 7)),
                                 mg_ops_scaled(mg_sin_ops(), 6)),
                      rest);
}
