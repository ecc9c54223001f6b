/* SEARCH and LOST (host/task/search.py). */
#include "task_search.h"

#include <string.h>

#include "fixedpoint.h"
#include "json.h"
#include "task_approach.h"
#include "sonar_guard.h"
#include "task_drive.h"
#include "task_method.h"
#include "task_sense.h"
#include "trig.h"

/* the drive to a far sighting (search.py far_step): none, the turn toward it, the drive, the
 * look; the look's waist offsets and frames a pose (search.py FAR_LOOK_OFFSETS_MRAD,
 * FAR_LOOK_FRAMES) */
enum { MG_FAR_NONE, MG_FAR_TURN, MG_FAR_DRIVE, MG_FAR_LOOK };
static const int32_t FAR_LOOK_OFFSETS_MRAD[] = {0, 350, -350, 700, -700};
#define FAR_LOOKS ((int32_t)(sizeof FAR_LOOK_OFFSETS_MRAD / sizeof FAR_LOOK_OFFSETS_MRAD[0]))
#define FAR_LOOK_FRAMES 2

void mg_task_enter_search(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)in;
    mg_search_params_t sp = t->p.search;
    int32_t th2s = t->arm[2], th5s = t->arm[5];
    if (t->lost_in >= 0 && t->rules->lost_search && t->rules->lost_search(t, &sp, &th2s, &th5s)) {
        char text[MG_TASK_NOTE_BYTES];
        mg_json_t j;
        mg_json_init(&j, text, sizeof text - 1);
        mg_json_begin_object(&j);
        mg_json_key(&j, "d_theta2_mrad");
        mg_json_int(&j, sp.d_theta2_mrad);
        mg_json_key(&j, "lost_in");
        const char *lost_in = mg_task_state_name(t->lost_in);
        mg_json_string(&j, lost_in, strlen(lost_in));
        mg_json_key(&j, "theta2s_mrad");
        mg_json_int(&j, th2s);
        mg_json_key(&j, "theta5s_mrad");
        mg_json_int(&j, th5s);
        mg_json_end_object(&j);
        mg_json_terminate(&j);
        mg_task_note(t, "lost_search", text);
    }
    t->lost_in = -1;
    mg_search_init(&t->search, &sp, th2s, th5s, now_us);
    t->has_turn_from = 0;
    t->has_wander_from = 0;
    t->far_phase = MG_FAR_NONE;
    t->wander_round.active = 0;
    t->has_wander_look = 0;
    t->gripper = 0;
    if (t->p.has_object_xy && !t->has_obj && t->lost == 0) {
        /* 001 section II: the object position P_i is given; plan toward it, vision refines it */
        t->has_obj = 1;
        t->obj_mm[0] = t->p.object_xy_mm[0], t->obj_mm[1] = t->p.object_xy_mm[1];
        t->obj_seen_us = now_us;
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "object position given: (");
        n = mg_task_text_int(why, sizeof why, n, t->obj_mm[0]);
        n = mg_task_text(why, sizeof why, n, ", ");
        n = mg_task_text_int(why, sizeof why, n, t->obj_mm[1]);
        mg_task_text(why, sizeof why, n, ") mm");
        mg_task_go(t, now_us, MG_APPROACH, why);
    }
}

int mg_task_seen_there_before(const mg_task_t *t)
{
    if (!t->has_sighting || !t->has_obj)
        return 0;
    const int64_t dx = (int64_t)t->obj_mm[0] - t->sighting_mm[0];
    const int64_t dy = (int64_t)t->obj_mm[1] - t->sighting_mm[1];
    const int64_t r = t->p.sighting_match_mm;
    return dx * dx + dy * dy <= r * r;
}

/* the transition's reason: the method's found_why, then tail */
static void go_found(mg_task_t *t, int64_t now_us, const char *tail)
{
    char why[MG_TASK_WHY];
    t->rules->found_why(t, why, sizeof why);
    mg_task_text(why, sizeof why, strlen(why), tail);
    mg_task_go(t, now_us, MG_APPROACH, why);
}

static void note_bool(mg_task_t *t, const char *key, int v)
{
    mg_task_note(t, key, v ? "true" : "false");
}

/* a front sonar (the middle three) sees something within wander_clear_mm */
static int front_blocked(const mg_task_t *t, const mg_task_inputs_t *in)
{
    const int32_t n = in->n_sonar < MG_TASK_SONARS ? in->n_sonar : MG_TASK_SONARS;
    int blocked = 0; /* the sonars at the front: n / 2 - 1 .. n / 2 + 1 */
    for (int32_t i = n / 2 - 1 > 0 ? n / 2 - 1 : 0; i < n / 2 + 2 && i < n; i++)
        blocked |= in->sonar_mm[i] > 0 && in->sonar_mm[i] < t->p.wander_clear_mm;
    return blocked;
}

