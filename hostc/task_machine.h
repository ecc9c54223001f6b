/* The task state machine of the move-to-grasp (host/task/machine.py): the states and their
 * transitions and timeouts, and the state the states share (arm targets and their settle time,
 * the last second of arm targets and base poses, the object estimate). What only one method
 * keeps is that method's own struct (task_method002.h ...), held in `ms`; where the methods
 * differ the machine asks its row of the method table (task_method.h). No I/O and no clock:
 * the caller passes now_us and the inputs. Integer, no allocation. */
#ifndef MOBIGRASP_HOSTC_TASK_MACHINE_H
#define MOBIGRASP_HOSTC_TASK_MACHINE_H

#include <stddef.h>
#include <stdint.h>

#include "fuzzy.h"
#include "kinematics.h"
#include "posture.h"
#include "search.h"
#include "task_path.h"

typedef enum {
    MG_SEARCH, MG_APPROACH, MG_ADJUST, MG_ROUGH_GRASP, MG_PRECISE_GRASP, MG_LIFT, MG_DONE,
    MG_LOST, MG_FAILED, MG_N_TASK_STATES
} mg_task_state_t;

/* the state's name as Python spells it ("SEARCH" ...) */
const char *mg_task_state_name(int32_t state);
int mg_task_terminal(int32_t state); /* DONE, FAILED */

/* host/task/params.py TaskParams: the fields the ported units read */
typedef struct {
    int64_t timeouts_us[MG_N_TASK_STATES]; /* < 0: none */
    int32_t servo_speed_mrad_per_s;       /* 3000, for settle times */
    int64_t settle_margin_us;             /* 300 000 */
    int64_t frame_latency_us;             /* 50 000 */
    int64_t lost_timeout_us;              /* 1 500 000 */
    int32_t grasp_r_mm;
    int32_t blind_approach_mm, blind_keep_mm; /* 002's blind drive on (task_method002.c) */
    int64_t blind_approach_us;
    int32_t slow_mmps;
    int32_t mount_forward_mm; /* waist axis ahead of the wheel axle */
    int32_t h_shoulder_mm, object_top_mm, grasp_height_mm; /* above the ground */
    int32_t t_d_px;            /* 002's T_d */
    int32_t cylinder_near_px, cross_near_px; /* 002: ADJUST from these spacings */
    int32_t bearing_tol_mrad;        /* ADJUST's close approach: facing within this */
    int32_t adjust_theta3_mrad, adjust_theta4_mrad; /* ADJUST's close-look posture */
    int32_t blind_finish_mm; /* ADJUST may finish on odometry within this of its goal */
    int32_t adjust_vmax_mmps; /* ADJUST's speed (000, 001) */
    /* the path approach of 000 and 001 (task_approach.c): the stand-off of 000's P3, the
     * estimate's shift that replans, the plans tried before the direct approach within
     * direct_max_mm */
    int32_t approach_standoff_mm, replan_shift_mm, max_plan_attempts, direct_max_mm;
    int64_t replan_period_us, sonar_sweep_us; /* 001: the sonar check's period, one sweep */
    int32_t posture_step_mrad; /* eq. (10)'s step per control step */
    mg_posture_params_t posture; /* its gains and margins (max_step_mrad: posture_step_mrad) */
    mg_fuzzy_params_t fuzzy;
    mg_search_params_t search; /* SEARCH's pattern (host/search.py SearchParams) */
    int32_t has_object_xy, object_xy_mm[2]; /* 001: P_i given in the odometry frame */
    int64_t confirm_us;        /* SEARCH: hold the pose this long to see the object again */
    int64_t lost_hold_us;      /* LOST: stand still this long before searching */
    int32_t max_lost;
    int32_t turn_wheel_mmps, wander_mmps, wander_clear_mm, sighting_match_mm;
    /* SEARCH: an unconfirmed sighting farther than sighting_approach_mm + sighting_match_mm
     * from the axle is driven to until sighting_approach_mm away and looked at (0: dropped),
     * at most sighting_approaches a run (task_search.c) */
    int32_t sighting_approach_mm, sighting_approaches;
    int32_t search_turn_wheel_mmps; /* SEARCH's base turns (0: turn_wheel_mmps) */
    int32_t sonar_offset_mm, r_r_mm, sonar_a_g_mrad; /* the sonar ring and the safety circle */
    int32_t detour_mm, detour_clear_mm, max_detours; /* 001: drive aside this often at most */
    int32_t grasp_r_tol_mm, hover_mm, lift_mm, pregrasp_back_mm;
    int64_t grasp_close_timeout_us;
    /* PRECISE_GRASP of 000 (grasp.py _align): w_T's window of 000 section IV, no spoke for
     * spoke_wait_us, at most precise_max_steps, the joint that drives k_T to 0 (1: the roll) */
    int32_t w_min_px, w_max_px;
    int64_t spoke_wait_us;
    int32_t precise_max_steps, precise_align_ch;
} mg_task_params_t;

