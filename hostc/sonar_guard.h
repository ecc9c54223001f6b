/* The sonar guard (host/task/sonar_guard.py): no drive into what the sonar ring sees. While the
 * base would move forward in SEARCH or APPROACH, a sonar of the ring's front half reading below
 * the safety circle R_r (001 eq. (16)) that is not the object's own echo stops the base; it then
 * turns in place toward the middle of the widest run of free sonars and drives GUARD_OUT_MM
 * along it, out of R_r. The ring is 001's (section III.C.2: k_s sonars from -pi/2, right, to
 * pi/2, left). Integer mm / mrad; no I/O. */
#ifndef MOBIGRASP_HOSTC_SONAR_GUARD_H
#define MOBIGRASP_HOSTC_SONAR_GUARD_H

#include <stdint.h>

#include "task_machine.h"

#define MG_TURN_TOL_MRAD 60   /* the detour turns to within this of its heading first */
#define MG_DETOUR_STOP_MM 400 /* straight ahead: footprint radius 170 mm + braking, margin */
#define MG_DETOUR_DIAG_MM 255
#define MG_GUARD_OBJECT_MM 150 /* an echo this close to the estimate's range is the object's */
#define MG_GUARD_OUT_MM 200    /* after a guard stop: drive this far toward the free sector */
/* the close approach (ADJUST, ROUGH_GRASP's drive into the grasp's reach) passes within R_r of
 * things beside the object on purpose (002's board post), so it is guarded nearer */
#define MG_CLOSE_GUARD_MM 30  /* a front echo this near the ring stops the close approach */
#define MG_CLOSE_OBJECT_MM 80 /* ... unless in the object's cone at most this much nearer */
#define MG_CLOSE_REACH_MM 60  /* stopped this near beyond grasp_r_mm: grasp, else search */
/* a thin thing beside the way leaves the front cone before the ring comes that near: the
 * edges of close echoes' arcs are kept on odometry (MG_SIDE_ECHOES at most) */
#define MG_CLOSE_MEMORY_MM 250 /* a front echo nearer than this (not the object's): kept */
#define MG_CLOSE_SIDE_MM 12    /* ... one the footprint reaches within this driving on stops */
#define MG_SIDE_CLEAR_MM 10    /* a kept edge this much nearer than a new reading is seen through */

/* phi_k of 001 section III.C.2 (k = 1..n evenly from -pi/2 to pi/2) of sonar k of n (n >= 2) */
int32_t mg_sonar_angle_mrad(int32_t k, int32_t n);
/* odometry heading of the middle of the widest run of neighbouring sonars that read no echo or
 * one beyond clear_mm; with none free, a quarter turn left */
int32_t mg_widest_free_heading(const mg_task_inputs_t *in, int32_t clear_mm);
/* the odometry heading of the sonar reading no echo or one beyond clear_mm whose direction is
 * nearest the bearing of xy_mm from the base: 1 and heading_mrad, or 0 when none is free */
int mg_free_heading_nearest(const mg_task_inputs_t *in, const int32_t xy_mm[2], int32_t clear_mm,
                            int32_t *heading_mrad);
/* an echo straight ahead within MG_DETOUR_STOP_MM, or at 45 degrees within MG_DETOUR_DIAG_MM */
int mg_blocked_ahead(const int32_t *sonar_mm, int32_t n);
/* the first front sonar below R_r that is not the object's own echo: 1 and its angle and
 * range, or 0 */
int mg_front_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                  int32_t *range_mm);
/* the first front sonar within MG_CLOSE_GUARD_MM that is not the object's own echo (its near
 * surface, a radius or so short of its centre): 1 and its angle and range; else a kept echo
 * edge the footprint reaches within MG_CLOSE_SIDE_MM driving straight on: 2 and its bearing
 * and the drive left; else 0 */
int mg_close_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                  int32_t *range_mm);
/* the close echo's trace detail (close_mm, phi_mrad, range_mm and, side, side = 1) */
void mg_note_close_echo(mg_task_t *t, int side, int32_t phi_mrad, int32_t range_mm);
/* the kept echo edges brought up to date with this step's new readings: those seen through
 * dropped, a close front echo's arc's edges added, far ones forgotten (sonar_guard.py) */
void mg_remember_echoes(mg_task_t *t, const mg_task_inputs_t *in);
/* after every step: mg_remember_echoes; then in ADJUST, driving forward, a close echo stops the
 * base; the grasp goes on from there when the object is within MG_CLOSE_REACH_MM beyond
 * grasp_r_mm of the waist, else LOST */
void mg_close_guard(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* in SEARCH or APPROACH with the base driving forward, a front echo below R_r: the base
 * stopped, the followed path and any plan being made dropped; 1 and the echo, or 0 */
int mg_guard_stop(mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                  int32_t *range_mm);
/* the detour after a guard stop: toward the widest free sector, MG_GUARD_OUT_MM long */
void mg_out_of_r_r(const mg_task_t *t, const mg_task_inputs_t *in, mg_detour_t *d);
/* the guard stop's trace detail (sonar_guard: phi_mrad, r_r_mm, range_mm and, turn_to not
 * NULL, its detour's heading turn_to_mrad) */
void mg_note_sonar_guard(mg_task_t *t, int32_t phi_mrad, int32_t range_mm,
                         const mg_detour_t *turn_to);
/* one step of the detour d (turn to its heading, then drive its length): 1 when it is over */
int mg_drive_detour(mg_task_t *t, const mg_task_inputs_t *in, mg_detour_t *d);
/* the guard of a method without its own planner's detours (000, 002), after every step
 * (Method.guard_wheels) */
void mg_sonar_guard_step(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);

#endif
