/* Paper 000's method (host/task/method000.py): the radial symbol found in SEARCH, the Bezier
 * path of eq. (9) followed in APPROACH (task_approach.c), the dual "+" closed in on in ADJUST,
 * the gripper down of eq. (11), the search after a loss near the object (Fig. 5 with the
 * paper's d_theta2). */
#ifndef MOBIGRASP_HOSTC_TASK_METHOD000_H
#define MOBIGRASP_HOSTC_TASK_METHOD000_H

#include <stddef.h>
#include <stdint.h>

#include "json.h"
#include "kinematics.h"
#include "plan000.h"
#include "search.h"
#include "task_approach.h"
#include "task_machine.h"

#define MG_MAX_TRACE_CANDIDATES 40 /* candidate curves kept in the plan's trace detail */
/* SEARCH's back-off from the radial symbol cut by the frame's border (method000.py
 * BACK_OFF_000_MM, BACK_OFF_FROM_MM, BACK_OFFS_000) and its phases: 000 turns toward it and
 * backs off (TURN, BACK), 001 faces away, drives off and turns back (AWAY, FACE), then both
 * LOOK */
#define MG_BACK_OFF_000_MM 150
#define MG_BACK_OFF_FROM_MM 40
#define MG_BACK_OFFS_000 1
/* SEARCH: a wander leg stopped short within this long of a frame of the symbol cut by the
 * frame's bottom, at least MG_CUT_LOOK_FLAT times wider than high, faces where it was seen and
 * looks there (method000.py CUT_LOOK_000_US, CUT_LOOK_FLAT) */
#define MG_CUT_LOOK_000_US 3000000
#define MG_CUT_LOOK_FLAT 3
/* SEARCH's wander of 000 (method000.py WANDER_000_MMPS and the rest) */
#define MG_WANDER_000_MMPS 350
#define MG_WANDER_D_THETA5_000_MRAD 350
#define MG_OUTWARD_FROM_000_MM 3000
#define MG_SIGHTING_APPROACH_000_MM 850
#define MG_ROUND_TRIES_000 2
#define MG_OUTWARD_INWARD_000_MRAD 1050
#define MG_EDGE_000_MM 900
enum {
    MG_BACK_OFF000_NONE,
    MG_BACK_OFF000_TURN,
    MG_BACK_OFF000_BACK,
    MG_BACK_OFF000_LOOK,
    MG_BACK_OFF_AWAY,
    MG_BACK_OFF_FACE
};
/* The back-off's state (State000's and State001's back_offs, back_off): the phase; TURN (a:
 * heading_from, b: turn_mrad), BACK (a, b: where it started, mm), AWAY (leg: the drive away,
 * b: the heading toward the symbol), FACE (leg: the turn back), LOOK (stopped_us) */
typedef struct {
    int32_t back_offs; /* back-offs from a cut symbol made in the run */
    int32_t phase, a, b;
    int64_t stopped_us;
    mg_detour_t leg;
    /* the first frame of the cut symbol not yet moved off (a rule with wait_us only) */
    int32_t has_cut_first;
    int64_t cut_first_us;
    /* the last frame of the symbol cut by the frame's bottom, flat, and the odometry heading it
     * was seen in */
    int32_t has_cut_seen, cut_heading_mrad;
    int64_t cut_seen_us;
} mg_cut_back_off_t;
/* How a method backs off (method000.py / method001.py back_offs_max, back_off_here,
 * back_off_due, back_off_first): at most max a run; from_start: only from the run's start
 * (000); wait_us > 0: at a frame of the cut symbol wait_us or more after the first, within
 * stale_us (001), 0: at the first (000); away_mm > 0: face away and drive this far off, the
 * sonars watching, then turn back (001); 0: turn toward it and back straight off
 * MG_BACK_OFF_000_MM (000) */
typedef struct {
    int32_t max, from_start;
    int64_t wait_us, stale_us;
    int32_t away_mm;
} mg_back_off_rule_t;

/* What 000's planner is asked (method000.py plan_follower): the pose and speed, the object's
 * estimate, the stand-off of P3 (approach_standoff_mm) */