/* the unconfirmed sighting from the base: out[0] its waist bearing (right positive), out[1]
 * its bearing from the axle, out[2] its distance from the axle in mm */
static void sighting_platform(const mg_task_t *t, const mg_task_inputs_t *in, int32_t out[3])
{
    int32_t xy[2];
    mg_odom_to_platform_q4(in->x_mm, in->y_mm, in->heading_mrad, t->p.mount_forward_mm,
                           t->sighting_mm[0], t->sighting_mm[1], xy);
    const int64_t x = xy[0], axle_y = (int64_t)xy[1] + (int64_t)t->p.mount_forward_mm * 16;
    out[0] = mg_atan2_mrad(x, xy[1]);
    out[1] = mg_atan2_mrad(x, axle_y);
    out[2] = (int32_t)(mg_isqrt(x * x + axle_y * axle_y) / 16);
}

/* a sighting not seen again at rest, farther than sighting_approach_mm + sighting_match_mm
 * from the axle: drive near it before dropping it (far_step); at most sighting_approaches a
 * run; 1 if the drive starts (search.py far_sighting) */
static int far_sighting(mg_task_t *t, const mg_task_inputs_t *in)
{
    if (!t->p.sighting_approach_mm || !t->has_sighting
        || t->far_count >= t->p.sighting_approaches)
        return 0;
    int32_t sp[3];
    sighting_platform(t, in, sp);
    if (sp[2] <= t->p.sighting_approach_mm + t->p.sighting_match_mm)
        return 0;
    t->far_count++;
    t->far_phase = MG_FAR_TURN;
    t->far_k = 0, t->far_since_us = 0;
    static const char *const names[] = {"bearing_mrad", "dist_mm", "n", "x_mm", "y_mm"};
    const int64_t values[] = {sp[1], sp[2], t->far_count, t->sighting_mm[0], t->sighting_mm[1]};
    mg_task_note_ints(t, "far_sighting", 5, names, values);
    return 1;
}

/* the search's far level, the waist at the sighting's bearing and off_mrad */
static void far_arm(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, int32_t off_mrad)
{
    const mg_search_params_t *sp = &t->search.p;
    int32_t sg[3];
    sighting_platform(t, in, sg);
    int32_t waist = sg[0] + off_mrad;
    waist = waist > sp->wander_theta5_mrad ? sp->wander_theta5_mrad
          : waist < -sp->wander_theta5_mrad ? -sp->wander_theta5_mrad : waist;
    mg_task_set_arm(t, now_us, sp->coarse_theta2_mrad[0], sp->theta3_mrad, sp->theta4_mrad,
                    waist, 1, 0);
}

/* one step of the drive to a far sighting, 1 while under way: turn toward it, drive straight
 * until sighting_approach_mm from it (a front sonar within wander_clear_mm stops it), then
 * the look: the waist at its bearing and FAR_LOOK_OFFSETS_MRAD beside it, FAR_LOOK_FRAMES
 * settled frames each (search.py far_step) */
static int far_step(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    int32_t sg[3];
    if (t->far_phase != MG_FAR_LOOK) /* the camera follows the sighting's bearing */
        far_arm(t, now_us, in, 0);
    if (t->far_phase == MG_FAR_TURN) {
        sighting_platform(t, in, sg);
        if ((sg[1] < 0 ? -sg[1] : sg[1]) > t->p.bearing_tol_mrad) {
            mg_task_turn_in_place(sg[1] > 0 ? -1 : 1, t->p.turn_wheel_mmps, t->wheels);
            return 1;
        }
        t->far_phase = MG_FAR_DRIVE;
        t->far_k = sg[2]; /* the distance the drive starts from */
    }
    if (t->far_phase == MG_FAR_DRIVE) {
        sighting_platform(t, in, sg);
        if (sg[2] > t->p.sighting_approach_mm && !front_blocked(t, in) && sg[2] <= t->far_k) {
            t->wheels[0] = t->wheels[1] = t->p.wander_mmps;
            return 1;
        }
        mg_task_note_int(t, "far_stop_mm", sg[2]);
        t->wheels[0] = t->wheels[1] = 0;
        t->far_phase = MG_FAR_LOOK;
        t->far_k = 0, t->far_since_us = now_us;
        return 1;
    }
    t->wheels[0] = t->wheels[1] = 0; /* a look: frames from far_since_us on, servos settled */
    const int64_t from = t->move_done_us > t->far_since_us ? t->move_done_us : t->far_since_us;
    if (now_us < from + t->p.frame_latency_us + FAR_LOOK_FRAMES * t->search.p.frame_period_us)
        return 1;
    if (t->far_k + 1 < FAR_LOOKS) {
        t->far_k++, t->far_since_us = now_us;
        far_arm(t, now_us, in, FAR_LOOK_OFFSETS_MRAD[t->far_k]);
        return 1;
    }
    return 0;
}

