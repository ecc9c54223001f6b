/* Ranging from a known physical size (host/ranging.py): the pinhole range of 000, 002
 * section 4 as printed, the parallax bearing, and what the ring-pair ranging of ranging.c
 * costs. Apart from ranging.c, which is also built bare for the ARM calibration (no libc:
 * these return op-count structs by value). */
#include "ranging.h"

#include "fixedpoint.h"

int mg_range_from_size_mm(int32_t size_um, int32_t f_px, int32_t size_px_q4, int32_t *out_mm)
{
    if (size_px_q4 <= 0)
        return 0;
    *out_mm = (int32_t)mg_div_round64((int64_t)size_um * f_px * 16, (int64_t)size_px_q4 * 1000);
    return 1;
}

int mg_range_002(int32_t d_pixel_q4, int32_t u_c_q4, int32_t v_c_q4, int32_t alpha_mrad,
                 int32_t theta5_mrad, int32_t f_px, int32_t u0_px, int32_t v0_px, int32_t d_um,
                 mg_range_002_t *out)
{
    int32_t d_oc;
    if (!mg_range_from_size_mm(d_um, f_px, d_pixel_q4, &d_oc))
        return 0;
    const int32_t th_v = alpha_mrad + mg_atan2_mrad(16 * v0_px - v_c_q4, 16 * f_px);
    const int32_t th_h = theta5_mrad + mg_atan2_mrad(u_c_q4 - 16 * u0_px, 16 * f_px);
    const int64_t horiz = mg_mul_q12(d_oc, mg_cos_q12(th_v));
    out->d_oc_mm = d_oc;
    out->theta_v_mrad = th_v;
    out->theta_h_mrad = th_h;
    out->x_oc_mm = (int32_t)mg_mul_q12(horiz, mg_sin_q12(th_h));
    out->y_oc_mm = (int32_t)mg_mul_q12(horiz, mg_cos_q12(th_h));
    out->z_oc_mm = (int32_t)mg_mul_q12(d_oc, mg_sin_q12(th_v));
    return 1;
}

mg_ops_t mg_range_002_ops(void)
{
    /* one division, two atan2, four sin/cos, a few Q12 products */
    const mg_ops_t own = {0, 0, 10, 0, 0, 2, 1, 0, 0, 0, 0};
    return mg_ops_add(mg_ops_add(mg_ops_add(own, mg_ops_scaled(mg_atan2_ops(), 2)),
                                 mg_ops_scaled(mg_sin_ops(), 4)),
                      mg_mul_q12_ops(4));
}

mg_ops_t mg_locate_ring_pair_ops(void)
{
    /* thirteen 64-bit divisions as libgcc's __aeabi_ldivmod (a shift-subtract loop, about 320
     * cycles on these operands: docs/budget.md), 64-bit products as 32-bit MUL pairs, four
     * sin/cos, one atan2, four digit-by-digit roots of ~45-bit numbers */
    const mg_ops_t div64 = {0, 0, 260, 20, 0, 0, 0, 0, 0, 0, 0};
    const mg_ops_t own = {0, 0, 60, 0, 0, 24, 0, 0, 0, 0, 0};
    return mg_ops_add(mg_ops_add(mg_ops_add(mg_ops_scaled(div64, 13), own),
                                 mg_ops_add(mg_ops_scaled(mg_sin_ops(), 4), mg_atan2_ops())),
                      mg_ops_scaled(mg_isqrt_ops((int64_t)1 << 44), 4));
}

int32_t mg_platform_bearing_mrad(int32_t cam_x_mm, int32_t cam_y_mm, int32_t bearing_mrad,
                                 int32_t dist_mm)
{
    /* in um, which keeps short ranges */
    const int64_t x_um = 1000 * (int64_t)cam_x_mm
                         + mg_mul_q12(1000 * (int64_t)dist_mm, mg_sin_q12(bearing_mrad));
    const int64_t y_um = 1000 * (int64_t)cam_y_mm
                         + mg_mul_q12(1000 * (int64_t)dist_mm, mg_cos_q12(bearing_mrad));
    return mg_atan2_mrad(x_um, y_um);
}
