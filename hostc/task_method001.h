/* Paper 001's method (host/task/method001.py): 000's vision and grasp with 001's sonar planning
 * of eq. (17) and its replanning (section III.E) in APPROACH, through the replanner of
 * host/planning/replan.py (a declared interface, mg_replanner001_t: the board's is
 * mg_board_replanner001, replan.c around plan001.c; the tests give scripted ones). Ours, as
 * the Python: the first plan waits for one sonar sweep, the object given and near is looked at
 * first, sightings while the base turns fast are not used, the follower never backs up; the
 * curve is followed to its end on the grasp circle, where ROUGH_GRASP looks back at the object
 * and, the look confirming it, the arm grasps by eq. (11) of 000 from there (look_decides,
 * enter_precise); with no feasible curve the fallbacks (a lower v0, a back-off, the widest
 * free sector, the detours of escape_001, start_detour). */
#ifndef MOBIGRASP_HOSTC_TASK_METHOD001_H
#define MOBIGRASP_HOSTC_TASK_METHOD001_H

#include <stddef.h>
#include <stdint.h>

#include "budget.h"
#include "plan001.h"
#include "replan.h"
#include "task_approach.h"
#include "task_machine.h"
#include "task_method000.h"

enum {
    MG_SIGHTING_MAX_TURN_MRAD_S = 500, /* APPROACH: sightings taken turning faster not used */
    MG_LOOK_FIRST_US = 4000000,        /* P_i given, object near and unseen: look this long */
    MG_LOOK_FIRST_LO_MM = 350,         /* ... when it is this far from the waist */
    MG_LOOK_FIRST_HI_MM = 1200,
    MG_DETOUR_EXTRA_MM = 100,  /* a detour's way out is checked this much beyond its end */
    MG_DETOUR_MARGIN_MM = 100, /* ... against the regions grown by this: it drives open-loop */
    MG_BACK_OFF_MM = 200,      /* fallback: back this far along the way the base came */
    /* SEARCH: away from a radial symbol cut by the frame (method001.py CUT_AWAY_MM,
     * BACK_OFFS_001): face away, drive this far off it, turn back; at most this often a run */
    MG_CUT_AWAY_MM = 400,
    MG_BACK_OFFS_001 = 2,
    /* ... once seen cut in frames this far apart, within a look-around (CUT_WAIT_US,
     * CUT_STALE_US) */
    MG_CUT_WAIT_US = 2000000,
    MG_CUT_STALE_US = 30000000,
    /* ... and with no cut frame: the object never seen, its estimate within this of the axle,
     * the look-around here over (UNSEEN_NEAR_MM) */
    MG_UNSEEN_NEAR_MM = 550,
    /* the grasp from the grasp circle: the look before it must see the object (dual "+")
     * within this of the estimate the base arrived with; the gripper goes down from this far
     * above the grasp point (the first reachable, in 10 mm steps down to the object's top) */
    MG_CIRCLE_CONFIRM_MM = 60,
    MG_CIRCLE_PRE_MM = 50
};

/* one sonar update of the replanner (replan.py ReplanDecision) */
typedef struct {
    int32_t blocked;   /* the rest of the path crosses an infeasible region */
    int32_t replanned; /* a new curve was planned */
    int32_t has_curve; /* a curve to follow from now on (0: stop, nothing feasible) */
    int32_t has_plan;  /* a plan was made (its time charged in slices) */
} mg_replan001_t;

/* 001's replanner as method001.py calls it (start_001, update_001, straight_clear_001, the
 * replanner's start_us); ctx: the replanner and its parameters (planner_params_001) */
typedef struct {
    /* a fresh replanner toward obj_mm, v0 divided by v0_div: its first plan (a path into
     * traj and o, the plan's time in o) */
    void (*start)(void *ctx, int64_t now_us, const mg_task_inputs_t *in, const int32_t obj_mm[2],
                  int32_t v0_div, mg_trajectory_t *traj, mg_plan_outcome_t *o);
    /* the rest of the path checked against fresh sonar, replanned when blocked or force: the
     * decision, its new path (o->has_path: replanned with a curve), reason and ARM9 work */
    void (*update)(void *ctx, int64_t now_us, const mg_task_inputs_t *in, int32_t force,
                   mg_replan001_t *dec, mg_trajectory_t *traj, mg_plan_outcome_t *o,
                   mg_ops_t *ops);
    /* the path and the replanner's curve start now */
    void (*start_path)(void *ctx, int64_t now_us);
    /* the straight travel_mm toward obj_mm misses the infeasible regions of eq. (16) of the
     * present reading and the memory: 1 / 0, its ARM9 work */
    int (*straight_clear)(void *ctx, const mg_task_inputs_t *in, const int32_t obj_mm[2],
                          int32_t travel_mm, mg_ops_t *ops);
    /* the detour's heading (escape_001): the direction nearest the object's bearing whose
     * straight detour_mm + MG_DETOUR_EXTRA_MM keeps out of the present reading's and the
     * memory's regions grown by MG_DETOUR_MARGIN_MM, side as mg_escape_heading_q's: 1 and
     * *heading_mrad, or 0; its ARM9 work */
    int (*escape)(void *ctx, const mg_task_inputs_t *in, const int32_t obj_mm[2],
                  int32_t detour_mm, int32_t side, int32_t *heading_mrad, mg_ops_t *ops);
} mg_replanner001_t;