/* back to the search's pattern after a drive off it */
static void rejoin(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const int32_t pose[3] = {in->x_mm, in->y_mm, in->heading_mrad};
    mg_search_rejoin(&t->search, now_us, pose);
    t->has_wander_from = t->has_turn_from = 0;
    t->wheels[0] = t->wheels[1] = 0;
}

/* Drive the search's wander straight ahead on odometry (000 section II "wanders in the
 * environment"); stop short when a front sonar sees something within wander_clear_mm. A leg of
 * the last ring so stopped goes round the obstacle when the search asks it (round_tries):
 * toward the free sonar direction nearest its station, detour_mm (the sonar guard's detour),
 * then to the same station again, stopping only for something in its way (mg_blocked_ahead),
 * not for the obstacle beside it (docs/task.md "000: a ring's leg stopped by an obstacle"). */
static void wander_step(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                        const mg_search_command_t *cmd)
{
    if (t->wander_round.active) {
        if (mg_drive_detour(t, in, &t->wander_round)) {
            t->wander_round.active = 0;
            mg_search_wander_resume(&t->search, now_us);
        }
        return;
    }
    if (t->has_wander_look) { /* facing a cut symbol, then a cycle at rest there */
        const int32_t off = mg_task_wrap_mrad((int64_t)t->wander_look_mrad - in->heading_mrad);
        if ((off < 0 ? -off : off) > t->p.bearing_tol_mrad) {
            mg_task_turn_in_place(off > 0 ? 1 : -1, t->p.turn_wheel_mmps, t->wheels);
            return;
        }
        t->wheels[0] = t->wheels[1] = 0;
        t->has_wander_look = 0;
        mg_search_wander_look(&t->search, now_us);
        return;
    }
    if (!t->has_wander_from) {
        t->has_wander_from = 1;
        t->wander_from_mm[0] = in->x_mm, t->wander_from_mm[1] = in->y_mm;
        mg_task_note_int(t, "wander_mm", cmd->drive_mm);
        mg_task_note_int(t, "search_cycle", cmd->cycle);
    }
    const int64_t dx = (int64_t)in->x_mm - t->wander_from_mm[0];
    const int64_t dy = (int64_t)in->y_mm - t->wander_from_mm[1];
    const int32_t n = in->n_sonar < MG_TASK_SONARS ? in->n_sonar : MG_TASK_SONARS;
    const int blocked = mg_search_passing(&t->search) ? mg_blocked_ahead(in->sonar_mm, n)
                                                      : front_blocked(t, in);
    if (dx * dx + dy * dy >= (int64_t)cmd->drive_mm * cmd->drive_mm || blocked) {
        mg_task_note_int(t, "wander_done_mm", mg_isqrt(dx * dx + dy * dy));
        note_bool(t, "wander_blocked", blocked);
        t->has_wander_from = 0;
        t->wheels[0] = t->wheels[1] = 0;
        if (!blocked) {
            mg_search_wander_done(&t->search, now_us);
            return;
        }
        int32_t look = 0;
        if (t->rules->search_cut_look && t->rules->search_cut_look(t, now_us, &look)) {
            /* the object may be what stopped it: face it and look */
            t->has_wander_look = 1;
            t->wander_look_mrad = look;
            mg_task_note_int(t, "wander_look_mrad",
                             mg_task_wrap_mrad((int64_t)look - in->heading_mrad));
            return;
        }
        int32_t station[2], head = 0;
        const int way = mg_search_station_xy(&t->search, station)
                        && mg_free_heading_nearest(in, station, t->p.detour_clear_mm, &head);
        if (mg_search_wander_blocked(&t->search, now_us, way)) {
            const mg_detour_t round = {1, head, 1, 0, {0, 0}, t->p.detour_mm, 1};
            t->wander_round = round;
            mg_task_note_int(t, "wander_round_mrad", head);
        }
    } else {
        t->wheels[0] = t->wheels[1] = t->p.wander_mmps;
    }
}