/* the camera's pinhole intrinsics in px (sense.py CameraModel) */
typedef struct {
    int32_t f_px, u0_px, v0_px;
} mg_camera_model_t;

#define MG_TASK_HIST 128   /* entries of the last second of arm targets and of base poses */
#define MG_TASK_EVENTS 8   /* transitions in one step */
/* bytes of a transition's reason, its 0 included (the longest, 001's look not confirming an
 * object out of reach, ~210) */
#define MG_TASK_WHY 256
#define MG_TASK_MS_BYTES 512 /* the largest method state */
#define MG_TASK_NOTES 12       /* members of a step's trace detail */
#define MG_TASK_NOTE_KEY 32    /* bytes of a member's key, its 0 included */
#define MG_TASK_NOTE_BYTES 384 /* bytes of a member's JSON value, its 0 included */
/* bytes of the one longer member a step may note (a plan's detail, its candidates' control
 * points), its 0 included */
#define MG_TASK_LONG_NOTE_BYTES 16384
#define MG_TASK_SONARS 16      /* sonars of the ring read */
#define MG_SIDE_ECHOES 16      /* the close guard's kept echo edges at most (sonar_guard.c) */

/* one member of the step's trace detail (Task.note): its key and its value in JSON, the
 * objects in it with their keys sorted */
typedef struct {
    char key[MG_TASK_NOTE_KEY];
    char json[MG_TASK_NOTE_BYTES];
    int32_t is_long; /* the value is the task's long_note (longer than json holds) */
} mg_task_note_t;

/* the detour of the sonar guard (sonar_guard.c): the heading to turn to, then (drive) this
 * far along it from where the turn ended */
typedef struct {
    int32_t active;
    int32_t heading_mrad, drive, has_from, from_mm[2], length_mm, checked;
} mg_detour_t;

/* the grasp states' phases (grasp.py t.phase) */
enum { MG_PHASE_NONE, MG_PHASE_REACH, MG_PHASE_SIGHT, MG_PHASE_ROLL, MG_PHASE_ALIGN,
       MG_PHASE_LOWER, MG_PHASE_CLOSE, MG_PHASE_RAISE, MG_PHASE_CHECK };
#define MG_CHECK_LOOKS 3 /* the waist offsets of the grasp check (grasp.c) */

typedef struct {
    int64_t t_us;
    int32_t from, to;
    char why[MG_TASK_WHY];
} mg_task_event_t;

typedef struct mg_task mg_task_t;
struct mg_task_inputs;
typedef void (*mg_task_state_fn)(mg_task_t *t, int64_t now_us, const struct mg_task_inputs *in);

