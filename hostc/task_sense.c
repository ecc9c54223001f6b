/* What the task reads from the camera and the odometry (host/task/sense.py). */
#include "task_sense.h"

#include "fixedpoint.h"
#include "trig.h"

static int64_t r12(int64_t v)
{
    return (v + 2048) >> 12;
}

void mg_camera_axes_q12(const int32_t joints_mrad[6], int32_t axes[3][3])
{
    const int32_t t1 = joints_mrad[1], t5 = joints_mrad[5];
    const int32_t alpha = joints_mrad[2] + joints_mrad[3] + joints_mrad[4];
    const int64_t ca = mg_cos_q12(alpha), sa = mg_sin_q12(alpha);
    const int64_t c5 = mg_cos_q12(t5), s5 = mg_sin_q12(t5);
    const int64_t x0[3] = {c5, -s5, 0};
    const int64_t y0[3] = {r12(sa * s5), r12(sa * c5), -ca}; /* z cross x0 */
    const int64_t c1 = mg_cos_q12(t1), s1 = mg_sin_q12(t1);
    for (int i = 0; i < 3; i++) {
        axes[0][i] = (int32_t)r12(c1 * x0[i] + s1 * y0[i]);
        axes[1][i] = (int32_t)r12(c1 * y0[i] - s1 * x0[i]);
    }
    axes[2][0] = (int32_t)r12(ca * s5);
    axes[2][1] = (int32_t)r12(ca * c5);
    axes[2][2] = (int32_t)sa;
}

void mg_pixel_to_platform_mm_q4(const mg_arm_geometry_t *g, const int32_t joints_mrad[6],
                                const mg_camera_model_t *cam, int32_t u_q4, int32_t v_q4,
                                int32_t depth_mm_q4, int32_t out_q4[3])
{
    int32_t pc[3], axes[3][3];
    mg_fk_mm_q4(g, joints_mrad[2], joints_mrad[3], joints_mrad[4], joints_mrad[5], pc);
    mg_camera_axes_q12(joints_mrad, axes);
    const int64_t f_q4 = (int64_t)cam->f_px * 16;
    const int64_t off_x = mg_floor_div((int64_t)depth_mm_q4 * (u_q4 - cam->u0_px * 16), f_q4);
    const int64_t off_y = mg_floor_div((int64_t)depth_mm_q4 * (v_q4 - cam->v0_px * 16), f_q4);
    for (int i = 0; i < 3; i++)
        out_q4[i] = (int32_t)(pc[i] + r12((int64_t)depth_mm_q4 * axes[2][i]
                                          + off_x * axes[0][i] + off_y * axes[1][i]));
}

int32_t mg_bearing_mrad(int32_t um_q4, int32_t theta5_mrad, const mg_camera_model_t *cam)
{
    return theta5_mrad + mg_atan2_mrad((int64_t)um_q4 - cam->u0_px * 16,
                                       (int64_t)cam->f_px * 16);
}

int32_t mg_d_pixel_px(int32_t d_pixel_q4)
{
    return (int32_t)(((int64_t)d_pixel_q4 + 8) >> 4);
}

void mg_platform_to_odom_mm(int32_t x_mm, int32_t y_mm, int32_t heading_mrad,
                            int32_t mount_forward_mm, const int32_t p_q4[3], int32_t out_mm[2])
{
    const int64_t c = mg_cos_q12(heading_mrad), s = mg_sin_q12(heading_mrad);
    const int64_t fwd_q4 = (int64_t)p_q4[1] + (int64_t)mount_forward_mm * 16;
    const int64_t right_q4 = p_q4[0];
    /* forward = (c, s), right = (s, -c) */
    const int64_t dx = r12(fwd_q4 * c + right_q4 * s), dy = r12(fwd_q4 * s - right_q4 * c);
    out_mm[0] = (int32_t)(x_mm + ((dx + 8) >> 4));
    out_mm[1] = (int32_t)(y_mm + ((dy + 8) >> 4));
}

void mg_odom_to_platform_q4(int32_t x_mm, int32_t y_mm, int32_t heading_mrad,
                            int32_t mount_forward_mm, int32_t obj_x_mm, int32_t obj_y_mm,
                            int32_t out_q4[2])
{
    const int64_t c = mg_cos_q12(heading_mrad), s = mg_sin_q12(heading_mrad);
    const int64_t dx = ((int64_t)obj_x_mm - x_mm) * 16, dy = ((int64_t)obj_y_mm - y_mm) * 16;
    out_q4[0] = (int32_t)r12(dx * s - dy * c);
    out_q4[1] = (int32_t)(r12(dx * c + dy * s) - (int64_t)mount_forward_mm * 16);
}

int mg_plus_positions(const mg_arm_geometry_t *g, const int32_t joints_mrad[6],
                      const mg_camera_model_t *cam, const int32_t uv_q4[4], int32_t dist_mm,
                      int32_t has_top, int32_t top_q4, int32_t out_q4[2][3])
{
    const int64_t depth = (int64_t)dist_mm * 16;
    if (depth <= 0 || depth > INT32_MAX / 4)
        return 0;
    for (int i = 0; i < 2; i++) {
        const int32_t u = uv_q4[2 * i], v = uv_q4[2 * i + 1];
        mg_pixel_to_platform_mm_q4(g, joints_mrad, cam, u, v, (int32_t)depth, out_q4[i]);
        if (!has_top)
            continue;
        int32_t far[3];
        mg_pixel_to_platform_mm_q4(g, joints_mrad, cam, u, v, (int32_t)(2 * depth), far);
        const int64_t dz = (int64_t)far[2] - out_q4[i][2]; /* z along the ray per depth */
        if (dz >= 0)
            return 0; /* the ray does not go down to the top */
        const int64_t d = depth + mg_floor_div(((int64_t)top_q4 - out_q4[i][2]) * depth, dz);
        if (!(0 < d && d <= 4 * depth))
            return 0;
        mg_pixel_to_platform_mm_q4(g, joints_mrad, cam, u, v, (int32_t)d, out_q4[i]);
    }
    return 1;
}