void mg_task_do_search(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const struct mg_task_method *r = t->rules;
    if (r->search_back_off && r->search_back_off(t, now_us, in))
        return;
    union {
        int64_t align;
        unsigned char bytes[MG_SIGHTING_BYTES];
    } seen;
    const int has = r->search_sighting(t, in, seen.bytes);
    if (t->has_confirm_until) {
        t->wheels[0] = t->wheels[1] = 0;
        /* holding the pose of the frame that showed the object: see it again, settled */
        if (has && now_us >= t->move_done_us + t->p.frame_latency_us
            && r->found(t, now_us, in, seen.bytes)) {
            t->has_confirm_until = 0;
            go_found(t, now_us, " (confirmed)");
            return;
        }
        if (now_us < t->confirm_until_us)
            return;
        t->has_confirm_until = 0; /* not seen again: resume the pattern */
        t->has_confirm_failed = 1;
        memcpy(t->confirm_failed, t->arm, sizeof t->confirm_failed);
        t->has_sighting = r->keeps_sightings && t->has_obj;
        t->sighting_mm[0] = t->obj_mm[0], t->sighting_mm[1] = t->obj_mm[1];
        mg_search_restart_dwell(&t->search, now_us);
        const int was_far = t->far_phase != MG_FAR_NONE;
        t->far_phase = MG_FAR_NONE;
        if (!far_sighting(t, in) && was_far)
            rejoin(t, now_us, in);
    } else if (has && r->found(t, now_us, in, seen.bytes)) {
        /* seen at a dwell, on a wander leg or while the base turns: stop and confirm */
        t->wheels[0] = t->wheels[1] = 0;
        if (mg_task_seen_there_before(t)) {
            go_found(t, now_us, " (seen twice at that place)");
            return;
        }
        int32_t held[6];
        mg_task_arm_at(t, now_us - t->p.frame_latency_us, held);
        if (t->has_confirm_failed && memcmp(held, t->confirm_failed, sizeof held) == 0)
            memcpy(held, t->arm, sizeof held); /* that pose was tried: the frame is a newer one */
        mg_task_set_arm(t, now_us, held[2], held[3], held[4], held[5], 1, held[1]);
        t->has_confirm_until = 1;
        t->confirm_until_us = t->move_done_us + t->p.confirm_us;
        char why[MG_TASK_WHY], text[MG_TASK_WHY + 8];
        r->found_why(t, why, sizeof why);
        mg_json_t j;
        mg_json_init(&j, text, sizeof text - 1);
        mg_json_string(&j, why, strlen(why));
        mg_json_terminate(&j);
        mg_task_note(t, "search_seen", text);
        return;
    }
    if (t->far_phase != MG_FAR_NONE) {
        if (far_step(t, now_us, in))
            return;
        t->far_phase = MG_FAR_NONE;
        rejoin(t, now_us, in);
    }
    const int32_t pose[3] = {in->x_mm, in->y_mm, in->heading_mrad};
    const mg_search_command_t cmd = mg_search_step(&t->search, now_us, pose);
    char why[MG_TASK_WHY];
    if (r->search_gives_up && r->search_gives_up(t, why, sizeof why)) {
        mg_task_fail(t, now_us, why);
        return;
    }
    mg_task_set_arm(t, now_us, cmd.theta2_mrad, cmd.theta3_mrad, cmd.theta4_mrad,
                    cmd.theta5_mrad, 1, 0);
    if (cmd.drive_mm) {
        wander_step(t, now_us, in, &cmd);
        return;
    }
    if (!cmd.base_turn_mrad) {
        t->wheels[0] = t->wheels[1] = 0;
        return;
    }
    if (!t->has_turn_from) {
        t->has_turn_from = 1;
        t->turn_from_mrad = in->heading_mrad;
        mg_task_note_int(t, "base_turn_mrad", cmd.base_turn_mrad);
        mg_task_note_int(t, "search_cycle", cmd.cycle);
    }
    const int32_t turned = mg_task_wrap_mrad((int64_t)in->heading_mrad - t->turn_from_mrad);
    const int32_t want = cmd.base_turn_mrad < 0 ? -cmd.base_turn_mrad : cmd.base_turn_mrad;
    if ((turned < 0 ? -turned : turned) >= want) {
        mg_search_base_turn_done(&t->search, now_us);
        t->has_turn_from = 0;
        t->wheels[0] = t->wheels[1] = 0;
    } else { /* on the spot: counter-clockwise for a positive turn */
        mg_task_turn_in_place(cmd.base_turn_mrad > 0 ? 1 : -1,
                              t->p.search_turn_wheel_mmps ? t->p.search_turn_wheel_mmps
                                                          : t->p.turn_wheel_mmps,
                              t->wheels);
    }
}

void mg_task_enter_lost(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)in;
    t->wheels[0] = t->wheels[1] = 0;
    t->lost++;
    if (t->lost > t->p.max_lost) {
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "object lost ");
        n = mg_task_text_int(why, sizeof why, n, t->lost);
        mg_task_text(why, sizeof why, n, " times");
        mg_task_fail(t, now_us, why);
    }
}

void mg_task_do_lost(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)in;
    t->wheels[0] = t->wheels[1] = 0;
    if (now_us - t->entered_us >= t->p.lost_hold_us)
        mg_task_go(t, now_us, MG_SEARCH, "platform stopped: searching with the arm (000 Fig. 5)");
}