typedef struct {
    int64_t now_us;
    int32_t x_mm, y_mm, heading_mrad, v_mmps;
    int32_t obj_mm[2];
    int32_t standoff_mm;
} mg_plan000_request_t;
/* 000's planner: eqs. (4)-(9) of 000 from the request (the candidates of bezier000.c), the
 * best curve's reference table into traj, the outcome into o; ctx: its own parameters */
typedef void (*mg_planner000_fn)(void *ctx, const mg_plan000_request_t *req,
                                 mg_trajectory_t *traj, mg_plan_outcome_t *o);

/* The board's planner behind mg_planner000_fn (plan000.c, method000.py plan_follower):
 * Params000 in integers (its stand-off replaced by the request's), the follower's wheel limit
 * (the plan's Vmax, mm/s) and the planner's state; ctx of mg_method000_plan000 */
typedef struct {
    mg_params000_t params;
    int32_t v_limit_mm_s;
    mg_planner000_t pl;
} mg_plan000_ctx_t;
/* 000's plan of eqs. (4)-(9) of 000 for the request: the best curve's reference table, the
 * plan's and the table's modelled time, the reason as plan_000 gives it ("ok", "already
 * within standoff of the object", "no feasible candidate (accel: 3, speed: 10)") */
void mg_method000_plan000(void *ctx, const mg_plan000_request_t *req, mg_trajectory_t *traj,
                          mg_plan_outcome_t *o);

/* What 000 keeps between steps (the task's ms, State000), and the planner its APPROACH plans
 * with (NULL: none, every plan fails "no planner") */
typedef struct {
    int32_t grasp_searches; /* searches after a loss in PRECISE_GRASP (grasp_lost) */
    mg_cut_back_off_t cut; /* the back-off from a cut symbol (search_back_off) */
    mg_planner000_fn planner;
    void *planner_ctx;
    int32_t board_planner; /* the planner is the board's: its plan's detail is noted */
} mg_state000_t;

void mg_method000_ms_init(void *ms);
void mg_method000_params(mg_task_params_t *p);
void mg_method000_set_planner(mg_task_t *t, mg_planner000_fn planner, void *ctx);
/* the board's planner (mg_method000_plan000 on ctx), its plans' trace detail noted as
 * method000.py plan_follower gives it */
void mg_method000_set_board_planner(mg_task_t *t, mg_plan000_ctx_t *ctx);
/* SEARCH: the radial symbol's sighting (an mg_sighting_t: its glue's pixel and depth) updates
 * the estimate; 1 when usable */
int mg_method000_found(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       const void *radial);
/* SEARCH: the radial symbol cut by the frame's border at the run's start: turn toward it, back
 * off MG_BACK_OFF_000_MM, look around again (method000.py search_back_off); 1 while the
 * back-off takes the step */
int mg_method000_search_back_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* SEARCH: a wander leg stopped short by an obstacle within MG_CUT_LOOK_000_US of a frame of
 * the cut symbol (it may be the object): 1 and the odometry heading to face to look there
 * (method000.py search_cut_look); 0: the next station */
int mg_method000_search_cut_look(const mg_task_t *t, int64_t now_us, int32_t *heading_mrad);
/* The back-off of either method (method000.py Method000.search_back_off with the method's
 * hooks): the state bo, the method's rule; 1 while the back-off takes the step */
int mg_search_back_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       mg_cut_back_off_t *bo, const mg_back_off_rule_t *rule);
/* 001's move off (method001.py back_off_first): bo's phase AWAY, facing away from what lies
 * turn_mrad (left positive) off the heading and driving away_mm, then FACE it again */
void mg_back_off_away(mg_cut_back_off_t *bo, const mg_task_inputs_t *in, int32_t turn_mrad,
                      int32_t away_mm);
/* the reason of SEARCH's transition to APPROACH, into why (cap bytes) */
void mg_method000_found_why(const mg_task_t *t, char *why, size_t cap);
/* SEARCH after a loss near the object (000 section III.B.2, III.C): the search's parameters
 * sp changed in place (at least one dense cycle) and its start: theta2s giving the camera the
 * pitch it had, in the search posture, and the waist where it was; 1 */
