/* The base drive the states share (host/task/drive.py). */
#include "task_drive.h"

#include "fixedpoint.h"
#include "path_follow.h"
#include "trig.h"

int32_t mg_task_wrap_mrad(int64_t a_mrad)
{
    return (int32_t)(mg_floor_mod(a_mrad + 3142, 6283) - 3142);
}

int mg_close_in(const int32_t obj_q4[2], int32_t grasp_r_mm, int32_t tol_mm,
                int32_t bearing_tol_mrad, int32_t vmax_mmps, int32_t wheels[2],
                mg_close_in_t *d)
{
    const int64_t xr = obj_q4[0], yr = obj_q4[1];
    d->bearing_mrad = mg_atan2_mrad(xr, yr); /* right positive, as theta5 */
    d->dist_mm = (int32_t)(mg_isqrt(xr * xr + yr * yr) >> 4);
    d->err_mm = d->dist_mm - grasp_r_mm;
    const int32_t abs_err = d->err_mm < 0 ? -d->err_mm : d->err_mm;
    const int32_t abs_bearing = d->bearing_mrad < 0 ? -d->bearing_mrad : d->bearing_mrad;
    if (abs_err <= tol_mm && abs_bearing <= bearing_tol_mrad) {
        wheels[0] = wheels[1] = 0;
        return 1;
    }
    int64_t v = 2 * (int64_t)d->err_mm;
    v = v < -vmax_mmps ? -vmax_mmps : v > vmax_mmps ? vmax_mmps : v;
    if (abs_bearing > 4 * (int64_t)bearing_tol_mrad)
        v = 0; /* face the object first */
    /* object to the right -> turn clockwise (negative yaw rate) */
    mg_wheel_speeds((int32_t)v, -2 * d->bearing_mrad, vmax_mmps, &wheels[0], &wheels[1]);
    return 0;
}
