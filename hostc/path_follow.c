/* Path following in time (host/control/path_follow.py): eq. (8) of 000 and Kanayama's law. */
#include "path_follow.h"

#include "div_round.h"
#include "fixedpoint.h"
#include "isqrt.h"

#define HALF_TRACK_MM 150 /* l_w / 2 */

#define TAU_BITS 15
#define COORD_LIMIT (1 << 21)
#define KAPPA_SAT 2147483647LL
#define KAPPA_SCALE 16384000LL /* 16000 * 2^16 >> 6 */
#define V_LIMIT_Q16 ((int64_t)1 << 22) /* 64 m/s */

static int64_t iabs(int64_t v)
{
    return v < 0 ? -v : v;
}

/* num / 2^shift rounded, halves away from zero */
static int64_t half_away(int64_t num, int shift)
{
    const int64_t half = (int64_t)1 << (shift - 1);
    return num >= 0 ? (num + half) >> shift : -((half - num) >> shift);
}

/* position, first and second derivative at tau (Q15) by Horner's rule (eq. (7) of 000) */
static void horner(const int64_t k[4], int64_t tau, int64_t out[3])
{
    out[0] = k[0]
             + ((tau * (k[1] + ((tau * (k[2] + ((tau * k[3]) >> TAU_BITS))) >> TAU_BITS)))
                >> TAU_BITS);
    out[1] = k[1] + ((tau * (2 * k[2] + ((tau * (3 * k[3])) >> TAU_BITS))) >> TAU_BITS);
    out[2] = 2 * k[2] + ((tau * (6 * k[3])) >> TAU_BITS);
}

int mg_trajectory_from_ctrl(const int32_t *ctrl, int32_t n, mg_trajectory_t *out)
{
    out->n = 0;
    if (n < 2 || n > MG_TRAJ_MAX_SAMPLES)
        return -1;
    int64_t k[3][4]; /* eq. (6) of 000 per coordinate */
    for (int c = 0; c < 3; c++) {
        const int64_t p0 = ctrl[c], p1 = ctrl[3 + c], p2 = ctrl[6 + c], p3 = ctrl[9 + c];
        if (iabs(p0) >= COORD_LIMIT || iabs(p1) >= COORD_LIMIT || iabs(p2) >= COORD_LIMIT
            || iabs(p3) >= COORD_LIMIT)
            return -1;
        k[c][0] = p0;
        k[c][1] = 3 * (p1 - p0);
        k[c][2] = 3 * (p0 - 2 * p1 + p2);
        k[c][3] = -p0 + 3 * p1 - 3 * p2 + p3;
    }
    for (int32_t j = 0; j < n; j++) {
        const int64_t tau = ((int64_t)j << TAU_BITS) / (n - 1);
        int64_t x[3], y[3], t[3];
        horner(k[0], tau, x);
        horner(k[1], tau, y);
        horner(k[2], tau, t);
        const int64_t s = mg_isqrt64((uint64_t)(x[1] * x[1] + y[1] * y[1]));
        if (t[1] <= 0 || s == 0)
            return -1;
        const int64_t cross = x[1] * y[2] - x[2] * y[1];
        int64_t kappa = (((iabs(cross) << 6) / s) * KAPPA_SCALE) / (s * s);
        if (kappa > KAPPA_SAT)
            kappa = KAPPA_SAT;
        const int64_t v_q16 = (s << 16) / t[1]; /* m/s Q16 */
        if (v_q16 >= V_LIMIT_Q16)
            return -1;
        const int64_t w = half_away(v_q16 * kappa * 1000, 32); /* mrad/s */
        out->t_us[j] = (int32_t)half_away((t[0] - ctrl[2]) * 125, 1);
        out->x_um[j] = (int32_t)half_away(x[0] * 125, 1);
        out->y_um[j] = (int32_t)half_away(y[0] * 125, 1);
        out->heading_mrad[j] = mg_atan2_mrad(y[1], x[1]);
        out->v_mm_s[j] = (int32_t)mg_div_round_i64(s * 1000, t[1]);
        out->w_mrad_s[j] = (int32_t)(cross >= 0 ? w : -w);
    }
    out->n = n;
    return 0;
}

int32_t mg_wrap_mrad(int64_t a_mrad)
{
    return (int32_t)(mg_floor_mod(a_mrad + 3142, 6283) - 3142);
}

static int32_t lerp(int32_t a, int32_t b, int64_t f_q12)
{
    return (int32_t)(a + (((int64_t)b - a) * f_q12 >> 12));
}

mg_traj_ref_t mg_trajectory_at(const mg_trajectory_t *tr, int64_t t_us, int32_t hint)
{
    const int32_t last = tr->n - 1;
    int32_t i = hint < 0 ? 0 : hint > last - 1 ? last - 1 : hint;
    while (i > 0 && tr->t_us[i] > t_us)
        i--;
    while (i < last - 1 && tr->t_us[i + 1] <= t_us)
        i++;
    const int64_t t_a = tr->t_us[i], t_b = tr->t_us[i + 1];
    mg_traj_ref_t r;
    r.index = i;
    if (t_us >= t_b) {
        r.x_um = tr->x_um[last], r.y_um = tr->y_um[last];
        r.heading_mrad = tr->heading_mrad[last];
        r.v_mm_s = r.w_mrad_s = 0;
        return r;
    }
    /* the Q12 fraction of the segment */
    const int64_t f = (t_us > t_a ? t_us - t_a : 0) * 4096 / (t_b - t_a > 1 ? t_b - t_a : 1);
    const int32_t dh = mg_wrap_mrad((int64_t)tr->heading_mrad[i + 1] - tr->heading_mrad[i]);
    r.x_um = lerp(tr->x_um[i], tr->x_um[i + 1], f);
    r.y_um = lerp(tr->y_um[i], tr->y_um[i + 1], f);
    r.heading_mrad = mg_wrap_mrad(tr->heading_mrad[i] + (dh * f >> 12));
    r.v_mm_s = lerp(tr->v_mm_s[i], tr->v_mm_s[i + 1], f);
    r.w_mrad_s = lerp(tr->w_mrad_s[i], tr->w_mrad_s[i + 1], f);
    return r;
}