int mg_method000_lost_search(mg_task_t *t, mg_search_params_t *sp, int32_t *theta2s_mrad,
                             int32_t *theta5s_mrad);
/* PRECISE_GRASP saw no spoke for waited_us at the hover: the first time in a run the object
 * is searched for (LOST, the transition made; 1), after that the grasp goes down on the rough
 * position (0) */
int mg_method000_grasp_lost(mg_task_t *t, int64_t now_us, int64_t waited_us);
/* the gripper down, eq. (11) of 000: MG_IK_OK and *pose, or the reason and *detail */
int32_t mg_method000_grasp_ik(const mg_arm_geometry_t *g, const int32_t target_q4[3],
                              mg_arm_pose_t *pose, int64_t *detail);
int mg_method000_lowers_hover(void);
int32_t mg_method000_look_height_mm(const mg_task_params_t *p, int32_t top);
int mg_method000_adjust_done(mg_task_t *t, int64_t now_us, const void *det, int32_t dist_mm);
/* Method.adjust_goal_mm's default: grasp_r_mm +- grasp_r_tol_mm */
void mg_method000_adjust_goal_mm(const mg_task_t *t, int32_t *goal_mm, int32_t *tol_mm);
int32_t mg_method000_adjust_vmax_mmps(const mg_task_params_t *p);
/* APPROACH: its entry (the path approach's common one, 000 adds nothing) and its step */
void mg_method000_enter_approach(mg_task_t *t);
void mg_method000_approach(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                           const mg_sighting_t *radial);
/* One vision job's results as 000's hooks read them (app_factory.h mg_frame000_of). */
typedef struct {
    int32_t has_frame;
    int32_t has_radial;
    mg_sighting_t radial;
    int32_t has_plus;
    mg_plus_seen_t plus;
    int32_t has_spoke, spoke_angle_mrad, spoke_width_px;
    int32_t has_held_fill, held_rgb[3], held_permille;
    int32_t has_cut, cut_side; /* the radial symbol cut by the frame's border: its side */
    int32_t cut_low_px, cut_w_px, cut_h_px; /* ... and its box's lower edge (y + h), size */
} mg_frame000_t;

/* The method row's hooks on the step's inputs (in->frame: an mg_frame000_t or NULL). */
void mg_method000_frame_of(const mg_task_t *t, const int32_t *const *words, void *frame);
/* SEARCH: this frame's radial symbol (an mg_sighting_t); 0: none */
int mg_method000_search_sighting(const mg_task_t *t, const mg_task_inputs_t *in, void *sighting);
void mg_method000_enter_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_method000_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* this frame's dual "+" (an mg_plus_seen_t) and radial symbol; NULL: none */
const void *mg_method000_plus_result(const mg_task_inputs_t *in);
const void *mg_method000_radial_check(const mg_task_inputs_t *in);
const mg_sighting_t *mg_method000_radial_result(const mg_task_inputs_t *in);
/* ROUGH_GRASP: hover_mm above the object's top; over the nearer "+" when both are known, the
 * grasp itself on the axis (the task's grasp_xy_q4) */
void mg_method000_rough_target(mg_task_t *t, const mg_task_inputs_t *in, int32_t target_q4[3]);
/* PRECISE_GRASP's entry: the roll to pi/2 (000 section III.C.2), then the alignment */
void mg_method000_enter_precise(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
int mg_method000_spoke_reading(const mg_task_inputs_t *in, int32_t *angle_mrad,
                               int32_t *width_px);
/* the 000 object's brown body (host/vision/held_fill.py body_brown) */
int mg_method000_body_brown(const int32_t rgb[3]);
int mg_method000_held_in_view(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);

/* the path hooks of 000: plans once (again when the estimate moves), no sonar check, no
 * detour, the follower's wheels as they are */
extern const mg_path_method_t mg_path000;

/* a curve's control points (P0..P3 as x, y, t in the planners' 1/16 mm and 1/16 ms) as the
 * trace's [[x, y, t] x 4] in m and s, as Python's repr prints them */
void mg_method000_json_ctrl(mg_json_t *j, const int32_t ctrl[12]);

#endif
