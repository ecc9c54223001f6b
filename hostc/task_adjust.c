/* ADJUST (host/task/adjust.py). */
#include "task_adjust.h"

#include "fixedpoint.h"
#include "task_drive.h"
#include "task_method.h"

void mg_task_enter_adjust(mg_task_t *t, int64_t now_us)
{
    if (!t->rules->adjust_keeps_posture) { /* the close-look posture; alpha is kept */
        const int32_t th3 = t->p.adjust_theta3_mrad, th4 = t->p.adjust_theta4_mrad;
        const int32_t alpha = t->arm[2] + t->arm[3] + t->arm[4];
        mg_task_set_arm(t, now_us, alpha - th3 - th4, th3, th4, t->arm[5], 0, 0);
        t->trust_from_us = t->move_done_us;
    }
    if (t->move_done_us > t->obj_seen_us) /* LOST counts from then */
        t->obj_seen_us = t->move_done_us;
}

void mg_task_do_adjust(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       const void *det, const mg_sighting_t *radial)
{
    const struct mg_task_method *r = t->rules;
    if (det)
        mg_task_see_object(t, now_us, in, r->adjust_position, det, r->adjust_is_object);
    else if (radial) /* 000, 001: the dual "+" out of its range, the rings (on the object) */
        mg_task_see_object(t, now_us, in, mg_task_sighting_position, radial, 1);
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    const int32_t dist = (int32_t)(mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1])
                                   >> 4);
    if (det && r->adjust_done(t, now_us, det, dist))
        return;
    /* the estimate stops the close approach at the method's goal (clear of the footprint) */
    int32_t goal_mm, tol_mm, wheels[2];
    r->adjust_goal_mm(t, &goal_mm, &tol_mm);
    mg_close_in_t d;
    const int done = mg_close_in(xy, goal_mm, tol_mm, t->p.bearing_tol_mrad,
                                 r->adjust_vmax_mmps(&t->p), wheels, &d);
    static const char *const names[3] = {"bearing_mrad", "dist_mm", "err_mm"};
    const int64_t values[3] = {d.bearing_mrad, d.dist_mm, d.err_mm};
    mg_task_note_ints(t, "adjust", 3, names, values);
    const int64_t unseen = now_us - t->obj_seen_us;
    if (unseen >= t->p.lost_timeout_us
        && (d.err_mm < 0 ? -d.err_mm : d.err_mm) > t->p.blind_finish_mm) {
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, r->adjust_detector);
        n = mg_task_text(why, sizeof why, n, " not seen for ");
        n = mg_task_text_int(why, sizeof why, n, unseen);
        n = mg_task_text(why, sizeof why, n, " us, ");
        n = mg_task_text_int(why, sizeof why, n, d.dist_mm);
        mg_task_text(why, sizeof why, n, " mm away");
        t->wheels[0] = t->wheels[1] = 0;
        t->lost_in = MG_ADJUST; /* the search that follows may differ */
        mg_task_go(t, now_us, MG_LOST, why);
        return;
    }
    mg_task_look_at_object(t, in, 1);
    t->wheels[0] = wheels[0];
    t->wheels[1] = wheels[1];
    if (done) {
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "object ");
        n = mg_task_text_int(why, sizeof why, n, d.dist_mm);
        n = mg_task_text(why, sizeof why, n, " mm ahead of the waist, bearing ");
        n = mg_task_text_int(why, sizeof why, n, d.bearing_mrad);
        mg_task_text(why, sizeof why, n, " mrad");
        mg_task_go(t, now_us, MG_ROUGH_GRASP, why);
    }
}
