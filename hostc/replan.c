/* The path update of 001 section III.E, the replanner's own part around the plan
 * (host/planning/replan.py Replanner: forget_seen, first_blocked_q4, update, _plan). */
#include "replan.h"

#include "bezier.h"
#include "blocked_q.h"
#include "fixedpoint.h"
#include "kernels.h"
#include "trig.h"

#define MAX_TESTED (MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY)

/* replan.py FORGET_OPS: one remembered region's test */
static const mg_ops_t FORGET = {0, 0, 10, 3, 0, 6, 0, 0, 0, 0, 0};

void mg_replan001_init(mg_replan001_state_t *st)
{
    st->n_memory = 0;
    st->level = 0;
    st->has_curve = 0;
    for (int w = 0; w < 12; w++)
        st->ctrl[w] = 0;
    st->start_us = st->old_start_us = 0;
    st->replans = 0;
}

int mg_replan001_object_echo(const mg_replan001_cfg_t *cfg, const mg_region_t *reg)
{
    int64_t words[MG_CLEAR_WORDS];
    mg_region_clear(reg, words);
    const int64_t d = mg_path_clearance(words, 1, &cfg->target_q4[0], &cfg->target_q4[1], 1);
    return d + reg->r_r_q4 <= cfg->echo_tol_q4;
}

int32_t mg_replan001_forget_seen(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st,
                                 int64_t px_q4, int64_t py_q4, int32_t heading_mrad)
{
    const int64_t s = mg_sin_q12(heading_mrad), c = mg_cos_q12(heading_mrad);
    const int64_t d_e2 = cfg->sonar.d_e_q4 * cfg->sonar.d_e_q4;
    int32_t kept = 0;
    for (int32_t i = 0; i < st->n_memory; i++) {
        mg_region_words_t w;
        mg_region_words(&st->memory[i], &w);
        const int64_t ax = w.mx - px_q4, ay = w.my - py_q4;
        const int64_t along = ax * c + ay * s;
        int64_t across = ay * c - ax * s;
        if (across < 0)
            across = -across;
        /* the ring's span pi/2 + A_g/2 about the heading (wider than pi/2) */
        const int within_span = !(along < 0 && across * 4096 < -along * cfg->sonar.cot_half_q12);
        if (!(ax * ax + ay * ay < d_e2 && within_span))
            st->memory[kept++] = st->memory[i];
    }
    const int32_t dropped = st->n_memory - kept;
    st->n_memory = kept;
    return dropped;
}

int mg_replan001_first_blocked(const mg_replan001_cfg_t *cfg, const mg_replan001_state_t *st,
                               int64_t t_us, const mg_region_t *regions, int32_t n,
                               int64_t where[2], mg_ops_t *ops)
{
    static const mg_ops_t none;
    int64_t geo[MG_GEO_HEAD + MG_REGION_WORDS * MAX_TESTED];
    *ops = none;
    if (!st->has_curve || n <= 0 || n > MAX_TESTED)
        return 0;
    geo[0] = geo[1] = geo[2] = 0;
    for (int32_t r = 0; r < n; r++)
        mg_region_geo(&regions[r], geo + MG_GEO_HEAD + MG_REGION_WORDS * r);
    const int64_t t_q4 = st->ctrl[2] + mg_floor_div((t_us - st->start_us) * 16000, 1000000);
    const int32_t tau0 = mg_tau_at_time_q15(st->ctrl, t_q4);
    const int hit = mg_first_blocked_q(st->ctrl, tau0, cfg->check_samples, geo, n, where, ops);
    *ops = mg_ops_add(*ops, mg_ops_scaled(mg_region_setup_ops(), n));
    return hit;
}

int32_t mg_replan001_fresh(const mg_replan001_cfg_t *cfg, int64_t px_q4, int64_t py_q4,
                           int32_t heading_mrad, const int32_t *sonar_mm, mg_region_t *out)
{
    mg_region_t scan[MG_SONAR_MAX_REGIONS];
    int32_t dropped = 0, n = 0;
    const int32_t n_scan = mg_sonar_regions(&cfg->sonar, px_q4, py_q4,
                                            (int64_t)heading_mrad * 1000, sonar_mm, scan,
                                            &dropped);
    for (int32_t i = 0; i < n_scan; i++)
        if (!mg_replan001_object_echo(cfg, &scan[i]))
            out[n++] = scan[i];
    return n;
}

