/* Sonar sub-regions and infeasible regions of 001 (eqs. (15)-(16)) in integers
 * (host/planning/sonar_regions.py, whose docstrings give the formulas and bounds). */
#include "sonar_regions.h"

#include "div_round.h"
#include "fixedpoint.h"
#include "trig.h"

#define PI_URAD 3141593
#define TAN_MAX_Q14 ((int64_t)1 << 20)

static int64_t axis_urad(const mg_sonar_cfg_t *cfg, int32_t k)
{
    return mg_div_round_i64((int64_t)(2 * (k - 1) - (cfg->k_s - 1)) * PI_URAD,
                            2 * (int64_t)(cfg->k_s - 1));
}

static int shared(const mg_sonar_cfg_t *cfg, const int64_t *rho, int32_t a, int32_t b)
{
    if (cfg->tol_q4 < 0 || b < 0 || b >= cfg->k_s || rho[a] >= cfg->d_e_q4)
        return 0;
    const int64_t d = rho[a] - rho[b];
    return (d < 0 ? -d : d) <= cfg->tol_q4;
}

int32_t mg_sonar_sub_regions(const mg_sonar_cfg_t *cfg, const int64_t *rho_q4, int64_t *out_lo,
                             int64_t *out_hi, int64_t *out_eta)
{
    int64_t rho[MG_SONAR_MAX], lo[MG_SONAR_MAX], hi[MG_SONAR_MAX];
    const int32_t k_s = cfg->k_s;
    if (k_s < 2 || k_s > MG_SONAR_MAX)
        return 0;
    const int64_t half = cfg->a_g_urad >> 1;
    for (int32_t k = 0; k < k_s; k++) {
        const int64_t r = rho_q4[k];
        rho[k] = r < cfg->d_e_q4 ? (r + cfg->offset_q4 < cfg->d_e_q4 ? r + cfg->offset_q4
                                                                     : cfg->d_e_q4)
                                 : cfg->d_e_q4;
        lo[k] = axis_urad(cfg, k + 1) - half;
        hi[k] = axis_urad(cfg, k + 1) + half;
    }
    if (cfg->a_g_urad * (k_s - 1) <= PI_URAD) { /* the cones do not overlap */
        for (int32_t k = 0; k < k_s; k++) {
            out_lo[k] = lo[k];
            out_hi[k] = hi[k];
            out_eta[k] = rho[k];
        }
        return k_s;
    }
    int32_t n = 0;
    for (int32_t k = 0; k < k_s; k++) {
        out_lo[n] = k > 0 ? hi[k - 1] : lo[k];
        out_hi[n] = k + 1 < k_s ? lo[k + 1] : hi[k];
        out_eta[n] = shared(cfg, rho, k, k - 1) || shared(cfg, rho, k, k + 1) ? cfg->d_e_q4
                                                                              : rho[k];
        n++;
        if (k + 1 < k_s) {
            out_lo[n] = lo[k + 1];
            out_hi[n] = hi[k];
            out_eta[n] = rho[k] > rho[k + 1] ? rho[k] : rho[k + 1];
            n++;
        }
    }
    return n;
}

int32_t mg_sonar_regions(const mg_sonar_cfg_t *cfg, int64_t px_q4, int64_t py_q4,
                         int64_t heading_urad, const int32_t *sonar_mm, mg_region_t *out,
                         int32_t *dropped)
{
    int64_t rho[MG_SONAR_MAX], lo[MG_SONAR_MAX_REGIONS], hi[MG_SONAR_MAX_REGIONS];
    int64_t eta[MG_SONAR_MAX_REGIONS];
    *dropped = 0;
    if (cfg->k_s < 2 || cfg->k_s > MG_SONAR_MAX)
        return 0;
    for (int32_t k = 0; k < cfg->k_s; k++) {
        if (sonar_mm[k] < 0) {
            (*dropped)++;
            rho[k] = cfg->d_e_q4;
        } else {
            rho[k] = (int64_t)sonar_mm[k] * 16;
        }
    }
    const int32_t n_sub = mg_sonar_sub_regions(cfg, rho, lo, hi, eta);
    int32_t n = 0;
    for (int32_t i = 0; i < n_sub; i++) {
        if (eta[i] >= cfg->d_e_q4)
            continue;
        out[n].ox_q4 = px_q4;
        out[n].oy_q4 = py_q4;
        out[n].lo_urad = heading_urad + lo[i];
        out[n].hi_urad = heading_urad + hi[i];
        out[n].eta_q4 = eta[i];
        out[n].r_r_q4 = cfg->r_r_q4;
        out[n].arc_bound = cfg->arc_bound;
        n++;
    }
    return n;
}

