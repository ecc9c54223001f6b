/* The sonar guard (host/task/sonar_guard.py). */
#include "sonar_guard.h"

#include "fixedpoint.h"
#include "task_drive.h"

int32_t mg_sonar_angle_mrad(int32_t k, int32_t n)
{
    return -1571 + k * 3142 / (n - 1);
}

static int32_t n_sonar(const mg_task_inputs_t *in)
{
    return in->n_sonar < MG_TASK_SONARS ? in->n_sonar : MG_TASK_SONARS;
}

int32_t mg_widest_free_heading(const mg_task_inputs_t *in, int32_t clear_mm)
{
    const int32_t n = n_sonar(in) >= 2 ? n_sonar(in) : 0;
    int32_t best_first = 0, best_len = 0, run_first = 0, run_len = 0;
    for (int32_t k = 0; k <= n; k++) { /* the sonar past the last ends the last run */
        const int free = k < n && (in->sonar_mm[k] <= 0 || in->sonar_mm[k] >= clear_mm);
        if (free) {
            run_first = run_len ? run_first : k;
            run_len++;
            continue;
        }
        if (run_len > best_len)
            best_first = run_first, best_len = run_len;
        run_len = 0;
    }
    if (best_len == 0)
        return mg_task_wrap_mrad((int64_t)in->heading_mrad + 1571);
    const int64_t mid = mg_floor_div((int64_t)mg_sonar_angle_mrad(best_first, n)
                                     + mg_sonar_angle_mrad(best_first + best_len - 1, n), 2);
    return mg_task_wrap_mrad(in->heading_mrad + mid);
}

int mg_free_heading_nearest(const mg_task_inputs_t *in, const int32_t xy_mm[2], int32_t clear_mm,
                            int32_t *heading_mrad)
{
    const int32_t bearing = mg_atan2_mrad((int64_t)xy_mm[1] - in->y_mm,
                                          (int64_t)xy_mm[0] - in->x_mm);
    const int32_t n = n_sonar(in) >= 2 ? n_sonar(in) : 0;
    int32_t best_off = -1;
    for (int32_t k = 0; k < n; k++) {
        const int32_t h = mg_task_wrap_mrad((int64_t)in->heading_mrad + mg_sonar_angle_mrad(k, n));
        int32_t off = mg_task_wrap_mrad((int64_t)h - bearing);
        off = off < 0 ? -off : off;
        if (in->sonar_mm[k] >= clear_mm && (best_off < 0 || off < best_off)) {
            best_off = off;
            *heading_mrad = h;
        }
    }
    return best_off >= 0;
}

int mg_blocked_ahead(const int32_t *sonar_mm, int32_t n)
{
    if (n < 3)
        return 0;
    const int32_t mid = n / 2, ahead = sonar_mm[mid];
    if (ahead > 0 && ahead < MG_DETOUR_STOP_MM)
        return 1;
    if (n < 5)
        return 0;
    const int32_t a = sonar_mm[mid - 1], b = sonar_mm[mid + 1];
    return (a > 0 && a < MG_DETOUR_DIAG_MM) || (b > 0 && b < MG_DETOUR_DIAG_MM);
}

/* the object estimate lies in the cone of the sonar at phi at about range rng */
static int object_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t phi, int32_t rng,
                       int32_t half_cone)
{
    const int32_t h = in->heading_mrad + phi;
    const int64_t off = t->p.sonar_offset_mm;
    const int64_t sx = in->x_mm + ((off * mg_cos_q12(h)) >> 12);
    const int64_t sy = in->y_mm + ((off * mg_sin_q12(h)) >> 12);
    const int64_t dx = t->obj_mm[0] - sx, dy = t->obj_mm[1] - sy;
    const int64_t d = mg_isqrt(dx * dx + dy * dy);
    const int32_t off_axis = mg_task_wrap_mrad((int64_t)mg_atan2_mrad(dy, dx) - h);
    const int64_t miss = d - rng;
    return (off_axis < 0 ? -off_axis : off_axis) <= half_cone
           && (miss < 0 ? -miss : miss) <= MG_GUARD_OBJECT_MM;
}