/* The board's replanner behind mg_replanner001_t (method001.py start_001, update_001,
 * straight_clear_001, escape_001): replan.c around plan001.c, the curve's reference table
 * (MG_PLAN000_TRAJ_SAMPLES samples, path_follow.c). ctx is an mg_board_replanner001_t whose
 * params (v0_mm_s unused: level_v0_mm_s by the slow-down level, divided by v0_div), cfg
 * (target_q4 set by start), level_v0_mm_s and v_limit_mm_s the caller fills. */
#define MG_REPLAN_LEVELS 4
typedef struct {
    mg_params001_t params;
    mg_replan001_cfg_t cfg;
    int32_t level_v0_mm_s[MG_REPLAN_LEVELS]; /* round(v0 slow_factors[level] 1000) */
    int32_t v_limit_mm_s;                    /* the follower's wheel limit, round(Vmax 1000) */
    int32_t v0_div;
    mg_replan001_state_t st;
    mg_plan001_t plan;
    mg_plan001_work_t work;
} mg_board_replanner001_t;
extern const mg_replanner001_t mg_board_replanner001;
/* Python's f"{q4 / 16000:.2f}" (the block's distance in the replanner's reason), 0 <= q4 <
 * 2^40, appended at at; the new end */
size_t mg_method001_text_m_2(char *out, size_t cap, size_t at, int64_t q4);

/* What 001 keeps between steps (the task's ms, State001). */
typedef struct {
    const mg_replanner001_t *rp; /* the replanner's calls (NULL: none, every plan fails) */
    void *rp_ctx;
    int32_t has_replanner;         /* a replanner was started (ms.replanner not None) */
    int32_t has_path_from, path_from_mm[2]; /* where the last planned path began */
    int32_t v0_div;                /* the planner's v0 divided by this (a fallback step) */
    int32_t fallbacks, detours, detour_side;
    /* arrived on the grasp circle: the estimate the look before the grasp is to confirm,
     * and the circle's radius l_e */
    int32_t has_circle_expected, circle_expected_mm[2], circle_l_e_mm;
    int32_t circle_adjusts; /* ... and the grasp's close-ins then (t->sight_adjusts) */
    int32_t ik_grasp;       /* PRECISE_GRASP goes down by eq. (11), no spoke alignment */
    int32_t has_l_e, l_e_mm; /* l_e of eq. (5) for grasp_height_mm, once computed (0: none) */
    mg_detour_t detour; /* a drive aside before the next plan (a fallback's, the guard's) */
    mg_cut_back_off_t cut; /* the move off a cut symbol (search_back_off) */
} mg_state001_t;

void mg_method001_ms_init(void *ms);
void mg_method001_params(mg_task_params_t *p);
/* the replanner's calls and context; with them l_e of eq. (5) for the task's grasp height
 * (the grasp circle's radius, its note at the arrival), computed here, at start-up */
void mg_method001_set_replanner(mg_task_t *t, const mg_replanner001_t *rp, void *ctx);
/* the object given and near, unseen: the camera on it, the base turned to face it for up to
 * MG_LOOK_FIRST_US before the first plan; 1 while looking */
int mg_method001_look_first(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* SEARCH: the radial symbol cut by the frame, wherever it is seen, or the object never seen
 * with its estimate within MG_UNSEEN_NEAR_MM once the look-around there is over: face away,
 * drive MG_CUT_AWAY_MM off it, the sonars watching, turn back and look around again
 * (method001.py search_back_off, back_off_first, back_off_move); 1 while it takes the step */
int mg_method001_search_back_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* 001's last gate of the wheels (method001.py guard_wheels): the close guard, and in SEARCH
 * or APPROACH a front echo below R_r stops the base and drops the path; in APPROACH the base
 * then turns toward the widest free sector and drives out of R_r (ms detour, driven before
 * the next plan) */
void mg_method001_guard_wheels(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* the counts charged by 001's task each step: a step along the path (method001.py FOLLOW_OPS),
 * one sonar looked at by the guard (GUARD_SONAR_OPS) */
mg_ops_t mg_method001_follow_ops(void);
mg_ops_t mg_method001_guard_sonar_ops(void);
/* ROUGH_GRASP after its look from the grasp circle (method001.py look_decides): the object
 * seen (dual "+") within MG_CIRCLE_CONFIRM_MM of where the base expected it and its grasp
 * point reachable by eq. (11) of 000 (gripper down): the gripper above the grasp point, the
 * descent next (1); else ADJUST and 000's precise grasp from here (1); 0 without an arrival
 * on the circle (the common rule) */
int mg_method001_look_decides(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* PRECISE_GRASP's entry: after the confirmed look, straight down to the grasp point and close
 * (grasp_close "ik"); else 000's roll and spoke alignment */
void mg_method001_enter_precise(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* the path hooks of 001 */
extern const mg_path_method_t mg_path001;

#endif