struct mg_task {
    const struct mg_task_method *rules; /* the method's row (task_method.h) */
    mg_task_params_t p;
    mg_camera_model_t cam; /* the method's camera */
    mg_arm_geometry_t geom; /* the method's arm */
    int32_t state;
    int64_t entered_us;
    int32_t entry_pending;
    /* each state's entry action and step; NULL: none (the states not ported do nothing) */
    mg_task_state_fn entry[MG_N_TASK_STATES], step[MG_N_TASK_STATES];
    int32_t arm[6], joints[6];
    int32_t gripper, wheels[2];
    int64_t move_done_us;
    int64_t trust_from_us;
    int32_t has_obj, obj_mm[2];
    int64_t obj_seen_us;
    int32_t graspable_seen, object_sighted; /* the latter dropped by a blind grasp that found
                                             * no evidence of the object (task_grasp.c) */
    int32_t has_failure;
    char failure[MG_TASK_WHY];
    /* (t_us, arm) and (t_us, x_mm, y_mm, heading_mrad): rings of n entries from the oldest's
     * index, *_first */
    int32_t n_arm_hist, n_pose_hist, arm_hist_first, pose_hist_first;
    int64_t arm_hist_t[MG_TASK_HIST], pose_hist_t[MG_TASK_HIST];
    int32_t arm_hist[MG_TASK_HIST][6], pose_hist[MG_TASK_HIST][3];
    int32_t hist_overflow; /* entries dropped for want of room (counted, never silent) */
    int32_t bad_detections; /* counters["bad_detections"] */
    int32_t lost_in;        /* the state the object was lost in (-1: none) */
    mg_task_path_t path;    /* the path approach's follower and plan (000, 001) */
    int32_t n_events, events_lost;
    mg_task_event_t events[MG_TASK_EVENTS];
    int32_t n_notes, notes_lost; /* this step's trace detail */
    mg_task_note_t notes[MG_TASK_NOTES];
    char long_note[MG_TASK_LONG_NOTE_BYTES];
    /* SEARCH and LOST (task_search.c) */
    mg_arm_search_t search;
    int32_t has_turn_from, turn_from_mrad;  /* heading where the base turn started */
    int32_t has_wander_from, wander_from_mm[2]; /* where the wander leg started */
    mg_detour_t wander_round; /* the drive round an obstacle that stopped a leg */
    int32_t has_wander_look, wander_look_mrad; /* the heading to face to look after it */
    int32_t has_confirm_until;
    int64_t confirm_until_us;
    int32_t has_confirm_failed, confirm_failed[6]; /* the pose a confirmation failed in */
    int32_t has_sighting, sighting_mm[2]; /* an unconfirmed sighting's place (keeps_sightings) */
    /* the drive to a far sighting under way (far_phase: MG_FAR_NONE, _TURN, _DRIVE, _LOOK), its
     * look's index or the distance it started from, since when the look holds; drives made */
    int32_t far_phase, far_k, far_count;
    int64_t far_since_us;
    int32_t lost;                          /* counters["lost"] */
    mg_detour_t guard_out; /* the drive out of R_r after a guard stop (sonar_guard.c) */
    /* the close guard's kept echo edges (odometry mm) and the ring's readings of the step
     * before (sonar_guard.c mg_remember_echoes) */
    int32_t n_side_echoes, side_echoes_mm[MG_SIDE_ECHOES][2];
    int32_t n_sonar_last, sonar_last[MG_TASK_SONARS];
    /* the grasp states (task_grasp.c) */
    int32_t phase;
    int64_t phase_us;
    int32_t has_reach, reach_mm[2]; /* the grasp reach to drive to: centre, tolerance */
    int32_t grasp_alpha_mrad;
    int32_t precise_steps, has_close_by;
    char close_by[16];             /* what decided the close */
    int32_t regrasps, check_seen;  /* LIFT: grasps missed, frames seeing the object standing */
    int32_t check_centre_mrad, check_k; /* the grasp check's look: centre waist, offset index */
    int32_t held[MG_CHECK_LOOKS], held_tip_mm[MG_CHECK_LOOKS][2]; /* fingertips held under */
    /* both "+" of the last dual "+" in the odometry frame (000: the precise grasp looks at
     * one of them), the grasp's own place on the object's axis (Q4 mm, platform frame) and
     * the roll steps of PRECISE_GRASP's spoke search */
    int32_t has_plus_odom, plus_odom_mm[2][2];
    int32_t has_grasp_xy, grasp_xy_q4[2];
    int32_t roll_scan;
    /* ROUGH_GRASP's look first (Method.sight_views): dual "+" sightings of it, the index of
     * its look (waist offset, wrist roll), the waist of its view the looks' offsets are added
     * to, and the looks that sent the base back to ADJUST for this grasp */
    int32_t sight_frames, sight_look, sight_th5_mrad, sight_adjusts;
    union {
        int64_t align;
        unsigned char bytes[MG_TASK_MS_BYTES];
    } ms; /* the method's own state: its module's struct */
};

/* the task of a method (its row) at start_us: the arm at HOME_ARM, nothing seen, the method's
 * state fresh; 0, or -1 when the method's state does not fit */
int mg_task_init(mg_task_t *t, const struct mg_task_method *rules, const mg_task_params_t *p,
                 int64_t start_us);
void mg_task_go(mg_task_t *t, int64_t now_us, int32_t to, const char *why);
void mg_task_fail(mg_task_t *t, int64_t now_us, const char *reason);
/* new arm targets (clamped) and the time the servos will have got there; has_th1 0: theta1
 * kept */
void mg_task_set_arm(mg_task_t *t, int64_t now_us, int32_t th2, int32_t th3, int32_t th4,
                     int32_t th5, int32_t has_th1, int32_t th1);
int mg_task_settled(const mg_task_t *t, int64_t now_us);
void mg_task_remember(mg_task_t *t, int64_t now_us, int32_t x_mm, int32_t y_mm,
                      int32_t heading_mrad);
void mg_task_arm_at(const mg_task_t *t, int64_t t_us, int32_t arm[6]);
/* 0 without a history */
int mg_task_pose_at(const mg_task_t *t, int64_t t_us, int64_t *at_us, int32_t pose[3]);
/* the task's posture parameters with the step cap max_step_mrad (machine.py posture_params) */
mg_posture_params_t mg_task_posture_params(const mg_task_t *t, int32_t max_step_mrad);

/* One step's inputs and outputs (machine.py TaskInputs / TaskOutputs without the detections
 * and the detail, which the ported states do not read yet). */