int mg_front_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                  int32_t *range_mm)
{
    const int32_t n = n_sonar(in), half_cone = t->p.sonar_a_g_mrad / 2;
    for (int32_t k = 0; n >= 2 && k < n; k++) {
        const int32_t phi = mg_sonar_angle_mrad(k, n), rng = in->sonar_mm[k];
        if ((phi < 0 ? -phi : phi) >= 1571 || !(rng > 0 && rng < t->p.r_r_mm))
            continue;
        if (t->has_obj && object_echo(t, in, phi, rng, half_cone))
            continue;
        *phi_mrad = phi;
        *range_mm = rng;
        return 1;
    }
    return 0;
}

/* the echo at rng of the sonar at phi is the object's own: its centre estimate in that cone,
 * the echo no more than MG_CLOSE_OBJECT_MM nearer than it (sonar_guard.py close_object_echo) */
static int close_object_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t phi,
                             int32_t rng)
{
    if (!t->has_obj)
        return 0;
    const int64_t off = t->p.sonar_offset_mm;
    const int32_t h = in->heading_mrad + phi;
    const int64_t dx = (int64_t)t->obj_mm[0] - in->x_mm - ((off * mg_cos_q12(h)) >> 12);
    const int64_t dy = (int64_t)t->obj_mm[1] - in->y_mm - ((off * mg_sin_q12(h)) >> 12);
    const int32_t off_axis = mg_task_wrap_mrad((int64_t)mg_atan2_mrad(dy, dx) - h);
    return (off_axis < 0 ? -off_axis : off_axis) <= t->p.sonar_a_g_mrad / 2
           && rng >= mg_isqrt(dx * dx + dy * dy) - MG_CLOSE_OBJECT_MM;
}

static int64_t dist2_mm2(const int32_t p[2], int64_t x, int64_t y)
{
    return (p[0] - x) * (p[0] - x) + (p[1] - y) * (p[1] - y);
}

static void drop_side_echo(mg_task_t *t, int32_t i)
{
    for (int32_t j = i + 1; j < t->n_side_echoes; j++) {
        t->side_echoes_mm[j - 1][0] = t->side_echoes_mm[j][0];
        t->side_echoes_mm[j - 1][1] = t->side_echoes_mm[j][1];
    }
    t->n_side_echoes--;
}

void mg_remember_echoes(mg_task_t *t, const mg_task_inputs_t *in)
{
    const int32_t n = n_sonar(in), off = t->p.sonar_offset_mm, half = t->p.sonar_a_g_mrad / 2;
    const int fresh_all = t->n_sonar_last != n;
    int32_t last[MG_TASK_SONARS];
    for (int32_t k = 0; k < n; k++) {
        last[k] = fresh_all ? -1 : t->sonar_last[k];
        t->sonar_last[k] = in->sonar_mm[k];
    }
    t->n_sonar_last = n;
    if (n < 2)
        return;
    const int64_t far = (int64_t)off + MG_CLOSE_MEMORY_MM;
    for (int32_t i = 0; i < t->n_side_echoes;) {
        if (dist2_mm2(t->side_echoes_mm[i], in->x_mm, in->y_mm) > far * far)
            drop_side_echo(t, i);
        else
            i++;
    }
    for (int32_t k = 0; k < n; k++) {
        const int32_t phi = mg_sonar_angle_mrad(k, n), rng = in->sonar_mm[k];
        if (rng == last[k] || rng <= 0)
            continue;
        const int32_t h = in->heading_mrad + phi;
        const int64_t sx = in->x_mm + (((int64_t)off * mg_cos_q12(h)) >> 12);
        const int64_t sy = in->y_mm + (((int64_t)off * mg_sin_q12(h)) >> 12);
        const int64_t free = (int64_t)rng - MG_SIDE_CLEAR_MM;
        for (int32_t i = 0; i < t->n_side_echoes;) {
            const int32_t *e = t->side_echoes_mm[i];
            const int32_t off_axis = mg_task_wrap_mrad(
                (int64_t)mg_atan2_mrad(e[1] - sy, e[0] - sx) - h);
            if ((off_axis < 0 ? -off_axis : off_axis) < half
                && dist2_mm2(e, sx, sy) < free * free)
                drop_side_echo(t, i);
            else
                i++;
        }
        if ((phi < 0 ? -phi : phi) >= 1571 || rng >= MG_CLOSE_MEMORY_MM
            || close_object_echo(t, in, phi, rng))
            continue;
        for (int32_t side = -1; side <= 1; side += 2) {
            const int32_t edge = h + side * half;
            if (t->n_side_echoes >= MG_SIDE_ECHOES) { /* the farthest from the base makes room */
                int32_t worst = 0;
                for (int32_t i = 1; i < t->n_side_echoes; i++)
                    if (dist2_mm2(t->side_echoes_mm[i], in->x_mm, in->y_mm)
                        > dist2_mm2(t->side_echoes_mm[worst], in->x_mm, in->y_mm))
                        worst = i;
                drop_side_echo(t, worst);
            }
            int32_t *e = t->side_echoes_mm[t->n_side_echoes++];
            e[0] = (int32_t)(sx + (((int64_t)rng * mg_cos_q12(edge)) >> 12));
            e[1] = (int32_t)(sy + (((int64_t)rng * mg_sin_q12(edge)) >> 12));
        }
    }
}

