/* The path update of 001 section III.E (host/planning/replan.py Replanner), the replanner's own
 * part around the plan: the regions remembered from earlier (re)plans and forgotten once the
 * sonars see their place again, the echoes of the object left out, the rest of the present
 * curve checked against the fresh reading and the memory (blocked_q.c), the slow-down level,
 * and what follows a plan (the new curve, no curve, or the old curve kept while the block is
 * far). The plan itself (plan_001) is the caller's: mg_replan001_check says whether one is
 * needed, mg_replan001_after_plan takes its outcome. Positions in 1/16 mm, headings in mrad,
 * control points as blocked_q.h's (12 words). Fixed capacities, no allocation, no float. */
#ifndef MG_REPLAN_H
#define MG_REPLAN_H

#include <stdint.h>

#include "budget.h"
#include "sonar_regions.h"

#define MG_REPLAN_MEMORY 16 /* remembered regions at most (Replanner memory) */

/* Replanner's configuration in integers */
typedef struct {
    mg_sonar_cfg_t sonar;
    int64_t target_q4[2];
    int64_t echo_tol_q4;   /* Params001.object_echo_tol_m */
    int32_t memory;        /* <= MG_REPLAN_MEMORY */
    int32_t check_samples; /* samples of the rest of the curve (m >= 2) */
    int32_t n_levels;      /* slow_factors */
    int64_t keep_going_q4;
} mg_replan001_cfg_t;

typedef struct {
    mg_region_t memory[MG_REPLAN_MEMORY]; /* oldest first */
    int32_t n_memory;
    int32_t level; /* index into slow_factors of the next plan's v0 */
    int32_t has_curve;
    int32_t ctrl[12];
    int64_t start_us, old_start_us;
    int32_t replans;
} mg_replan001_state_t;

/* a sonar update's check (the part of Replanner.update before the plan) */
typedef struct {
    int32_t blocked;   /* the rest of the curve enters a region */
    int64_t where[2];  /* its first sample inside (when blocked) */
    mg_ops_t ops;      /* the check's ARM9 cost */
} mg_replan001_check_t;

/* what follows a plan (ReplanDecision) */
enum { MG_REPLAN_NEW = 0, MG_REPLAN_STOP = 1, MG_REPLAN_KEPT = 2 };
/* why a plan was made: "blocked", "no path" (none before), "path dropped" (forced) */
enum { MG_REPLAN_WHY_BLOCKED = 0, MG_REPLAN_WHY_NO_PATH = 1, MG_REPLAN_WHY_DROPPED = 2 };

void mg_replan001_init(mg_replan001_state_t *st);
/* is_object_echo: the region's echo arc passes within echo_tol of the target */
int mg_replan001_object_echo(const mg_replan001_cfg_t *cfg, const mg_region_t *reg);
/* the regions of a reading (sonar_mm, k_s of them) less the object's echoes; their number */
int32_t mg_replan001_fresh(const mg_replan001_cfg_t *cfg, int64_t px_q4, int64_t py_q4,
                           int32_t heading_mrad, const int32_t *sonar_mm, mg_region_t *out);
/* forget_seen: the remembered regions whose echo's middle the ring sees again; how many */
int32_t mg_replan001_forget_seen(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st,
                                 int64_t px_q4, int64_t py_q4, int32_t heading_mrad);
/* first_blocked_q4: the first point of the rest of the curve (after t_us) inside any of the
 * n regions: 1 and where, or 0; *ops the test's cost with the regions' words */
int mg_replan001_first_blocked(const mg_replan001_cfg_t *cfg, const mg_replan001_state_t *st,
                               int64_t t_us, const mg_region_t *regions, int32_t n,
                               int64_t where[2], mg_ops_t *ops);
/* the check of update: forget, the fresh reading's regions less the object's echoes, the
 * curve against them and the memory; returns 1 when a plan is to be made (no curve, blocked
 * or force), 0: the path is clear */
int mg_replan001_check(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st, int64_t t_us,
                       int64_t px_q4, int64_t py_q4, int32_t heading_mrad,
                       const int32_t *sonar_mm, int force, mg_replan001_check_t *chk);
/* a plan made at t_us (start: level 0 first): the fresh reading's regions (not the object's
 * echoes, not already remembered) remembered, the level stepped, the plan's curve (has_best:
 * best_ctrl) taken from t_us */
void mg_replan001_adopt(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st, int64_t t_us,
                        int64_t px_q4, int64_t py_q4, int32_t heading_mrad,
                        const int32_t *sonar_mm, int has_best, const int32_t *best_ctrl);
/* start_path: the present curve starts at t_us (its plan charged in slices) */
void mg_replan001_start_path(mg_replan001_state_t *st, int64_t t_us);
/* the rest of update after mg_replan001_check asked for a plan: adopt it, then the decision
 * (MG_REPLAN_*), *why (MG_REPLAN_WHY_*), *ahead_q4 the block's distance (-1: none) */
int mg_replan001_after_plan(const mg_replan001_cfg_t *cfg, mg_replan001_state_t *st,
                            int64_t t_us, int64_t px_q4, int64_t py_q4, int32_t heading_mrad,
                            const int32_t *sonar_mm, const mg_replan001_check_t *chk,
                            int has_best, const int32_t *best_ctrl, int32_t *why,
                            int64_t *ahead_q4);

#endif
