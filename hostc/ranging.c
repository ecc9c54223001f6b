/* The 002 ring-pair ranging, host/ranging.py locate_ring_pair: the axis point between the two
 * rings from their pixel spacing d, the image point of their midpoint (u, v) and the red width
 * (all Q4 px), camera pitch alpha and waist yaw theta5 (mrad). The exact pinhole geometry of a
 * vertical segment seen by a pitched camera (002 §4, D_OC = D f / d_pixel done along the
 * ray), then the front surface moved to the axis by the radius R = width D / (2 d). */
#include "div_round.h"
#include "isqrt.h"
#include "kernels.h"

int32_t mg_locate_ring_pair(int32_t d_pixel_q4, int32_t u_q4, int32_t v_q4, int32_t width_q4,
                            int32_t alpha_mrad, int32_t theta5_mrad, int32_t f_px,
                            int32_t u0_px, int32_t v0_px, int32_t d_um, int32_t *out)
{
    /* the range where every product below fits in 64 bits (a frame is far inside it) */
    if (d_pixel_q4 <= 0 || f_px <= 0 || f_px > MG_RANGING_MAX_PX || d_um <= 0
        || d_um > MG_RANGING_MAX_UM || width_q4 < 0 || width_q4 > 16 * MG_RANGING_MAX_PX)
        return 0;
    for (int32_t k = 0; k < 2; k++) {
        const int32_t c = k ? v_q4 - 16 * v0_px : u_q4 - 16 * u0_px;
        if (c < -16 * MG_RANGING_MAX_PX || c > 16 * MG_RANGING_MAX_PX)
            return 0;
    }
    const int64_t fq = 16 * (int64_t)f_px; /* f in Q4 px */
    const int64_t xn = (int64_t)u_q4 - 16 * (int64_t)u0_px;
    const int64_t yn = (int64_t)v_q4 - 16 * (int64_t)v0_px;
    const int64_t sa = mg_sin_q12(alpha_mrad), ca = mg_cos_q12(alpha_mrad);
    /* the ray (xn, yn, f) in platform axes before the yaw, Q16: right, forward, up */
    const int64_t fwd = ca * fq + sa * yn;
    const int64_t up = sa * fq - ca * yn;
    const int64_t right = xn * 4096;
    /* depth Z_c = D fwd / d in µm; the point is Z_c * ray / f */
    const int64_t zc_um = mg_div_round_i64((int64_t)d_um * fwd, (int64_t)d_pixel_q4 * 4096);
    int64_t x_um = mg_div_round_i64(zc_um * right, fq * 4096);
    int64_t y_um = mg_div_round_i64(zc_um * fwd, fq * 4096);
    const int64_t z_um = mg_div_round_i64(zc_um * up, fq * 4096);
    if (x_um > MG_RANGING_MAX_UM_OUT || x_um < -MG_RANGING_MAX_UM_OUT
        || y_um > MG_RANGING_MAX_UM_OUT || y_um < -MG_RANGING_MAX_UM_OUT
        || z_um > MG_RANGING_MAX_UM_OUT || z_um < -MG_RANGING_MAX_UM_OUT)
        return 0;
    /* front surface -> axis along the horizontal ray */
    const int64_t radius_um = mg_div_round_i64((int64_t)width_q4 * d_um, 2 * (int64_t)d_pixel_q4);
    if (radius_um > MG_RANGING_MAX_UM_OUT)
        return 0;
    const int64_t h_um = mg_isqrt64((uint64_t)(x_um * x_um + y_um * y_um));
    if (h_um > 0) {
        x_um += mg_div_round_i64(x_um * radius_um, h_um);
        y_um += mg_div_round_i64(y_um * radius_um, h_um);
    }
    /* waist yaw: theta5 > 0 turns the camera to the right */
    const int64_t s5 = mg_sin_q12(theta5_mrad), c5 = mg_cos_q12(theta5_mrad);
    const int64_t xr = mg_mul_q12_i64(x_um, c5) + mg_mul_q12_i64(y_um, s5);
    const int64_t yr = mg_mul_q12_i64(y_um, c5) - mg_mul_q12_i64(x_um, s5);
    const int64_t dist_um = mg_isqrt64((uint64_t)(xr * xr + yr * yr + z_um * z_um));
    out[0] = (int32_t)mg_div_round_i64(xr, 1000);
    out[1] = (int32_t)mg_div_round_i64(yr, 1000);
    out[2] = (int32_t)mg_div_round_i64(z_um, 1000);
    out[3] = (int32_t)mg_div_round_i64(dist_um, 1000);
    out[4] = mg_atan2_mrad(xr, yr);
    out[5] = (int32_t)mg_div_round_i64(radius_um, 1000);
    return 1;
}