void mg_wheel_speeds(int32_t v_mm_s, int32_t w_mrad_s, int32_t limit_mm_s, int32_t *left,
                     int32_t *right)
{
    const int64_t turn = mg_div_round64((int64_t)w_mrad_s * HALF_TRACK_MM, 1000);
    int64_t l = v_mm_s - turn, r = v_mm_s + turn;
    const int64_t limit = limit_mm_s < 0                     ? 0
                          : limit_mm_s > MG_WHEEL_LIMIT_MM_S ? MG_WHEEL_LIMIT_MM_S
                                                             : limit_mm_s;
    const int64_t peak = iabs(l) > iabs(r) ? iabs(l) : iabs(r);
    if (peak > limit) {
        l = mg_div_round64(l * limit, peak);
        r = mg_div_round64(r * limit, peak);
    }
    *left = (int32_t)l;
    *right = (int32_t)r;
}

void mg_path_follower_init(mg_path_follower_t *f, const mg_trajectory_t *traj, int64_t start_us,
                           int32_t v_limit_mm_s, const mg_follow_gains_t *gains,
                           int32_t goal_tol_mm, int64_t overtime_us)
{
    f->traj = traj;
    f->start_us = start_us;
    f->v_limit_mm_s = v_limit_mm_s;
    f->gains = *gains;
    f->goal_tol_mm = goal_tol_mm;
    f->overtime_us = overtime_us;
    f->hint = 0;
    f->steps = 0;
}

mg_wheel_command_t mg_path_follower_step(mg_path_follower_t *f, int64_t t_us,
                                         const mg_pose_t *pose)
{
    f->steps++;
    const int64_t rel = t_us - f->start_us;
    const mg_traj_ref_t ref = mg_trajectory_at(f->traj, rel, f->hint);
    f->hint = ref.index;
    const int64_t dx_mm = mg_div_round64(ref.x_um - pose->x_um, 1000);
    const int64_t dy_mm = mg_div_round64(ref.y_um - pose->y_um, 1000);
    const int64_t c = mg_cos_q12(pose->heading_mrad), s = mg_sin_q12(pose->heading_mrad);
    const int64_t e_x = (c * dx_mm + s * dy_mm) >> 12;  /* along the robot, mm */
    const int64_t e_y = (-s * dx_mm + c * dy_mm) >> 12; /* to the robot's left, mm */
    const int32_t e_th = mg_wrap_mrad((int64_t)ref.heading_mrad - pose->heading_mrad);
    const int64_t err_mm = iabs(dx_mm) > iabs(dy_mm) ? iabs(dx_mm) : iabs(dy_mm);
    const int64_t duration = f->traj->t_us[f->traj->n - 1];
    const int finished = rel >= duration;
    mg_wheel_command_t cmd = {0, 0, 0, (int32_t)err_mm};
    if (finished && (err_mm <= f->goal_tol_mm || rel >= duration + f->overtime_us)) {
        cmd.done = 1;
        return cmd;
    }
    const mg_follow_gains_t *g = &f->gains;
    const int64_t vr = ref.v_mm_s;
    int64_t v = ((vr * mg_cos_q12(e_th)) >> 12) + (((int64_t)g->k_x_q12 * e_x) >> 12);
    int64_t w = ref.w_mrad_s + mg_div_round64(vr * g->k_y_per_m2 * e_y, 1000)
                + ((vr * g->k_theta_per_m * mg_sin_q12(e_th)) >> 12);
    if (finished) { /* past the end: creep to the final point, turning toward it */
        v = ((int64_t)g->k_x_q12 * e_x) >> 12;
        v = v < -60 ? -60 : v > 60 ? 60 : v;
        w = err_mm > 5 ? 2 * mg_atan2_mrad(e_y, iabs(e_x) > 1 ? iabs(e_x) : 1) : 0;
    }
    mg_wheel_speeds((int32_t)v, (int32_t)w, f->v_limit_mm_s, &cmd.left_mm_s, &cmd.right_mm_s);
    return cmd;
}

mg_ops_t mg_path_follow_step_ops(void)
{
    /* path_follow.py STEP_OPS: six 64-bit quotients, four sin/cos, the products */
    const mg_ops_t ops = {0, 0, 1740, 140, 4, 14, 0, 8, 0, 0, 0};
    return ops;
}

mg_ops_t mg_trajectory_ops(int32_t n)
{
    /* path_follow.py SAMPLE_OPS per sample, CURVE_OPS (bezier_q.py CURVE_SETUP_OPS) once */
    const mg_ops_t sample = {0, 0, 1706, 146, 1, 63, 2, 2, 0, 0, 0};
    const mg_ops_t curve = {0, 0, 250, 10, 0, 30, 0, 0, 0, 0, 0};
    return mg_ops_add(mg_ops_scaled(sample, n), curve);
}
