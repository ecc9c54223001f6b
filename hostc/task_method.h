/* What differs between the papers' methods, behind one interface the machine calls
 * (host/task/method.py): one row per method in mg_task_methods (task_method.c), each method's
 * own state its module's struct. A fourth method is one module and one row. */
#ifndef MOBIGRASP_HOSTC_TASK_METHOD_H
#define MOBIGRASP_HOSTC_TASK_METHOD_H

#include <stddef.h>
#include <stdint.h>

#include "task_machine.h"

struct mg_path_method;
#define MG_SIGHTING_BYTES 64 /* the largest method's search sighting */
#define MG_FRAME_BYTES 256   /* the largest method's frame of results (mg_frame002_t ...) */

/* the detectors the task names (host/vision/registry.py), in the program's order: every
 * method's per-state lists (Method.detectors) and fallbacks keep this order */
enum {
    MG_DET_DUAL_PLUS, MG_DET_RADIAL_SYMBOL, MG_DET_SPOKE, MG_DET_DOUBLE_CROSS,
    MG_DET_RED_CYLINDER, MG_DET_RED_ROI, MG_DET_HELD_FILL, MG_DET_RADIAL_CUT, MG_N_DETECTORS
};
extern const char *const mg_detector_names[MG_N_DETECTORS];

/* a detector that stands in for another in a state (Method.detector_fallbacks) */
typedef struct {
    int32_t state, detector, primary;
} mg_fallback_t;
#define MG_MAX_FALLBACKS 4
#define MG_MAX_CHECKS 2 /* the grasp check's detectors */
#define MG_MAX_SIGHT_VIEWS 8 /* the views of ROUGH_GRASP's look */

