/* The fuzzy controller of 002 section 3.1 (host/control/fuzzy.py). */
#include "fuzzy.h"

#include "fixedpoint.h"

#define Q12 4096
#define E_RANGE (3 * Q12)  /* x_e in [-12288, 12288] */
#define EC_RANGE (2 * Q12) /* x_ec in [-8192, 8192] */

/* Table 1 of 002: rows E_c = NB, NS, Z, PS, PB; columns E = NB .. PB; entries the U sets
 * NB .. PB as 0 .. 6 */
static const int8_t rules[5][7] = {
    {0, 0, 1, 1, 3, 4, 5},
    {0, 1, 2, 2, 3, 4, 5},
    {0, 1, 2, 3, 4, 5, 6},
    {1, 2, 3, 3, 4, 5, 6},
    {2, 2, 3, 4, 4, 5, 6},
};

static int32_t clamp(int64_t v, int32_t lim)
{
    return (int32_t)(v < -lim ? -lim : v > lim ? lim : v);
}

void mg_fuzzy_controller_init(mg_fuzzy_controller_t *c, const mg_fuzzy_params_t *p)
{
    c->p = *p;
    c->no_rule_fired = 0;
}

void mg_fuzzy_quantise(const mg_fuzzy_controller_t *c, int32_t e_mrad, int64_t ec_mrad_s,
                       int32_t *x_e, int32_t *x_ec)
{
    *x_e = clamp(mg_div_round64((int64_t)e_mrad * E_RANGE, c->p.e_th_mrad), E_RANGE);
    *x_ec = clamp(mg_div_round64(ec_mrad_s * EC_RANGE, c->p.e_cth_mrad_s), EC_RANGE);
}

/* the membership in Q12 of set j of n (peaks at multiples of 4096, centred on the middle) */
static int32_t membership(int32_t x, int32_t j, int32_t n)
{
    const int32_t d = x - (j - n / 2) * Q12;
    return Q12 - (d < 0 ? -d : d);
}

int32_t mg_fuzzy_infer_q12(mg_fuzzy_controller_t *c, int32_t x_e, int32_t x_ec)
{
    int64_t num = 0, den = 0;
    for (int32_t k = 0; k < 5; k++) {
        const int32_t mu_ec = membership(x_ec, k, 5);
        if (mu_ec <= 0)
            continue;
        for (int32_t j = 0; j < 7; j++) {
            const int32_t mu_e = membership(x_e, j, 7);
            if (mu_e <= 0)
                continue;
            const int32_t w = mu_e < mu_ec ? mu_e : mu_ec; /* AND = min */
            num += (int64_t)(rules[k][j] - 3) * w;         /* b_h = (h - 3) / 3 */
            den += w;
        }
    }
    if (den == 0) {
        c->no_rule_fired++;
        return 0;
    }
    return (int32_t)mg_div_round64(num * Q12, 3 * den); /* eq. (1): the centroid */
}

int32_t mg_fuzzy_u_mrad(mg_fuzzy_controller_t *c, int32_t e_mrad, int64_t ec_mrad_s)
{
    int32_t x_e, x_ec;
    mg_fuzzy_quantise(c, e_mrad, ec_mrad_s, &x_e, &x_ec);
    const int32_t u_q12 = mg_fuzzy_infer_q12(c, x_e, x_ec);
    return (int32_t)mg_div_round64((int64_t)u_q12 * c->p.u_th_mrad, Q12); /* u = u_q / k_u */
}

void mg_fuzzy_wheels_mm_s(const mg_fuzzy_controller_t *c, int32_t u_mrad, int32_t *left,
                          int32_t *right)
{
    /* eq. (2) of 002: v_r = 2 V_avg / (2 + k_uc u), v_l = 2 V_avg - v_r */
    const int64_t v = c->p.v_avg_mm_s;
    const int64_t k_u = mg_div_round64((int64_t)c->p.k_uc_q12 * u_mrad, 1000);
    const int64_t v_r = mg_div_round64(2 * v * Q12, 2 * Q12 + k_u);
    *left = (int32_t)(2 * v - v_r);
    *right = (int32_t)v_r;
}

void mg_fuzzy_approach_init(mg_fuzzy_approach_t *a, const mg_fuzzy_params_t *p)
{
    mg_fuzzy_controller_init(&a->ctl, p);
    a->has_prev = 0;
    a->prev_t_us = 0;
    a->prev_e_mrad = 0;
}

mg_fuzzy_command_t mg_fuzzy_approach_step(mg_fuzzy_approach_t *a, int64_t t_us, int32_t has_e,
                                          int32_t e_mrad, int32_t has_d_pixel,
                                          int32_t d_pixel)
{
    mg_fuzzy_command_t cmd = {0, 0, 0, 0};
    if (has_d_pixel && d_pixel > a->ctl.p.t_d_px) {
        cmd.stop = 1; /* the rings more than T_d apart: at the grasp distance (002 section 4) */
        return cmd;
    }
    if (!has_e) {
        a->has_prev = 0;
        return cmd;
    }
    int64_t ec = 0;
    if (a->has_prev && t_us > a->prev_t_us)
        ec = mg_div_round64(((int64_t)e_mrad - a->prev_e_mrad) * 1000000,
                            t_us - a->prev_t_us);
    a->has_prev = 1, a->prev_t_us = t_us, a->prev_e_mrad = e_mrad;
    cmd.u_mrad = mg_fuzzy_u_mrad(&a->ctl, e_mrad, ec);
    mg_fuzzy_wheels_mm_s(&a->ctl, cmd.u_mrad, &cmd.left_mm_s, &cmd.right_mm_s);
    return cmd;
}

mg_ops_t mg_fuzzy_eval_ops(void)
{
    const mg_ops_t ops = {0, 0, 60, 20, 6, 0, 3, 0, 0, 0, 0};
    return ops;
}