/* the kept edge the footprint (a circle of the ring's radius) reaches first driving straight
 * on, within MG_CLOSE_SIDE_MM: 1 and its bearing from the base and the drive left, or 0 */
static int side_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                     int32_t *range_mm)
{
    const int64_t r = t->p.sonar_offset_mm;
    const int64_t c = mg_cos_q12(in->heading_mrad), s = mg_sin_q12(in->heading_mrad);
    int found = 0;
    for (int32_t i = 0; i < t->n_side_echoes; i++) {
        const int64_t dx = (int64_t)t->side_echoes_mm[i][0] - in->x_mm;
        const int64_t dy = (int64_t)t->side_echoes_mm[i][1] - in->y_mm;
        const int64_t ahead = (dx * c + dy * s) >> 12, aside = (dy * c - dx * s) >> 12;
        if (ahead <= 0 || (aside < 0 ? -aside : aside) >= r)
            continue;
        const int64_t left = ahead - mg_isqrt(r * r - aside * aside);
        if (left < MG_CLOSE_SIDE_MM && (!found || left < *range_mm)) {
            found = 1;
            *range_mm = (int32_t)left;
            *phi_mrad = mg_task_wrap_mrad((int64_t)mg_atan2_mrad(dy, dx) - in->heading_mrad);
        }
    }
    return found;
}

int mg_close_echo(const mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                  int32_t *range_mm)
{
    const int32_t n = n_sonar(in);
    for (int32_t k = 0; n >= 2 && k < n; k++) {
        const int32_t phi = mg_sonar_angle_mrad(k, n), rng = in->sonar_mm[k];
        if ((phi < 0 ? -phi : phi) >= 1571 || !(rng > 0 && rng < MG_CLOSE_GUARD_MM))
            continue;
        if (close_object_echo(t, in, phi, rng))
            continue;
        *phi_mrad = phi;
        *range_mm = rng;
        return 1;
    }
    return side_echo(t, in, phi_mrad, range_mm) ? 2 : 0;
}

void mg_note_close_echo(mg_task_t *t, int side, int32_t phi_mrad, int32_t range_mm)
{
    static const char *const names[4] = {"close_mm", "phi_mrad", "range_mm", "side"};
    const int64_t values[4] = {side ? MG_CLOSE_SIDE_MM : MG_CLOSE_GUARD_MM, phi_mrad, range_mm,
                               1};
    mg_task_note_ints(t, "close_guard", side ? 4 : 3, names, values);
}

/* after every step: the kept echo edges brought up to date; then in ADJUST, driving forward: a
 * close echo stops the base; the grasp goes on from there when the object is within
 * MG_CLOSE_REACH_MM beyond grasp_r_mm of the waist, else it is searched for again (LOST) */
void mg_close_guard(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    int32_t phi, rng;
    mg_remember_echoes(t, in);
    if (t->state != MG_ADJUST || (int64_t)t->wheels[0] + t->wheels[1] <= 0)
        return;
    const int echo = mg_close_echo(t, in, &phi, &rng);
    if (!echo)
        return;
    const int side = echo == 2;
    t->wheels[0] = t->wheels[1] = 0;
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    const int32_t dist = (int32_t)(mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1])
                                   >> 4);
    static const char *const names[5] = {"close_mm", "object_mm", "phi_mrad", "range_mm",
                                         "side"};
    const int64_t values[5] = {side ? MG_CLOSE_SIDE_MM : MG_CLOSE_GUARD_MM, dist, phi, rng, 1};
    mg_task_note_ints(t, "close_guard", side ? 5 : 4, names, values);
    const int grasp = dist <= t->p.grasp_r_mm + MG_CLOSE_REACH_MM;
    char why[MG_TASK_WHY];
    size_t n = mg_task_text(why, sizeof why, 0,
                            side ? "close guard: a kept echo edge " : "close guard: echo ");
    n = mg_task_text_int(why, sizeof why, n, rng);
    n = mg_task_text(why, sizeof why, n, " mm ahead at ");
    n = mg_task_text_int(why, sizeof why, n, phi);
    n = mg_task_text(why, sizeof why, n, " mrad, object ");
    n = mg_task_text_int(why, sizeof why, n, dist);
    mg_task_text(why, sizeof why, n, grasp ? " mm away: grasp from here"
                                           : " mm away: search again");
    mg_task_go(t, now_us, grasp ? MG_ROUGH_GRASP : MG_LOST, why);
}