static int64_t rot(int64_t r_q4, int64_t c_q14)
{
    return mg_div_round_i64(r_q4 * c_q14, (int64_t)1 << 14);
}

void mg_region_words(const mg_region_t *reg, mg_region_words_t *w)
{
    const int64_t mid = (reg->lo_urad + reg->hi_urad) >> 1;
    const int64_t half = (reg->hi_urad - reg->lo_urad) >> 1;
    int32_t s_m, c_m, s_h, c_h, s_lo, c_lo, s_hi, c_hi;
    mg_sincos_urad_q14(mid, &s_m, &c_m);
    mg_sincos_urad_q14(half, &s_h, &c_h);
    mg_sincos_urad_q14(reg->lo_urad, &s_lo, &c_lo);
    mg_sincos_urad_q14(reg->hi_urad, &s_hi, &c_hi);
    const int64_t eta = reg->eta_q4, r_r = reg->r_r_q4;
    int64_t back = 0;
    if (half <= 0 || s_h <= 0) {
        w->tan_half = -1;
    } else {
        w->tan_half = TAN_MAX_Q14;
        if (c_h > 0) {
            const int64_t t = mg_div_round_i64((int64_t)s_h * (1 << 14), c_h);
            if (t < TAN_MAX_Q14)
                w->tan_half = t;
        }
        back = mg_div_round_i64(r_r * (1 << 14), s_h);
    }
    w->arc = reg->arc_bound && eta > r_r;
    w->cb_pos = 0;
    w->cb2_q16 = (int64_t)1 << 16;
    if (w->arc) {
        const int64_t cb = mg_div_round_i64(
            (int64_t)c_h * mg_isqrt(eta * eta - r_r * r_r) - (int64_t)s_h * r_r, eta);
        w->cb_pos = cb >= 0;
        w->cb2_q16 = (cb * cb + (1 << 11)) >> 12;
    }
    const int64_t ox = reg->ox_q4, oy = reg->oy_q4;
    const int64_t below = eta - r_r > 0 ? eta - r_r : 0;
    w->qx = ox - rot(back, c_m);
    w->qy = oy - rot(back, s_m);
    w->cos_mid = c_m;
    w->sin_mid = s_m;
    w->lo2 = below * below;
    w->hi2 = (eta + r_r) * (eta + r_r);
    w->e1x = ox + rot(eta, c_lo);
    w->e1y = oy + rot(eta, s_lo);
    w->e2x = ox + rot(eta, c_hi);
    w->e2y = oy + rot(eta, s_hi);
    w->mx = ox + rot(eta, c_m);
    w->my = oy + rot(eta, s_m);
}

static void put_words(int64_t *out, const int64_t *words, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        out[i] = words[i];
}

void mg_region_geo(const mg_region_t *reg, int64_t *out)
{
    mg_region_words_t w;
    mg_region_words(reg, &w);
    const int64_t geo[12] = {w.qx,      w.qy,      w.cos_mid, w.sin_mid, w.tan_half, reg->ox_q4,
                             reg->oy_q4, w.lo2,    w.hi2,     w.arc,     w.cb_pos,   w.cb2_q16};
    put_words(out, geo, 12);
}

void mg_region_clear(const mg_region_t *reg, int64_t *out)
{
    mg_region_words_t w;
    mg_region_words(reg, &w);
    const int64_t clear[11] = {reg->ox_q4, reg->oy_q4, w.cos_mid, w.sin_mid, w.tan_half,
                               reg->eta_q4, reg->r_r_q4, w.e1x, w.e1y, w.e2x, w.e2y};
    put_words(out, clear, 11);
}

mg_ops_t mg_region_setup_ops(void)
{
    /* sonar_regions.py REGION_SETUP_OPS: 8 sines, 3 64-bit quotients, one root of 2^32, the
     * products */
    const mg_ops_t ops = {0, 0, 998, 99, 8, 38, 0, 16, 0, 0, 0};
    return ops;
}
