/* The Fig. 5 search of 000 as a state object over simulated time (host/search.py ArmSearch). */
#include "search.h"

#include <stddef.h>

#include "fixedpoint.h"

#define LEG_TURN_MIN_MRAD 35   /* a leg whose heading is off by less starts without a turn */
#define LEG_TURN_MAX_MRAD 3000 /* a turn toward a station behind is cut here */

void mg_search_params_default(mg_search_params_t *p)
{
    static const mg_search_params_t d = {
        -2800, -2100, 60, -800, 800, 200, -200, 2300, 1047, 3, {-2250, -2500, -2750}, 1571,
        0, 4, 1800, 1, 1400, 0, 2, 66667, 5000, 4500, 1100, 1500, 2, 200, 0, 700, 0, 0};
    *p = d;
}

static int32_t clamp(int32_t v, int32_t lo, int32_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static int32_t iabs(int32_t v)
{
    return v < 0 ? -v : v;
}

/* a list of ints with a capacity: appending past it is remembered, not done */
typedef struct {
    int32_t *v;
    int32_t n, cap, overflow;
} list_t;

static void push(list_t *l, int32_t x)
{
    if (l->n < l->cap)
        l->v[l->n++] = x;
    else
        l->overflow = 1;
}

/* Python's range(a, b, step) appended */
static void range(list_t *l, int32_t a, int32_t b, int32_t step)
{
    if (step > 0)
        for (int32_t x = a; x < b; x += step)
            push(l, x);
    else
        for (int32_t x = a; x > b; x += step)
            push(l, x);
}

/* theta2 levels of one cycle from start: toward one end, then the rest toward the other */
static int32_t levels_of(int32_t lo, int32_t hi, int32_t step, int32_t start, int32_t upward,
                         int32_t *out, int32_t cap, int32_t *overflow)
{
    int32_t tmp[2 * MG_SEARCH_MAX_POSES];
    list_t l = {tmp, 0, 2 * MG_SEARCH_MAX_POSES, 0};
    start = clamp(start, lo, hi);
    if (upward) {
        range(&l, start, hi, step);
        push(&l, hi);
        range(&l, start - step, lo, -step);
        if (start != lo)
            push(&l, lo);
    } else {
        range(&l, start, lo, -step);
        push(&l, lo);
        range(&l, start + step, hi, step);
        if (start != hi)
            push(&l, hi);
    }
    int32_t n = 0;
    for (int32_t i = 0; i < l.n; i++) { /* the first of each value */
        int32_t seen = 0;
        for (int32_t k = 0; k < n && !seen; k++)
            seen = out[k] == tmp[i];
        if (!seen && n < cap)
            out[n++] = tmp[i];
        else if (!seen)
            *overflow = 1;
    }
    *overflow |= l.overflow;
    return n;
}

static void sweep_of(list_t *l, int32_t lo, int32_t hi, int32_t step, int32_t frm,
                     int32_t to_hi)
{
    frm = clamp(frm, lo, hi);
    if (to_hi) {
        range(l, frm, hi, step);
        push(l, hi);
    } else {
        range(l, frm, lo, -step);
        push(l, lo);
    }
}

int32_t mg_search_cycle(const mg_search_params_t *p, int32_t theta2_start_mrad,
                        int32_t theta5_start_mrad, int32_t upward, int32_t coarse,
                        int32_t poses[][2], int32_t max, int32_t *overflow)
{
    int32_t levels[2 * MG_SEARCH_MAX_POSES], n_levels;
    int32_t th5 = clamp(theta5_start_mrad, p->theta5_min_mrad, p->theta5_max_mrad);
    /* the first sweep toward the far end from theta5s */
    int32_t to_hi = (th5 - p->theta5_min_mrad) <= (p->theta5_max_mrad - th5);
    if (coarse) { /* the coarse levels sorted, nearest to theta2s first */
        n_levels = 0;
        for (int32_t i = 0; i < p->n_coarse; i++) {
            int32_t k = n_levels++;
            while (k > 0 && levels[k - 1] > p->coarse_theta2_mrad[i]) {
                levels[k] = levels[k - 1];
                k--;
            }
            levels[k] = p->coarse_theta2_mrad[i];
        }
        if (iabs(levels[n_levels - 1] - theta2_start_mrad) < iabs(levels[0] - theta2_start_mrad))
            for (int32_t i = 0; i < n_levels / 2; i++) {
                const int32_t t = levels[i];
                levels[i] = levels[n_levels - 1 - i];
                levels[n_levels - 1 - i] = t;
            }
        /* one sweep from the middle sees only one side: come back over it */
        if (n_levels == 1 && p->theta5_min_mrad < th5 && th5 < p->theta5_max_mrad)
            levels[n_levels++] = levels[0];
    } else {
        n_levels = levels_of(p->theta2_min_mrad, p->theta2_max_mrad, p->d_theta2_mrad,
                             theta2_start_mrad, upward, levels, 2 * MG_SEARCH_MAX_POSES,
                             overflow);
    }
    int32_t n = 0;
    for (int32_t i = 0; i < n_levels; i++) {
        int32_t sw[MG_SEARCH_MAX_POSES];
        list_t l = {sw, 0, MG_SEARCH_MAX_POSES, 0};
        sweep_of(&l, p->theta5_min_mrad, p->theta5_max_mrad, p->d_theta5_mrad, th5, to_hi);
        *overflow |= l.overflow;
        for (int32_t k = 0; k < l.n; k++) {
            if (n >= max) {
                *overflow = 1;
                break;
            }
            poses[n][0] = levels[i];
            poses[n++][1] = sw[k];
        }
        th5 = sw[l.n - 1];
        to_hi = !to_hi;
    }
    return n;
}

/* the waist poses of the sweeping wander, cyclic, one way then back without the ends: both
 * sides (side 0), the left (1) or the right (-1) side alone and outward_inward_mrad across */
static void build_sweep(mg_arm_search_t *s, int32_t side)
{
    const int32_t w = s->p.wander_theta5_mrad, d = s->p.wander_d_theta5_mrad;
    const int32_t c = s->p.outward_inward_mrad;
    s->side = side;
    int32_t up[MG_SEARCH_MAX_SWEEP];
    list_t l = {up, 0, MG_SEARCH_MAX_SWEEP, 0};
    if (side == 0) {
        range(&l, -w, w, d);
        push(&l, w);
    } else if (side > 0) {
        range(&l, w, -c, -d);
        push(&l, -c);
    } else {
        range(&l, -w, c, d);
        push(&l, c);
    }
    s->n_wsweep = 0;
    for (int32_t i = 0; i < l.n; i++)
        s->wsweep[s->n_wsweep++] = up[i];
    for (int32_t i = l.n - 2; i > 0 && s->n_wsweep < MG_SEARCH_MAX_SWEEP; i--)
        s->wsweep[s->n_wsweep++] = up[i];
    s->overflow |= l.overflow || (l.n > 2 && s->n_wsweep < 2 * l.n - 2);
}

static void new_cycle(mg_arm_search_t *s, int32_t th2, int32_t th5, int32_t upward,
                      int32_t coarse)
{
    s->n_poses = mg_search_cycle(&s->p, th2, th5, upward, coarse, s->poses,
                                 MG_SEARCH_MAX_POSES, &s->overflow);
    s->index = 0;
}

void mg_search_init(mg_arm_search_t *s, const mg_search_params_t *p, int32_t theta2_start_mrad,
                    int32_t theta5_start_mrad, int64_t now_us)
{
    s->p = *p;
    /* the coarse levels clamped into [theta2_min, theta2_max], each once, in order */
    int32_t n = 0;
    for (int32_t i = 0; i < p->n_coarse && i < MG_SEARCH_LEVELS; i++) {
        const int32_t v = clamp(p->coarse_theta2_mrad[i], p->theta2_min_mrad,
                                p->theta2_max_mrad);
        int32_t seen = 0;
        for (int32_t k = 0; k < n; k++)
            seen |= s->p.coarse_theta2_mrad[k] == v;
        if (!seen)
            s->p.coarse_theta2_mrad[n++] = v;
    }
    s->p.n_coarse = n;
    s->overflow = 0;
    s->cycle = 0;
    s->upward = 1;
    new_cycle(s, theta2_start_mrad, theta5_start_mrad, 1, p->dense_cycles <= 0);
    s->prev[0] = theta2_start_mrad, s->prev[1] = theta5_start_mrad;
    s->pose_start_us = now_us;
    s->turning = s->wandering = s->corner = 0;
    s->cycles_here = s->wanders = 0;
    build_sweep(s, 0);
    s->windex = 0;
    s->wpose[0] = s->p.coarse_theta2_mrad[0], s->wpose[1] = p->theta5_max_mrad;
    s->pose[0] = s->pose[1] = s->pose[2] = 0;
    s->origin[0] = s->origin[1] = 0;
    s->has_stations = s->n_stations = s->station = 0;
    s->leg[0] = s->leg[1] = 0;
    s->rounds = 0;
    s->covered = 0;
}

int64_t mg_search_dwell_us(const mg_arm_search_t *s, const int32_t frm[2], const int32_t to[2],
                           int32_t frames)
{
    /* the servo travel of the larger joint move, then the frames to look */
    const int32_t a = iabs(frm[0] - to[0]), b = iabs(frm[1] - to[1]);
    return (int64_t)(a > b ? a : b) * 1000000 / s->p.servo_speed_mrad_per_s
           + (int64_t)(frames ? frames : s->p.frames_per_pose) * s->p.frame_period_us;
}

static mg_search_command_t command(const mg_arm_search_t *s, int32_t th2, int32_t th5,
                                   int32_t turn, int32_t drive)
{
    const mg_search_command_t c = {th2, s->p.theta3_mrad, s->p.theta4_mrad, th5, turn,
                                   s->index, s->cycle, drive};
    return c;
}

static mg_search_command_t pose_command(const mg_arm_search_t *s, int32_t turn)
{
    return command(s, s->poses[s->index][0], s->poses[s->index][1], turn, 0);
}

/* The side the sweep looks to alone on this leg: on a ring's leg that keeps at least
 * outward_from_mm from the rings' centre (the ground inside it was seen from the ring inside),
 * the side away from the centre (1 left, -1 right); else 0, both sides. */
static int32_t outward_side(const mg_arm_search_t *s)
{
    const mg_search_params_t *p = &s->p;
    if (!p->outward_from_mm || !p->cover_mm || !s->has_stations || s->station >= s->n_stations)
        return 0;
    const int64_t px = s->pose[0], py = s->pose[1];
    const int64_t sx = s->stations[s->station][0], sy = s->stations[s->station][1];
    const int64_t ox = s->origin[0], oy = s->origin[1];
    const int64_t lx = sx - px, ly = sy - py, ax = ox - px, ay = oy - py;
    const int64_t cross = lx * ay - ly * ax; /* > 0: the centre lies left of the leg */
    const int64_t along = lx * ax + ly * ay, length2 = lx * lx + ly * ly;
    int64_t near2;
    if (along <= 0 || length2 == 0) /* the leg's nearest point to the centre is its start */
        near2 = ax * ax + ay * ay;
    else if (along >= length2) /* its end */
        near2 = (ox - sx) * (ox - sx) + (oy - sy) * (oy - sy);
    else /* the centre's foot on the leg */
        near2 = cross * cross / length2;
    if (near2 < (int64_t)p->outward_from_mm * p->outward_from_mm)
        return 0;
    return cross > 0 ? -1 : 1;
}

/* drive the next leg; the sweep starts at the waist pose nearest at */
static void start_wander(mg_arm_search_t *s, int64_t now_us, const int32_t at[2])
{
    s->wandering = 1, s->turning = 0, s->corner = 0;
    if (!s->p.wander_sweep)
        return;
    build_sweep(s, outward_side(s));
    int32_t best = 0;
    for (int32_t k = 1; k < s->n_wsweep; k++)
        if (iabs(s->wsweep[k] - at[1]) < iabs(s->wsweep[best] - at[1]))
            best = k;
    s->windex = best;
    s->wpose[0] = s->p.coarse_theta2_mrad[0], s->wpose[1] = s->wsweep[best];
    s->pose_start_us = now_us;
    s->prev[0] = at[0], s->prev[1] = at[1];
}

/* Turn toward the next station of the coverage rings (coverage.c), then drive to it; the rings
 * are laid out from the pose where the first leg starts. Past the last station the search looks
 * around where it is (covered). */
static void start_leg(mg_arm_search_t *s, int64_t now_us, const int32_t at[2])
{
    const mg_search_params_t *p = &s->p;
    if (!s->has_stations) { /* the rings in the start's frame, then in odometry */
        s->origin[0] = s->pose[0], s->origin[1] = s->pose[1];
        const int32_t n = mg_ring_stations(p->cover_mm, p->view_mm, p->chord_mm, p->edge_mm,
                                           s->stations, MG_COVER_STATIONS, &s->overflow);
        s->n_stations = n > 0 ? n : 0;
        for (int32_t i = 0; i < s->n_stations; i++) {
            const int32_t xy[2] = {s->stations[i][0], s->stations[i][1]};
            mg_to_odometry(s->pose, xy, s->stations[i]);
        }
        s->has_stations = 1;
    }
    int32_t turn = 0, drive = 0;
    for (; s->station < s->n_stations; s->station++) { /* a station reached already: the next */
        mg_leg_to(s->pose, s->stations[s->station], &turn, &drive);
        if (drive >= p->chord_mm / 4)
            break;
    }
    if (s->station >= s->n_stations) {
        s->covered = 1;
        s->turning = 1;
        return;
    }
    s->leg[0] = turn < -LEG_TURN_MAX_MRAD ? -LEG_TURN_MAX_MRAD
                : turn > LEG_TURN_MAX_MRAD ? LEG_TURN_MAX_MRAD : turn;
    s->leg[1] = drive;
    if (iabs(turn) < LEG_TURN_MIN_MRAD) {
        start_wander(s, now_us, at);
    } else {
        s->wandering = 0, s->turning = 1, s->corner = 1;
        s->wpose[0] = at[0], s->wpose[1] = at[1];
    }
}

static mg_search_command_t moving_command(mg_arm_search_t *s, int64_t now_us)
{
    const mg_search_params_t *p = &s->p;
    if (s->wandering) {
        int32_t th2 = p->coarse_theta2_mrad[0], th5 = p->theta5_max_mrad; /* looking left */
        if (p->wander_sweep) { /* the far level's sweep while driving */
            int64_t d;
            while (now_us - s->pose_start_us
                   >= (d = mg_search_dwell_us(s, s->prev, s->wpose, p->wander_frames_per_pose))) {
                s->pose_start_us += d;
                s->prev[0] = s->wpose[0], s->prev[1] = s->wpose[1];
                s->windex = (s->windex + 1) % s->n_wsweep;
                s->wpose[0] = p->coarse_theta2_mrad[0], s->wpose[1] = s->wsweep[s->windex];
            }
            th2 = s->wpose[0], th5 = s->wpose[1];
        }
        return command(s, th2, th5, 0,
                       p->cover_mm ? s->leg[1] : p->wander_mm * (1 + s->wanders / 2));
    }
    if (s->corner) /* the arm holds the last wander pose while the base turns */
        return command(s, s->wpose[0], s->wpose[1],
                       p->cover_mm ? s->leg[0] : p->coarse_base_turn_mrad, 0);
    return pose_command(s, s->cycle <= 1 ? p->base_turn_mrad : p->coarse_base_turn_mrad);
}

mg_search_command_t mg_search_step(mg_arm_search_t *s, int64_t now_us, const int32_t *pose)
{
    if (pose != NULL)
        s->pose[0] = pose[0], s->pose[1] = pose[1], s->pose[2] = pose[2];
    if (s->turning || s->wandering)
        return moving_command(s, now_us);
    int64_t d;
    while (now_us - s->pose_start_us
           >= (d = mg_search_dwell_us(s, s->prev, s->poses[s->index], 0))) {
        s->pose_start_us += d;
        s->prev[0] = s->poses[s->index][0], s->prev[1] = s->poses[s->index][1];
        if (s->index + 1 >= s->n_poses) {
            s->cycle++;
            s->cycles_here++;
            /* a full turn of the base found nothing here: wander instead of turning again */
            const int32_t here = s->wanders == 0 ? s->p.turns_per_wander : s->p.stop_cycles;
            const int32_t at[2] = {s->prev[0], s->prev[1]};
            if (s->p.wander_mm > 0 && s->cycles_here >= here && s->p.cover_mm && !s->covered) {
                s->cycles_here = 0;
                start_leg(s, now_us, at);
            } else if (s->p.wander_mm > 0 && s->cycles_here >= here && !s->p.cover_mm) {
                s->cycles_here = 0;
                start_wander(s, now_us, at);
            } else {
                s->turning = 1;
            }
            return moving_command(s, now_us);
        }
        s->index++;
    }
    return pose_command(s, 0);
}

void mg_search_rejoin(mg_arm_search_t *s, int64_t now_us, const int32_t pose[3])
{
    s->pose[0] = pose[0], s->pose[1] = pose[1], s->pose[2] = pose[2];
    if (s->p.cover_mm && s->has_stations && (s->wandering || s->corner)) {
        const int32_t at[2] = {s->wpose[0], s->wpose[1]};
        start_leg(s, now_us, at);
    } else {
        s->pose_start_us = now_us;
    }
}

void mg_search_restart_dwell(mg_arm_search_t *s, int64_t now_us)
{
    s->pose_start_us = now_us;
}

static void next_cycle(mg_arm_search_t *s, int64_t now_us, int32_t th2, int32_t th5)
{
    /* from the lower half climb first, from the upper half descend first */
    s->upward = th2 <= mg_floor_div((int64_t)s->p.theta2_min_mrad + s->p.theta2_max_mrad, 2);
    new_cycle(s, th2, th5, s->upward, s->cycle >= s->p.dense_cycles);
    s->prev[0] = th2, s->prev[1] = th5;
    s->pose_start_us = now_us;
    s->turning = s->wandering = s->corner = 0;
}

void mg_search_base_turn_done(mg_arm_search_t *s, int64_t now_us)
{
    if (s->turning && s->corner) {
        const int32_t at[2] = {s->wpose[0], s->wpose[1]};
        start_wander(s, now_us, at);
    } else if (s->turning) {
        next_cycle(s, now_us, s->poses[s->index][0], s->poses[s->index][1]);
    }
}

static void end_wander(mg_arm_search_t *s, int64_t now_us, int32_t look)
{
    if (!s->wandering)
        return;
    s->wanders++;
    const mg_search_params_t *p = &s->p;
    const int32_t at[2] = {p->wander_sweep ? s->wpose[0] : p->coarse_theta2_mrad[0],
                           p->wander_sweep ? s->wpose[1] : p->theta5_max_mrad};
    if (p->cover_mm) {
        s->station++; /* reached, or stopped short by an obstacle: the next one */
        if (p->stop_cycles == 0 && !look) {
            start_leg(s, now_us, at);
            if (!s->covered)
                return;
        }
        next_cycle(s, now_us, at[0], at[1]);
        return;
    }
    if (p->stop_cycles == 0) { /* a corner of the spiral: turn, then the next leg */
        s->wandering = 0, s->turning = 1, s->corner = 1;
        s->wpose[0] = at[0], s->wpose[1] = at[1];
        return;
    }
    next_cycle(s, now_us, at[0], at[1]);
}

void mg_search_wander_done(mg_arm_search_t *s, int64_t now_us)
{
    s->rounds = 0;
    end_wander(s, now_us, 0);
}

void mg_search_wander_look(mg_arm_search_t *s, int64_t now_us)
{
    end_wander(s, now_us, 1);
}

int32_t mg_search_wander_blocked(mg_arm_search_t *s, int64_t now_us, int32_t can_round)
{
    if (s->wandering && s->p.cover_mm && can_round && s->rounds < s->p.round_tries
        && outward_side(s) != 0) {
        s->rounds++;
        return 1;
    }
    end_wander(s, now_us, 0);
    return 0;
}

void mg_search_wander_resume(mg_arm_search_t *s, int64_t now_us)
{
    if (!s->wandering)
        return;
    const int32_t at[2] = {s->wpose[0], s->wpose[1]};
    start_leg(s, now_us, at);
    if (s->covered)
        next_cycle(s, now_us, at[0], at[1]);
}

int32_t mg_search_station_xy(const mg_arm_search_t *s, int32_t xy_mm[2])
{
    if (!s->has_stations || s->station >= s->n_stations)
        return 0;
    xy_mm[0] = s->stations[s->station][0], xy_mm[1] = s->stations[s->station][1];
    return 1;
}

int32_t mg_search_passing(const mg_arm_search_t *s)
{
    return s->p.cover_mm > 0 && s->rounds > 0;
}