typedef struct mg_task_inputs {
    int32_t has_joints, joints_mrad[6];
    int32_t x_mm, y_mm, heading_mrad, v_mmps;
    int32_t n_sonar, sonar_mm[MG_TASK_SONARS]; /* the ring, right to left; 0xFFFF: no echo */
    int32_t grasp_closed;
    const void *frame; /* this frame's results in the method's type (NULL: no new frame) */
} mg_task_inputs_t;
typedef struct {
    int32_t servo_mrad[6];
    int32_t wheels_mmps[2];
    int32_t gripper_permille;
    int32_t state;
} mg_task_outputs_t;

/* the object estimate in the platform frame (X_r, Y_r), Q4 mm (needs has_obj) */
void mg_task_obj_platform(const mg_task_t *t, const mg_task_inputs_t *in, int32_t out_q4[2]);
/* posture adjustment (eq. (10) of 000) toward the estimated object, at the method's look
 * height (top: the object's look, else the grasp's) */
void mg_task_look_at_object(mg_task_t *t, const mg_task_inputs_t *in, int32_t top);
/* the object's platform-frame position (Q4 mm) from a detection seen with the arm at joints
 * (the method's object_position): 1, or 0 when it gives none */
typedef int (*mg_task_position_fn)(const mg_task_t *t, const int32_t joints[6], const void *det,
                                   int32_t p_q4[3]);
/* update the object estimate from a detection, placed by position(det) with the arm and base
 * of its capture; 0 when unusable (counted in bad_detections when it gives no place or one
 * farther than 5 m); is_object: the detector sees the object itself, not a guide */
int mg_task_see_object(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       mg_task_position_fn position, const void *det, int32_t is_object);
/* a detector's pinhole sighting, as its glue gives it (host/vision's sighting functions): the
 * target's pixel (Q4 px) and depth (Q4 mm) */
typedef struct {
    int32_t u_q4, v_q4, depth_mm_q4;
} mg_sighting_t;
/* Method.object_position's default: the sighting's ray at its depth (sense.py
 * object_in_platform); an mg_task_position_fn of an mg_sighting_t (NULL: none) */
int mg_task_sighting_position(const mg_task_t *t, const int32_t joints[6], const void *det,
                              int32_t p_q4[3]);
/* a dual "+" as the task reads it: its sighting (the midpoint at the depth dist_mm), both
 * "+" centres (u1, v1, u2, v2, Q4 px) and dist_mm (host/vision/dual_plus.py) */
typedef struct {
    mg_sighting_t sighting;
    int32_t uv_q4[4];
    int32_t dist_mm;
} mg_plus_seen_t;
/* the place of an mg_plus_seen_t (its sighting's); mg_task_see_object with it also keeps both
 * "+" in the odometry frame (machine.py _remember_plus) */
int mg_task_plus_position(const mg_task_t *t, const int32_t joints[6], const void *det,
                          int32_t p_q4[3]);
/* advance the task to now_us: the state's timeout, its entry action and step, the method's
 * wheel guard, the history; the events of this step are t->events */
void mg_task_step(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                  mg_task_outputs_t *out);

/* Add to this step's trace detail (Task.note): key's value, JSON text (a key noted again is
 * replaced); the members past MG_TASK_NOTES or longer than MG_TASK_NOTE_BYTES are counted in
 * notes_lost */
void mg_task_note(mg_task_t *t, const char *key, const char *json);
/* the JSON value of the step's i-th detail member */
const char *mg_task_note_json(const mg_task_t *t, int32_t i);
void mg_task_note_int(mg_task_t *t, const char *key, int64_t v);
/* a member whose value is an object of n int members (names in sorted order) */
void mg_task_note_ints(mg_task_t *t, const char *key, int32_t n, const char *const *names,
                       const int64_t *values);
/* the gripper point (eq. (3) of 000) of the arm's targets, Q4 mm */
void mg_task_gripper_point_q4(const mg_task_t *t, int32_t out_q4[3]);
/* the arm to pose (theta2..5; has_th1 0: the roll kept) */
void mg_task_apply_pose(mg_task_t *t, int64_t now_us, const mg_arm_pose_t *pose,
                        int32_t has_th1, int32_t th1);

/* a reason's text: s, then the decimal v (task_machine.c), 0-terminated within cap */
size_t mg_task_text(char *out, size_t cap, size_t at, const char *s);
size_t mg_task_text_int(char *out, size_t cap, size_t at, int64_t v);
/* v_q4 / 16 to one decimal as Python's format(v / 16, ".1f") prints it */
size_t mg_task_text_q4_1(char *out, size_t cap, size_t at, int64_t v_q4);
/* why mg_ik_pitch_mm_q4 refused a target (host/kinematics.py Unreachable.reason), from its
 * code, detail and pose (the pose outside the limits for MG_IK_JOINT_LIMIT) */
size_t mg_task_ik_reason(const mg_arm_geometry_t *g, int32_t code, int64_t detail,
                         const mg_arm_pose_t *pose, char *out, size_t cap, size_t at);

#endif