typedef struct mg_task_method {
    const char *name;
    size_t ms_bytes;                     /* its State's size (at most MG_TASK_MS_BYTES) */
    void (*ms_init)(void *ms);           /* a fresh State */
    void (*params)(mg_task_params_t *p); /* TaskParams.for_method(name) of the ported fields */
    /* the reason FAILED gives (Method.failure_reason) */
    void (*failure_reason)(const mg_task_t *t, const char *reason, char *out, size_t cap);
    /* a cue of the object itself (002: the red cylinder's ROI) was seen though its detector
     * never measured it: ROUGH_GRASP then searches again (Method.object_cue_seen; NULL: none) */
    int (*object_cue_seen)(const mg_task_t *t);
    /* the wheels' last gate (Method.guard_wheels); NULL: none ported */
    void (*guard_wheels)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* the height (mm above the ground) the posture adjustment looks at: the object's look
     * (top) or the grasp's (Method.look_height_mm) */
    int32_t (*look_height_mm)(const mg_task_params_t *p, int32_t top);
    /* ADJUST (adjust.py): what it closes in on (the name, the place of its result, whether it
     * is the object itself), its stop rule (Method.adjust_done; det: the result), the goal of
     * its close approach and its speed */
    const char *adjust_detector;
    mg_task_position_fn adjust_position;
    int32_t adjust_is_object;
    int (*adjust_done)(mg_task_t *t, int64_t now_us, const void *det, int32_t dist_mm);
    void (*adjust_goal_mm)(const mg_task_t *t, int32_t *goal_mm, int32_t *tol_mm);
    int32_t (*adjust_vmax_mmps)(const mg_task_params_t *p);
    /* this frame's result of the adjust detector (NULL: none); the radial symbol's sighting
     * ADJUST reads when the adjust detector saw nothing (NULL hook or result: none) */
    const void *(*adjust_result)(const mg_task_inputs_t *in);
    const mg_sighting_t *(*radial_result)(const mg_task_inputs_t *in);
    /* SEARCH (search.py): the sighting of this frame the search looks at, into sighting
     * (MG_SIGHTING_BYTES; 0: none, Method.search_sighting); whether it gives a usable object
     * or bearing (kept; Method.found) and the transition's reason (Method.found_why); the
     * search given up (1 and why; NULL: never, Method.search_gives_up); the search after a
     * loss near the object (1 and the changed parameters and start; NULL: none,
     * Method.lost_search); an unconfirmed sighting seen again at its place counts */
    int (*search_sighting)(const mg_task_t *t, const mg_task_inputs_t *in, void *sighting);
    int (*found)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, const void *sighting);
    void (*found_why)(const mg_task_t *t, char *why, size_t cap);
    int (*search_gives_up)(const mg_task_t *t, char *why, size_t cap);
    int (*lost_search)(mg_task_t *t, mg_search_params_t *sp, int32_t *theta2s_mrad,
                       int32_t *theta5s_mrad);
    int32_t keeps_sightings;
    /* SEARCH's step taken by a back-off from an object too near to be seen whole (1: the
     * step is done; NULL: never, Method.search_back_off) */
    int (*search_back_off)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* a wander leg stopped short by an obstacle: 1 and the odometry heading to face to look
     * around there before the next station (the object may be what stopped it); NULL or 0:
     * the next station (Method.search_cut_look) */
    int (*search_cut_look)(const mg_task_t *t, int64_t now_us, int32_t *heading_mrad);
    /* APPROACH: its entry action after the common reset, and its step */
    void (*enter_approach)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    void (*approach)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* the grasp (grasp.py): the detectors that see the object itself, as the failure names
     * them; the reach the base drives the object into first (1; NULL or 0: none); where the
     * gripper goes first; the grasp's IK; an unreachable rough target tried lower; the entry
     * of PRECISE_GRASP; the grasp check's look (1; NULL or 0: the common look); the frame
     * shows the object held (Method.held_in_view); the check detector's result and place */
    const char *object_detectors;
    int (*grasp_reach_mm)(const mg_task_t *t, int32_t *centre_mm, int32_t *half_mm);
    void (*rough_target)(mg_task_t *t, const mg_task_inputs_t *in, int32_t target_q4[3]);
    int32_t (*grasp_ik)(const mg_arm_geometry_t *g, const int32_t target_q4[3],
                        mg_arm_pose_t *pose, int64_t *detail);
    int32_t lowers_hover;
    /* ROUGH_GRASP first looks at the object from these (range mm, pitch down mrad), the first
     * the arm reaches, the base standing still (Method.sight_views; none: the grasp goes on the
     * estimate ADJUST ended with); the look's detector (the dual "+": this frame's result and
     * its place); after the look the method's decision (1: the transition or the grasp pose
     * made, Method.look_decides; NULL or 0: the common rule) */
    int32_t n_sight_views;
    int32_t sight_views[MG_MAX_SIGHT_VIEWS][2];
    const void *(*sight_result)(const mg_task_inputs_t *in);
    mg_task_position_fn sight_position;
    int (*look_decides)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    void (*enter_precise)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* PRECISE_GRASP's spoke of this frame: 1 and its image angle (mrad) and width (whole px),
     * 0: none (NULL: the method aligns on nothing); no spoke for spoke_wait_us: 1 when the
     * method searches for the object instead, the transition made (Method.grasp_lost; NULL:
     * never) */
    int (*spoke_reading)(const mg_task_inputs_t *in, int32_t *angle_mrad, int32_t *width_px);
    int (*grasp_lost)(mg_task_t *t, int64_t now_us, int64_t waited_us);
    int (*held_view_pose)(const mg_task_t *t, mg_arm_pose_t *pose);
    int (*held_in_view)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* the grasp check's detectors (Method.check_detectors), in their order */
    int32_t n_checks;
    struct {
        const char *detector;
        const void *(*result)(const mg_task_inputs_t *in); /* this frame's, NULL: none */
        mg_task_position_fn position;
        int32_t is_object;
    } checks[MG_MAX_CHECKS];
    int32_t grasp_alpha_mrad;
    int32_t plus_on_top; /* both "+" placed where their rays meet the top (Method.plus_on_top) */
    /* ADJUST starts from the posture it enters with, eq. (10) alone (1), or first puts the
     * elbow and shoulder to the close-look posture (0; Method.adjust_keeps_posture) */
    int32_t adjust_keeps_posture;
    /* the detectors each state runs (bits of MG_DET_*), the fallbacks among them, and the
     * frame of one vision job's results as the method's hooks read it (words[i]: detector i's
     * out words, NULL: nothing found or not run; into frame, MG_FRAME_BYTES) */
    uint32_t detectors[MG_N_TASK_STATES];
    int32_t n_fallbacks;
    mg_fallback_t fallbacks[MG_MAX_FALLBACKS];
    void (*frame_of)(const mg_task_t *t, const int32_t *const *words, void *frame);
    mg_camera_model_t camera;
    mg_arm_geometry_t geom; /* l2, l3, l4 of the arm the method assumes, Q4 mm */
    /* APPROACH's path hooks (task_approach.h; approach.py PathMethod); NULL: no path */
    const struct mg_path_method *path;
} mg_task_method_t;

extern const mg_task_method_t mg_task_methods[];
extern const int32_t mg_n_task_methods;
const mg_task_method_t *mg_task_method_find(const char *name); /* NULL: unknown */

/* TaskParams(): the defaults of the ported fields (000 section IV's where it gives them); a
 * method's params hook changes its own (param_defaults) */
void mg_task_params_default(mg_task_params_t *p);
/* the detectors the current state runs (bits of MG_DET_*; Task.detectors_needed) */
uint32_t mg_task_detectors_needed(const mg_task_t *t);
/* the detector det stands in for in the current state, or -1 (Task.detector_fallbacks) */
int32_t mg_task_detector_fallback(const mg_task_t *t, int32_t det);

/* Method.failure_reason's default: the reason as it is */
void mg_task_reason_as_is(const mg_task_t *t, const char *reason, char *out, size_t cap);

#endif