int mg_replan001_check(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st, int64_t t_us,
                       int64_t px_q4, int64_t py_q4, int32_t heading_mrad,
                       const int32_t *sonar_mm, int force, mg_replan001_check_t *chk)
{
    mg_region_t tested[MAX_TESTED];
    const int32_t n_mem = st->n_memory;
    mg_replan001_forget_seen(cfg, st, px_q4, py_q4, heading_mrad);
    int32_t n = mg_replan001_fresh(cfg, px_q4, py_q4, heading_mrad, sonar_mm, tested);
    for (int32_t i = 0; i < st->n_memory; i++)
        tested[n++] = st->memory[i];
    chk->where[0] = chk->where[1] = 0;
    chk->blocked = mg_replan001_first_blocked(cfg, st, t_us, tested, n, chk->where, &chk->ops);
    chk->ops = mg_ops_add(chk->ops, mg_ops_scaled(FORGET, n_mem));
    if (n_mem)
        chk->ops.luts += 2;
    return !st->has_curve || chk->blocked || force;
}

static int same_region(const mg_region_t *a, const mg_region_t *b)
{
    return a->ox_q4 == b->ox_q4 && a->oy_q4 == b->oy_q4 && a->lo_urad == b->lo_urad
        && a->hi_urad == b->hi_urad && a->eta_q4 == b->eta_q4 && a->r_r_q4 == b->r_r_q4
        && a->arc_bound == b->arc_bound;
}

void mg_replan001_adopt(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st, int64_t t_us,
                        int64_t px_q4, int64_t py_q4, int32_t heading_mrad,
                        const int32_t *sonar_mm, int has_best, const int32_t *best_ctrl)
{
    mg_region_t fresh[MG_SONAR_MAX_REGIONS];
    const int32_t n = mg_replan001_fresh(cfg, px_q4, py_q4, heading_mrad, sonar_mm, fresh);
    const int32_t cap = cfg->memory < MG_REPLAN_MEMORY ? cfg->memory : MG_REPLAN_MEMORY;
    for (int32_t i = 0; i < n && cap > 0; i++) {
        int known = 0;
        for (int32_t j = 0; j < st->n_memory && !known; j++)
            known = same_region(&fresh[i], &st->memory[j]);
        if (known)
            continue;
        if (st->n_memory == cap) { /* the oldest forgotten first */
            for (int32_t j = 1; j < cap; j++)
                st->memory[j - 1] = st->memory[j];
            st->n_memory--;
        }
        st->memory[st->n_memory++] = fresh[i];
    }
    /* ours, not 001: no feasible curve -> the next plan slower; a success one step faster */
    if (!has_best)
        st->level = st->level + 1 < cfg->n_levels ? st->level + 1 : cfg->n_levels - 1;
    else if (st->level > 0)
        st->level--;
    st->old_start_us = st->start_us;
    st->has_curve = has_best != 0;
    for (int w = 0; w < 12; w++)
        st->ctrl[w] = has_best ? best_ctrl[w] : 0;
    st->start_us = t_us;
}

void mg_replan001_start_path(mg_replan001_state_t *st, int64_t t_us)
{
    st->start_us = t_us;
}

int mg_replan001_after_plan(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st,
                            int64_t t_us, int64_t px_q4, int64_t py_q4, int32_t heading_mrad,
                            const int32_t *sonar_mm, const mg_replan001_check_t *chk,
                            int has_best, const int32_t *best_ctrl, int32_t *why,
                            int64_t *ahead_q4)
{
    int32_t old[12];
    const int had_curve = st->has_curve;
    for (int w = 0; w < 12; w++)
        old[w] = st->ctrl[w];
    mg_replan001_adopt(cfg, st, t_us, px_q4, py_q4, heading_mrad, sonar_mm, has_best,
                       best_ctrl);
    st->replans++;
    *ahead_q4 = -1;
    if (chk->blocked) {
        const int64_t dx = chk->where[0] - px_q4, dy = chk->where[1] - py_q4;
        *ahead_q4 = mg_isqrt(dx * dx + dy * dy);
    }
    *why = chk->blocked ? MG_REPLAN_WHY_BLOCKED
                        : had_curve ? MG_REPLAN_WHY_DROPPED : MG_REPLAN_WHY_NO_PATH;
    if (!has_best && had_curve && *ahead_q4 > cfg->keep_going_q4) {
        /* ours: the block is far, keep the path and look again at the next reading */
        st->has_curve = 1;
        for (int w = 0; w < 12; w++)
            st->ctrl[w] = old[w];
        st->start_us = st->old_start_us;
        return MG_REPLAN_KEPT;
    }
    return has_best ? MG_REPLAN_NEW : MG_REPLAN_STOP;
}
