/* The grasp states (host/task/grasp.py): ROUGH_GRASP (000 section III.C.1; 001 first looks back
 * at the object with the base still, Method.sight_views, and decides after the look; 002: the
 * base first drives the object into the reach of the level grasp, then the pre-grasp point by
 * eq. (4) of 002), PRECISE_GRASP (002: in to the axis, down and close; 000's roll and spoke
 * alignment are the method's own phases) and LIFT with the grasp check on positive evidence: the held object
 * fills the hand camera's frame at two waist offsets whose fingertip places are HELD_MOVE_MM
 * apart (docs/task.md). Platform frame, Q4 mm. */
#ifndef MOBIGRASP_HOSTC_TASK_GRASP_H
#define MOBIGRASP_HOSTC_TASK_GRASP_H

#include <stdint.h>

#include "task_machine.h"

#define MG_CHECK_AWAY_MM 60 /* seen farther than this from the fingertip: standing, not held */
#define MG_CHECK_SEEN_FRAMES 2
#define MG_CHECK_POSE_US 500000 /* look this long at each waist offset, settled */
#define MG_MAX_REGRASPS 2
#define MG_HELD_MOVE_MM 25
/* PRECISE_GRASP's spoke search: the roll by 30 degrees at a time, twice (0, -30, -60 degrees
 * from the pi/2 roll cover the quarter turn the "+" repeats in) */
#define MG_ROLL_SCAN_MRAD 524
#define MG_ROLL_SCAN_STEPS 2

/* the object's axis at height_mm above the ground, back_mm short of it along the line from
 * the waist (platform frame, Q4 mm) */
void mg_task_object_target_q4(const mg_task_t *t, const mg_task_inputs_t *in, int32_t height_mm,
                              int32_t back_mm, int32_t out_q4[3]);
/* the gripper point to (x, y, z) at the grasp's pitch (has_th1: the roll too): 1, or 0 with
 * the reason in the detail (precise_unreachable) */
int mg_task_move_point(mg_task_t *t, int64_t now_us, const int32_t xyz_q4[3], int32_t has_th1,
                       int32_t th1);
/* an arm pose in the trace detail: [theta2, theta3, theta4, theta5] mrad */
void mg_task_note_pose(mg_task_t *t, const char *key, const mg_arm_pose_t *p);
/* Down to the grasp height (from above the "+" to the object's axis when the roll aligns),
 * then close; condition: what decided it (the trace's grasp_close: "precise", "ik" (001's
 * grasp from its grasp circle), "no_spoke", "max_steps") */
void mg_task_descend(mg_task_t *t, int64_t now_us, const char *why, const char *condition);
/* the grasp check's evidence: two fingertip places held under HELD_MOVE_MM apart or more */
int mg_task_held_evidence(const mg_task_t *t);
/* the common look of the grasp check's frames: held_fill's colour is the object's (the
 * detail's grasp_check_fill); frames of a swing are not evidence (Method.held_in_view) */
int mg_task_held_fill_in_view(mg_task_t *t, int64_t now_us, int32_t has_fill,
                              const int32_t rgb[3], int32_t fill_permille,
                              int (*colour)(const int32_t rgb[3]));

void mg_task_enter_rough_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_do_rough_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_enter_precise_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_do_precise_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_enter_lift(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_do_lift(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);

#endif