int mg_drive_detour(mg_task_t *t, const mg_task_inputs_t *in, mg_detour_t *d)
{
    const int32_t err = mg_task_wrap_mrad((int64_t)d->heading_mrad - in->heading_mrad);
    if (!d->has_from && (err < 0 ? -err : err) > MG_TURN_TOL_MRAD) {
        const int32_t v = t->p.turn_wheel_mmps; /* counter-clockwise for err > 0 */
        t->wheels[0] = err < 0 ? v : -v;
        t->wheels[1] = err < 0 ? -v : v;
        return 0;
    }
    if (!d->drive) {
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    if (!d->has_from) {
        d->has_from = 1;
        d->from_mm[0] = in->x_mm, d->from_mm[1] = in->y_mm;
    }
    const int64_t dx = (int64_t)in->x_mm - d->from_mm[0], dy = (int64_t)in->y_mm - d->from_mm[1];
    const int32_t n = n_sonar(in);
    /* a detour chosen clear of 001's regions passes beside what it avoids on purpose: only an
     * echo straight ahead stops it */
    const int blocked = d->checked && n ? in->sonar_mm[n / 2] > 0
                                              && in->sonar_mm[n / 2] < MG_DETOUR_STOP_MM
                                        : mg_blocked_ahead(in->sonar_mm, n);
    if (dx * dx + dy * dy >= (int64_t)d->length_mm * d->length_mm || blocked) {
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    t->wheels[0] = t->wheels[1] = t->p.wander_mmps;
    return 0;
}

static int guarded(int32_t state)
{
    return state == MG_SEARCH || state == MG_APPROACH;
}

int mg_guard_stop(mg_task_t *t, const mg_task_inputs_t *in, int32_t *phi_mrad,
                  int32_t *range_mm)
{
    if (!guarded(t->state) || (int64_t)t->wheels[0] + t->wheels[1] <= 0
        || !mg_front_echo(t, in, phi_mrad, range_mm))
        return 0;
    t->wheels[0] = t->wheels[1] = 0;
    t->path.has_follower = t->path.has_job = 0; /* a plan being made started from a pose left */
    return 1;
}

void mg_out_of_r_r(const mg_task_t *t, const mg_task_inputs_t *in, mg_detour_t *d)
{
    const mg_detour_t out = {1, mg_widest_free_heading(in, t->p.detour_clear_mm), 1, 0, {0, 0},
                             MG_GUARD_OUT_MM, 0};
    *d = out;
}

void mg_note_sonar_guard(mg_task_t *t, int32_t phi_mrad, int32_t range_mm,
                         const mg_detour_t *turn_to)
{
    static const char *const names[4] = {"phi_mrad", "r_r_mm", "range_mm", "turn_to_mrad"};
    const int64_t values[4] = {phi_mrad, t->p.r_r_mm, range_mm,
                               turn_to ? turn_to->heading_mrad : 0};
    mg_task_note_ints(t, "sonar_guard", turn_to ? 4 : 3, names, values);
}

void mg_sonar_guard_step(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_close_guard(t, now_us, in);
    if (t->guard_out.active) {
        if (!guarded(t->state) || mg_drive_detour(t, in, &t->guard_out))
            t->guard_out.active = 0;
        return;
    }
    /* in SEARCH or APPROACH, with the base driving forward, a front echo below R_r stops it;
     * the detour: toward the widest free sector, out of R_r */
    int32_t phi, rng;
    if (!mg_guard_stop(t, in, &phi, &rng))
        return;
    mg_out_of_r_r(t, in, &t->guard_out);
    /* its heading the middle of the sonars free to detour_clear_mm: it passes beside the echo
     * that stopped the base, so only one straight ahead stops it (host/task/sonar_guard.py) */
    t->guard_out.checked = 1;
    mg_note_sonar_guard(t, phi, rng, &t->guard_out);
}
