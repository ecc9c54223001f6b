/* Object search with the eye-in-hand camera, 000 section III.B.2 Fig. 5 (host/search.py, whose
 * docstring gives the pattern and the measured reasons for its coarse levels and the wander
 * spiral): the wrist pitch theta2 steps over its levels, the waist theta5 sweeps each level
 * boustrophedon; after a cycle the base turns, after a look-around it wanders. Angles in mrad,
 * time in simulated us. */
#ifndef MOBIGRASP_HOSTC_SEARCH_H
#define MOBIGRASP_HOSTC_SEARCH_H

#include <stdint.h>

#include "coverage.h"

#define MG_SEARCH_LEVELS 8       /* coarse theta2 levels */
#define MG_SEARCH_MAX_POSES 512  /* poses of one cycle */
#define MG_SEARCH_MAX_SWEEP 256  /* waist poses of the sweeping wander */

typedef struct {
    int32_t theta2_min_mrad, theta2_max_mrad, d_theta2_mrad;
    int32_t theta5_min_mrad, theta5_max_mrad, d_theta5_mrad;
    int32_t theta3_mrad, theta4_mrad; /* the search posture of elbow and shoulder */
    int32_t base_turn_mrad;
    int32_t n_coarse;
    int32_t coarse_theta2_mrad[MG_SEARCH_LEVELS]; /* clamped and deduplicated by init */
    int32_t coarse_base_turn_mrad;
    int32_t dense_cycles, turns_per_wander, wander_mm, wander_sweep, wander_theta5_mrad;
    int32_t stop_cycles, frames_per_pose;
    int64_t frame_period_us;
    int32_t servo_speed_mrad_per_s;
    int32_t cover_mm; /* the wander covers this disc by coverage.c's rings (0: square spiral) */
    int32_t view_mm;  /* half-width of the strip the wander's sweep sees */
    int32_t chord_mm; /* spacing of the rings' stations */
    int32_t wander_frames_per_pose; /* frames per waist pose of the sweep while driving */
    int32_t wander_d_theta5_mrad;   /* waist step of the sweep while driving */
    int32_t outward_from_mm; /* a ring's leg this far from the start sweeps outward (0: never) */
    int32_t outward_inward_mrad; /* ... and this far across to the inner side */
    int32_t round_tries; /* a leg sweeping outward alone stopped by an obstacle goes round it
                          * and aims at its station again at most this often until a leg ends
                          * unblocked (0: the next station at once) */
    int32_t edge_mm; /* the last ring this far inside cover_mm (0: view_mm; coverage.c) */
} mg_search_params_t;

/* host/search.py SearchParams' defaults (000 section IV's pattern, the coverage rings) */
void mg_search_params_default(mg_search_params_t *p);

typedef struct {
    int32_t theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad;
    int32_t base_turn_mrad; /* a base turn to perform (0: none) */
    int32_t pose_index;     /* in the current cycle */
    int32_t cycle;          /* completed cycles */
    int32_t drive_mm;       /* a wander: drive this far straight ahead (0: none) */
} mg_search_command_t;

typedef struct {
    mg_search_params_t p;
    int32_t cycle, upward;
    int32_t n_poses, index;
    int32_t poses[MG_SEARCH_MAX_POSES][2]; /* (theta2, theta5) */
    int32_t prev[2];
    int64_t pose_start_us;
    int32_t turning, wandering, corner;
    int32_t cycles_here, wanders;
    int32_t n_wsweep, windex;
    int32_t side; /* the sweep while driving looks to: 0 both sides, 1 left, -1 right alone */
    int32_t wsweep[MG_SEARCH_MAX_SWEEP];
    int32_t wpose[2];
    int32_t pose[3]; /* the base's odometry (x_mm, y_mm, heading_mrad) as last reported */
    int32_t origin[2]; /* the rings' centre in odometry (where the first leg starts) */
    int32_t has_stations, n_stations, station; /* the rings in odometry, the next one */
    int32_t stations[MG_COVER_STATIONS][2];
    int32_t leg[2];  /* turn_mrad, drive_mm of the leg toward the next station */
    int32_t rounds; /* drives round an obstacle since a leg last ended unblocked */
    int32_t covered; /* the rings are done: the disc of cover_mm has been seen */
    int32_t overflow; /* a cycle or a sweep longer than the arrays: cut short */
} mg_arm_search_t;

/* all (theta2, theta5) poses of one cycle in order (Fig. 5): their count */
int32_t mg_search_cycle(const mg_search_params_t *p, int32_t theta2_start_mrad,
                        int32_t theta5_start_mrad, int32_t upward, int32_t coarse,
                        int32_t poses[][2], int32_t max, int32_t *overflow);
void mg_search_init(mg_arm_search_t *s, const mg_search_params_t *p, int32_t theta2_start_mrad,
                    int32_t theta5_start_mrad, int64_t now_us);
/* servo travel plus frames camera frames (frames 0: the search's frames_per_pose) */
int64_t mg_search_dwell_us(const mg_arm_search_t *s, const int32_t frm[2], const int32_t to[2],
                           int32_t frames);
/* advance the pattern to now_us, the command in force; pose: the base's odometry (x_mm, y_mm,
 * heading_mrad) the rings' legs need (NULL: the last one given) */
mg_search_command_t mg_search_step(mg_arm_search_t *s, int64_t now_us, const int32_t *pose);
void mg_search_restart_dwell(mg_arm_search_t *s, int64_t now_us);
/* the caller drove the base off the pattern and is back at pose (x_mm, y_mm, heading_mrad): a
 * ring's leg under way, or the turn before it, aims at its station again from there; else the
 * pose in hand is held from now_us on (host/search.py ArmSearch.rejoin) */
void mg_search_rejoin(mg_arm_search_t *s, int64_t now_us, const int32_t pose[3]);
void mg_search_base_turn_done(mg_arm_search_t *s, int64_t now_us);
void mg_search_wander_done(mg_arm_search_t *s, int64_t now_us);
/* the base stopped short of the leg's end with the object possibly in front (the caller's
 * evidence): the leg ends, and one cycle at rest looks around here before the next station */
void mg_search_wander_look(mg_arm_search_t *s, int64_t now_us);
/* the base stopped short of the leg's end, an obstacle ahead: 1 when the caller is to drive
 * round it (can_round: it has a way) and then call mg_search_wander_resume (a leg sweeping
 * outward alone, fewer than round_tries times since a leg last ended unblocked); else 0, the
 * leg ended: the next station */
int32_t mg_search_wander_blocked(mg_arm_search_t *s, int64_t now_us, int32_t can_round);
/* the caller has driven round the obstacle: aim at the same station from here */
void mg_search_wander_resume(mg_arm_search_t *s, int64_t now_us);
/* the odometry place of the station the rings' leg drives to: 1 and xy_mm, or 0 off the rings */
int32_t mg_search_station_xy(const mg_arm_search_t *s, int32_t xy_mm[2]);
/* a leg after a drive round an obstacle (until one ends unblocked): the caller stops it only
 * for something in its way, not for the obstacle it passes beside */
int32_t mg_search_passing(const mg_arm_search_t *s);

#endif
