/* The host program's configuration (config.h). */
#include "config.h"
#include "fixedpoint.h"

#include <string.h>

#include "grasp_circle.h"
#include "json.h"
#include "task_method.h"
#include "trig.h"

#define E9 MG_CONFIG_E9
#define PI_LO_E9 3141592653LL /* pi's billionths: a range's top ends at pi (floor), ... */
#define PI_HI_E9 3141592654LL /* ... its bottom at -pi (ceil) */
#define MAX_TIMEOUT_US 3600000000LL /* mcu_sim/world/scenario.py MAX_TIME_LIMIT_S */
#define MAX_OBJECT_MM 100000        /* 2 WORLD_HALF_M in mm */

/* where a paper parameter goes (Method.paper_to_task): nowhere (the world's, or not used), a
 * table of TaskParams, a field of its own */
enum { TO_NONE, TO_PLANNER, TO_SEARCH_TH2_MIN, TO_SEARCH_TH2_MAX, TO_SEARCH_TH5_MIN,
       TO_SEARCH_TH5_MAX, TO_SEARCH_DTH2, TO_K_THETA, TO_W_MIN, TO_W_MAX, TO_R_R, TO_A_G,
       TO_FUZZY_E_TH, TO_FUZZY_E_CTH, TO_FUZZY_U_TH, TO_FUZZY_V_AVG, TO_FUZZY_K_U, TO_T_D };

/* a paper parameter (Method.paper_params: Param): integer kind, the paper's value, the
 * range, where it goes (and the gain's index for TO_K_THETA) */
typedef struct {
    const char *name;
    int32_t is_int;
    int64_t default_e9, lo_e9, hi_e9;
    int32_t to, index;
} param_t;

/* (lo, hi, gap): pairs kept ordered, hi - lo >= gap (Method.param_order) */
typedef struct {
    const char *lo, *hi;
    int64_t gap_e9;
} order_t;

typedef struct {
    const char *method;
    const param_t *params;
    int32_t n_params;
    const order_t *order;
    int32_t n_order;
} schema_t;

/* host/task/method000.py paper_params, paper_to_task, param_order */
static const param_t PARAMS_000[] = {
    {"k_s", 1, 5 * E9, 1 * E9, 20 * E9, TO_NONE, 0},
    {"T_s", 0, 300000000, 50000000, 2 * E9, TO_PLANNER, 0},
    {"k1", 0, 500000000, 0, 10 * E9, TO_PLANNER, 0},
    {"k2", 0, 500000000, 0, 10 * E9, TO_PLANNER, 0},
    {"theta2_min", 0, -2800000000LL, -3 * E9, 0, TO_SEARCH_TH2_MIN, 0},
    {"theta2_max", 0, -2100000000LL, -3 * E9, 0, TO_SEARCH_TH2_MAX, 0},
    {"theta5_min", 0, -800000000, -1400000000LL, 1400000000LL, TO_SEARCH_TH5_MIN, 0},
    {"theta5_max", 0, 800000000, -1400000000LL, 1400000000LL, TO_SEARCH_TH5_MAX, 0},
    {"dtheta2_l", 0, 60000000, 5000000, 500000000, TO_SEARCH_DTH2, 0},
    {"k_theta2", 0, 1 * E9, 0, 10 * E9, TO_K_THETA, 0},
    {"k_theta3", 0, 0, 0, 10 * E9, TO_K_THETA, 1},
    {"k_theta4", 0, 0, 0, 10 * E9, TO_K_THETA, 2},
    {"alpha_T", 0, -1570796327LL, -PI_LO_E9, 0, TO_NONE, 0},
    {"w_min", 1, 20 * E9, 1 * E9, 320 * E9, TO_W_MIN, 0},
    {"w_max", 1, 40 * E9, 1 * E9, 320 * E9, TO_W_MAX, 0},
    {"v0_mps", 0, 120000000, 10000000, 1 * E9, TO_PLANNER, 0},
    {"vmax_mps", 0, 250000000, 10000000, 1 * E9, TO_PLANNER, 0},
    {"amax_mps2", 0, 40000000, 1000000, 2 * E9, TO_PLANNER, 0},
    {"rmin_m", 0, 100000000, 10000000, 2 * E9, TO_PLANNER, 0},
    {"l_w", 0, 300000000, 100000000, 1 * E9, TO_NONE, 0},
    {"L_m", 0, 109000000, 10000000, 500000000, TO_NONE, 0},
    {"D_act_m", 0, 47300000, 5000000, 500000000, TO_NONE, 0},
};
static const order_t ORDER_000[] = {{"theta2_min", "theta2_max", 10000000},
                                    {"theta5_min", "theta5_max", 10000000},
                                    {"w_min", "w_max", 0},
                                    {"v0_mps", "vmax_mps", 0}};
/* host/task/method001.py: its planner's (Vmax, Amax, n_e, v0, T_s, k1, k2, T_D) and the sonar
 * range D_e go to Params001 (mg_config_params001) */
static const param_t PARAMS_001[] = {
    {"Vmax", 0, 400000000, 10000000, 1 * E9, TO_NONE, 0},
    {"Amax", 0, 100000000, 1000000, 2 * E9, TO_NONE, 0},
    {"R_r", 0, 200000000, 50000000, 1 * E9, TO_R_R, 0},
    {"k_s", 1, 5 * E9, 2 * E9, 5 * E9, TO_NONE, 0},
    {"A_g", 0, 1050000000, 50000000, 3140000000LL, TO_A_G, 0}, /* under pi: method001.py */
    {"D_e", 0, 2500000000LL, 100000000, 10 * E9, TO_NONE, 0},
    {"h_e", 0, 208000000, 10000000, 1 * E9, TO_NONE, 0},
    {"n_e", 1, 36 * E9, 1 * E9, 360 * E9, TO_NONE, 0},
    {"v0", 0, 200000000, 10000000, 1 * E9, TO_NONE, 0},
    {"T_s", 0, 500000000, 50000000, 2 * E9, TO_NONE, 0},
    {"k1", 0, 800000000, 0, 10 * E9, TO_NONE, 0},
    {"k2", 0, 200000000, 0, 10 * E9, TO_NONE, 0},
    {"T_D", 0, 15 * E9, 0, 100 * E9, TO_NONE, 0},
};
static const order_t ORDER_001[] = {{"v0", "Vmax", 0}};
/* host/task/method002.py */
static const param_t PARAMS_002[] = {
    {"T_h", 1, 30 * E9, 1 * E9, 255 * E9, TO_NONE, 0},
    {"n", 1, 10 * E9, 1 * E9, 100 * E9, TO_NONE, 0},
    {"e_th", 0, 1430000000, 10000000, PI_LO_E9, TO_FUZZY_E_TH, 0},
    {"e_cth", 0, 5 * E9, 10000000, 50 * E9, TO_FUZZY_E_CTH, 0},
    {"u_th", 0, 1 * E9, 10000000, 10 * E9, TO_FUZZY_U_TH, 0},
    {"V_avg", 0, 150000000, 10000000, 1 * E9, TO_FUZZY_V_AVG, 0},
    {"k_u", 0, 1 * E9, 10000000, 7 * E9, TO_FUZZY_K_U, 0},
    {"D", 0, 14500000, 1000000, 100000000, TO_NONE, 0},
    {"T_d", 0, 45 * E9, 1 * E9, 320 * E9, TO_T_D, 0},
};

#define N(a) ((int32_t)(sizeof a / sizeof a[0]))
static const schema_t SCHEMAS[] = {
    {"000", PARAMS_000, N(PARAMS_000), ORDER_000, N(ORDER_000)},
    {"001", PARAMS_001, N(PARAMS_001), ORDER_001, N(ORDER_001)},
    {"002", PARAMS_002, N(PARAMS_002), NULL, 0},
};

static const schema_t *schema_of(const char *method)
{
    for (int32_t i = 0; i < N(SCHEMAS); i++)
        if (strcmp(SCHEMAS[i].method, method) == 0)
            return &SCHEMAS[i];
    return NULL;
}

/* why: "<key>: <text>", 0-terminated within cap; -1 */
static int refuse(char *why, size_t cap, const char *key, const char *text)
{
    size_t n = mg_task_text(why, cap, 0, key);
    n = mg_task_text(why, cap, n, ": ");
    mg_task_text(why, cap, n, text);
    return -1;
}


/* A JSON number's text [p, end) in billionths, exactly (a tie past the ninth decimal to
 * even); *is_int: an integer literal. 0: not a number, or 10^9 or more in size. */
static int read_e9(const char *p, const char *end, int64_t *out, int *is_int)
{
    char digits[64];
    int32_t n = 0, exp10 = 0, any = 0, rest_nonzero = 0;
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r'))
        p++;
    while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\n' || end[-1] == '\r'))
        end--;
    const int neg = p < end && *p == '-';
    p += neg;
    *is_int = 1;
    for (int frac = 0; p < end; p++) {
        if (*p == '.' && !frac) {
            frac = 1, *is_int = 0;
            continue;
        }
        if (*p < '0' || *p > '9')
            break;
        any = 1;
        exp10 -= frac;
        if (n == 0 && *p == '0')
            continue; /* leading zeros */
        if (n < (int32_t)sizeof digits)
            digits[n++] = *p;
        else
            exp10++, rest_nonzero |= *p != '0'; /* past 64 digits: only whether any is set */
    }
    if (!any)
        return 0;
    if (p < end && (*p == 'e' || *p == 'E')) {
        *is_int = 0;
        p++;
        const int eneg = p < end && (*p == '-' || *p == '+') ? *p++ == '-' : 0;
        int32_t e = 0, edigits = 0;
        for (; p < end && *p >= '0' && *p <= '9'; p++, edigits++)
            e = e < 1000 ? e * 10 + (*p - '0') : e;
        if (!edigits)
            return 0;
        exp10 += eneg ? -e : e;
    }
    if (p != end)
        return 0;
    /* the value is digits * 10^exp10: its billionths are the first n + exp10 + 9 digits */
    const int32_t keep = n + exp10 + 9;
    if (keep > 18)
        return 0;
    int64_t v = 0;
    for (int32_t i = 0; i < keep; i++)
        v = v * 10 + (i < n ? digits[i] - '0' : 0);
    if (keep < n) { /* the digits past the billionths decide the rounding */
        const int32_t first = keep >= 0 ? digits[keep] - '0' : 0;
        for (int32_t i = (keep >= 0 ? keep + 1 : 0); i < n; i++)
            rest_nonzero |= digits[i] != '0';
        if (keep < 0) /* below half a billionth */
            rest_nonzero = 0;
        if (keep >= 0 && (first > 5 || (first == 5 && (rest_nonzero || (v & 1)))))
            v++;
    }
    *out = neg ? -v : v;
    return 1;
}

/* the "params" object: each name of the method's schema, its kind and range */
static int parse_params(mg_json_in_t *in, const schema_t *s, mg_config_t *c, char *why,
                        size_t cap)
{
    char key[64], name[96];
    int first = 1, k;
    if (!mg_json_begin_object_in(in))
        return refuse(why, cap, "params", "expected a table (section)");
    while ((k = mg_json_next_member(in, &first, key, sizeof key)) == 1) {
        size_t nn = mg_task_text(name, sizeof name, 0, "params.");
        mg_task_text(name, sizeof name, nn, key);
        int32_t i = 0;
        while (i < s->n_params && strcmp(s->params[i].name, key) != 0)
            i++;
        if (i == s->n_params) {
            char text[MG_CONFIG_WHY];
            size_t m = mg_task_text(text, sizeof text, 0, "unknown key; expected a parameter"
                                                          " of method ");
            m = mg_task_text(text, sizeof text, m, s->method);
            m = mg_task_text(text, sizeof text, m, ":");
            for (int32_t j = 0; j < s->n_params; j++) {
                m = mg_task_text(text, sizeof text, m, j ? ", " : " ");
                m = mg_task_text(text, sizeof text, m, s->params[j].name);
            }
            return refuse(why, cap, name, text);
        }
        const param_t *p = &s->params[i];
        const char *at = in->p;
        if (!mg_json_skip_value(in))
            return refuse(why, cap, name, "malformed JSON");
        int64_t v;
        int is_int;
        if (!read_e9(at, in->p, &v, &is_int) || (p->is_int && !is_int) || v < p->lo_e9
            || v > p->hi_e9)
            return refuse(why, cap, name, p->is_int ? "expected an integer in its range"
                                                    : "expected a number in its range");
        c->given[i] = 1;
        c->value_e9[i] = v;
    }
    if (k != 0)
        return refuse(why, cap, "params", "malformed JSON");
    for (int32_t o = 0; o < s->n_order; o++) {
        int32_t lo = 0, hi = 0;
        while (strcmp(s->params[lo].name, s->order[o].lo) != 0)
            lo++;
        while (strcmp(s->params[hi].name, s->order[o].hi) != 0)
            hi++;
        if (c->value_e9[hi] - c->value_e9[lo] < s->order[o].gap_e9 - 1) {
            char text[96];
            size_t m = mg_task_text(text, sizeof text, 0, "expected ");
            m = mg_task_text(text, sizeof text, m, s->order[o].lo);
            m = mg_task_text(text, sizeof text, m, s->order[o].gap_e9 ? " < " : " <= ");
            m = mg_task_text(text, sizeof text, m, s->order[o].hi);
            if (s->order[o].gap_e9)
                mg_task_text(text, sizeof text, m, " by the pair's gap");
            const int32_t bad = c->given[lo] || !c->given[hi] ? lo : hi;
            size_t nn = mg_task_text(name, sizeof name, 0, "params.");
            mg_task_text(name, sizeof name, nn, s->params[bad].name);
            return refuse(why, cap, name, text);
        }
    }
    return 0;
}

/* the "task" object: timeouts_us (the task's states that have one) and object_xy_mm */
static int parse_task(mg_json_in_t *in, mg_config_t *c, char *why, size_t cap)
{
    char key[64], name[96];
    int first = 1, k;
    if (!mg_json_begin_object_in(in))
        return refuse(why, cap, "task", "expected a table (section)");
    while ((k = mg_json_next_member(in, &first, key, sizeof key)) == 1) {
        if (strcmp(key, "timeouts_us") == 0) {
            int first2 = 1, k2;
            if (!mg_json_begin_object_in(in))
                return refuse(why, cap, "task.timeouts_us", "expected a table of task states"
                                                            " and us");
            while ((k2 = mg_json_next_member(in, &first2, key, sizeof key)) == 1) {
                size_t nn = mg_task_text(name, sizeof name, 0, "task.timeouts_us.");
                mg_task_text(name, sizeof name, nn, key);
                int32_t s = 0;
                while (s < MG_N_TASK_STATES
                       && (strcmp(mg_task_state_name(s), key) != 0 || mg_task_terminal(s)))
                    s++;
                if (s == MG_N_TASK_STATES)
                    return refuse(why, cap, name, "unknown state; expected one of SEARCH, "
                                  "APPROACH, ADJUST, ROUGH_GRASP, PRECISE_GRASP, LIFT, LOST");
                int64_t us;
                if (!mg_json_read_int(in, &us) || us < 1 || us > MAX_TIMEOUT_US)
                    return refuse(why, cap, name, "expected an integer in [1, 3600000000] us");
                c->has_timeout[s] = 1;
                c->timeouts_us[s] = us;
            }
            if (k2 != 0)
                return refuse(why, cap, "task.timeouts_us", "malformed JSON");
        } else if (strcmp(key, "object_xy_mm") == 0) {
            int first2 = 1, k2;
            if (!mg_json_begin_array_in(in))
                return refuse(why, cap, "task.object_xy_mm", "expected [x, y] in mm, or []");
            c->n_object_xy = 0;
            while ((k2 = mg_json_next_element(in, &first2)) == 1) {
                int64_t v;
                if (c->n_object_xy >= 2 || !mg_json_read_int(in, &v) || v < -MAX_OBJECT_MM
                    || v > MAX_OBJECT_MM)
                    return refuse(why, cap, "task.object_xy_mm", "expected [x, y] in mm "
                                  "(integers within 100000), or []");
                c->object_xy_mm[c->n_object_xy++] = (int32_t)v;
            }
            if (k2 != 0 || c->n_object_xy == 1)
                return refuse(why, cap, "task.object_xy_mm", "expected [x, y] in mm, or []");
            c->has_object_xy = 1;
        } else {
            size_t nn = mg_task_text(name, sizeof name, 0, "task.");
            mg_task_text(name, sizeof name, nn, key);
            return refuse(why, cap, name, "unknown key; expected one of: timeouts_us, "
                                          "object_xy_mm");
        }
    }
    return k == 0 ? 0 : refuse(why, cap, "task", "malformed JSON");
}

/* the camera's "f_px", "u0_px", "v0_px" (rounded as Python's round, host/app_factory.py) */
static int parse_camera(mg_json_in_t *in, mg_config_t *c, char *why, size_t cap)
{
    char key[64];
    int first = 1, k;
    if (!mg_json_begin_object_in(in))
        return refuse(why, cap, "camera", "expected a table (section)");
    while ((k = mg_json_next_member(in, &first, key, sizeof key)) == 1) {
        const char *at = in->p;
        if (!mg_json_skip_value(in))
            return refuse(why, cap, "camera", "malformed JSON");
        int64_t v;
        int is_int;
        if (strcmp(key, "f_px") == 0) {
            if (!read_e9(at, in->p, &v, &is_int) || mg_div_even64(v, E9) < 1
                || mg_div_even64(v, E9) > 100000)
                return refuse(why, cap, "camera.f_px", "expected a number of px in [1, 100000]");
            c->f_px = (int32_t)mg_div_even64(v, E9);
        } else if (strcmp(key, "u0_px") == 0 || strcmp(key, "v0_px") == 0) {
            const int u = key[0] == 'u'; /* the scenario's ranges (CAMERA_RANGES) */
            if (!read_e9(at, in->p, &v, &is_int) || v < 0 || v > (u ? 320 : 240) * E9)
                return refuse(why, cap, u ? "camera.u0_px" : "camera.v0_px",
                              u ? "expected a number of px in [0, 320]"
                                : "expected a number of px in [0, 240]");
            *(u ? &c->u0_px : &c->v0_px) = (int32_t)mg_div_even64(v, E9);
        }
    }
    return k == 0 ? 0 : refuse(why, cap, "camera", "malformed JSON");
}

void mg_config_default(mg_config_t *c)
{
    memset(c, 0, sizeof *c);
    mg_task_text(c->method, sizeof c->method, 0, "000"); /* the Python host's default */
    c->f_px = 611; /* the camera's without a configuration (host/app_factory.py) */
    c->u0_px = 160;
    c->v0_px = 120;
}

static void defaults_of(mg_config_t *c, const schema_t *s)
{
    c->n_params = s ? s->n_params : 0;
    for (int32_t i = 0; i < c->n_params; i++) {
        c->given[i] = 0;
        c->value_e9[i] = s->params[i].default_e9;
    }
}

int mg_config_parse(const char *text, size_t n, mg_config_t *c, char *why, size_t cap)
{
    mg_config_default(c);
    mg_json_in_t in;
    char key[64];
    int first = 1, k;
    mg_json_in_init(&in, text, n);
    if (!mg_json_utf8_valid(text, n) || !mg_json_begin_object_in(&in))
        return refuse(why, cap, "(document)", "expected a JSON object with method, params, "
                                              "camera, task");
    /* the method first: the parameters are its */
    mg_json_in_t scan = in;
    while ((k = mg_json_next_member(&scan, &first, key, sizeof key)) == 1) {
        if (strcmp(key, "method") != 0) {
            if (!mg_json_skip_value(&scan))
                return refuse(why, cap, "(document)", "malformed JSON");
            continue;
        }
        if (!mg_json_read_string(&scan, c->method, sizeof c->method))
            return refuse(why, cap, "method", "expected a method's name");
    }
    if (k != 0 || !mg_json_at_end(&scan))
        return refuse(why, cap, "(document)", "malformed JSON");
    const schema_t *s = schema_of(c->method);
    defaults_of(c, s);
    first = 1;
    while ((k = mg_json_next_member(&in, &first, key, sizeof key)) == 1) {
        int r = 0;
        if (strcmp(key, "method") == 0)
            r = mg_json_skip_value(&in) ? 0 : -1;
        else if (strcmp(key, "params") == 0 && s != NULL)
            r = parse_params(&in, s, c, why, cap);
        else if (strcmp(key, "params") == 0)
            r = refuse(why, cap, "params", "the method has no paper parameters");
        else if (strcmp(key, "camera") == 0)
            r = parse_camera(&in, c, why, cap);
        else if (strcmp(key, "task") == 0)
            r = parse_task(&in, c, why, cap);
        else
            r = refuse(why, cap, key, "unknown key; expected one of: method, params, camera, "
                                      "task");
        if (r != 0)
            return -1;
    }
    return k == 0 ? 0 : refuse(why, cap, "(document)", "malformed JSON");
}

/* the value of the method's parameter name (its default when not given) */
static int64_t param(const mg_config_t *c, const schema_t *s, const char *name)
{
    for (int32_t i = 0; i < s->n_params; i++)
        if (strcmp(s->params[i].name, name) == 0)
            return c->value_e9[i];
    return 0;
}

static int32_t milli(int64_t v_e9) /* method.py mrad: round(1000 x) */
{
    return (int32_t)mg_div_even64(v_e9, E9 / 1000);
}

int mg_config_task_params(const mg_config_t *c, mg_task_params_t *p)
{
    const mg_task_method_t *rules = mg_task_method_find(c->method);
    if (rules == NULL)
        return -1;
    rules->params(p);
    const schema_t *s = schema_of(c->method);
    for (int32_t i = 0; s != NULL && i < s->n_params; i++) {
        if (!c->given[i])
            continue; /* the task's default (host/app_factory.py task_params maps those given) */
        const int64_t v = c->value_e9[i];
        switch (s->params[i].to) {
        case TO_SEARCH_TH2_MIN: p->search.theta2_min_mrad = milli(v); break;
        case TO_SEARCH_TH2_MAX: p->search.theta2_max_mrad = milli(v); break;
        case TO_SEARCH_TH5_MIN: p->search.theta5_min_mrad = milli(v); break;
        case TO_SEARCH_TH5_MAX: p->search.theta5_max_mrad = milli(v); break;
        case TO_SEARCH_DTH2: p->search.d_theta2_mrad = milli(v); break;
        case TO_W_MIN: p->w_min_px = (int32_t)(v / E9); break;
        case TO_W_MAX: p->w_max_px = (int32_t)(v / E9); break;
        case TO_R_R: p->r_r_mm = milli(v); break;
        case TO_A_G: p->sonar_a_g_mrad = milli(v); break;
        case TO_FUZZY_E_TH: p->fuzzy.e_th_mrad = milli(v); break;
        case TO_FUZZY_E_CTH: p->fuzzy.e_cth_mrad_s = milli(v); break;
        case TO_FUZZY_U_TH: p->fuzzy.u_th_mrad = milli(v); break;
        case TO_FUZZY_V_AVG: p->fuzzy.v_avg_mm_s = milli(v); break;
        case TO_FUZZY_K_U: p->fuzzy.k_uc_q12 = (int32_t)mg_div_even64(v * 4096, E9); break;
        case TO_T_D: p->fuzzy.t_d_px = p->t_d_px = (int32_t)mg_div_even64(v, E9); break;
        default: break; /* the planner's (mg_config_params000), or not the task's */
        }
    }
    /* eq. (10)'s gains: PostureParams()'s, those given replaced (method.py q12) */
    for (int32_t i = 0; s != NULL && i < s->n_params; i++)
        if (s->params[i].to == TO_K_THETA && c->given[i]) {
            static const int32_t GAINS[3] = {4096, 0, 0};
            memcpy(p->posture.k_theta_q12, GAINS, sizeof GAINS);
            for (int32_t j = 0; j < s->n_params; j++)
                if (s->params[j].to == TO_K_THETA && c->given[j])
                    p->posture.k_theta_q12[s->params[j].index] =
                        (int32_t)mg_div_even64(c->value_e9[j] * 4096, E9);
            break;
        }
    for (int32_t st = 0; st < MG_N_TASK_STATES; st++)
        if (c->has_timeout[st])
            p->timeouts_us[st] = c->timeouts_us[st];
    if (c->has_object_xy) {
        p->has_object_xy = c->n_object_xy == 2;
        p->object_xy_mm[0] = c->n_object_xy == 2 ? c->object_xy_mm[0] : 0;
        p->object_xy_mm[1] = c->n_object_xy == 2 ? c->object_xy_mm[1] : 0;
    }
    return 0;
}

/* the schema's values of c when c is of that method, else the paper's (its defaults) */
static const mg_config_t *given_or_default(const mg_config_t *c, const char *method,
                                           mg_config_t *dflt)
{
    if (strcmp(c->method, method) == 0)
        return c;
    mg_config_default(dflt);
    defaults_of(dflt, schema_of(method));
    return dflt;
}

void mg_config_params000(const mg_config_t *c, const mg_task_params_t *p, mg_params000_t *pl,
                         int32_t *v_limit_mm_s)
{
    const schema_t *s000 = schema_of("000");
    mg_config_t dflt;
    const mg_config_t *given = given_or_default(c, "000", &dflt); /* else Params000()'s */
    const int64_t v_max = param(given, s000, "vmax_mps"), a_max = param(given, s000, "amax_mps2");
    const int64_t r_min = param(given, s000, "rmin_m");
    /* bezier000.py plan_000 and bezier_q.py limits_q: round() of each in its unit */
    pl->t_s_ms = (int32_t)mg_div_even64(param(given, s000, "T_s"), E9 / 1000);
    pl->v0_mm_s = (int32_t)mg_div_even64(param(given, s000, "v0_mps"), E9 / 1000);
    pl->standoff_q4 = p->approach_standoff_mm * 16;
    pl->moving_q4 = 320; /* Params000.moving_speed_mps = 0.02 */
    pl->n_samples_min = 16;
    pl->n_samples_max = 64;
    pl->budget_us = 90000;
    pl->k1_q16 = (int32_t)mg_div_even64(param(given, s000, "k1") * 65536, E9);
    pl->k2_q16 = (int32_t)mg_div_even64(param(given, s000, "k2") * 65536, E9);
    pl->lim[0] = (int32_t)mg_div_even64(v_max * 65536, E9);
    pl->lim[1] = (int32_t)mg_div_even64(a_max * 65536, E9);
    pl->lim[2] = (int32_t)mg_div_even64(65536 * E9, r_min);
    pl->lim[3] = 0; /* 000's |dv/dt| */
    *v_limit_mm_s = (int32_t)mg_div_even64(v_max, E9 / 1000);
}

void mg_config_params001(const mg_config_t *c, const mg_task_params_t *p, mg_params001_t *pl,
                         int32_t *v_limit_mm_s)
{
    const schema_t *s001 = schema_of("001");
    mg_config_t dflt;
    const mg_config_t *given = given_or_default(c, "001", &dflt);
    const int64_t v_max = param(given, s001, "Vmax"), a_max = param(given, s001, "Amax");
    /* bezier001.py Params001, bezier_q.py limits_q: round() of each in its unit */
    pl->v0_mm_s = (int32_t)mg_div_even64(param(given, s001, "v0"), E9 / 1000);
    pl->t_s_ms = (int32_t)mg_div_even64(param(given, s001, "T_s"), E9 / 1000);
    pl->k1_q16 = (int32_t)mg_div_even64(param(given, s001, "k1") * 65536, E9);
    pl->k2_q16 = (int32_t)mg_div_even64(param(given, s001, "k2") * 65536, E9);
    pl->t_d_q4 = mg_div_even64(param(given, s001, "T_D") * 160, E9); /* T_D in cm */
    pl->n_e = (int32_t)(param(given, s001, "n_e") / E9);
    pl->coarse_inflate_q4 = 1600; /* coarse_inflate_m 0.1 */
    pl->moving_q4 = 320;          /* moving_speed_mps 0.02 */
    pl->echo_tol_q4 = 2400;       /* object_echo_tol_m 0.15 */
    pl->facing_cos_q12 = mg_cos_q12(1571); /* endpoint_max_angle_rad pi / 2 */
    pl->n_coarse_min = 8;
    pl->n_coarse_max = 32;
    pl->n_fine = 48;
    pl->max_fine = 24;
    pl->budget_us = 75000;
    pl->total_budget_us = 98000;
    pl->expected_q16 = 32768; /* expected_cost_fraction 0.5 */
    pl->lim[0] = (int32_t)mg_div_even64(v_max * 65536, E9);
    pl->lim[1] = (int32_t)mg_div_even64(a_max * 65536, E9);
    pl->lim_coarse[0] = (int32_t)mg_div_even64(v_max * 9 * 65536, 10 * E9); /* coarse_margin 0.9 */
    pl->lim_coarse[1] = (int32_t)mg_div_even64(a_max * 9 * 65536, 10 * E9);
    pl->lim[2] = pl->lim_coarse[2] = -1; /* no radius test */
    pl->lim[3] = pl->lim_coarse[3] = 1;  /* a_t = v^2 kappa */
    /* eq. (5) for the object's grasp point on ArmGeometry001's links (um); l_e = (l_m + l_n)
     * / 2, the grasp circle's test radius l_e less CIRCLE_MARGIN_M (1 mm) squared, floored */
    int64_t l_um[2] = {0, 0};
    if (mg_grasp_radius001_um(p->grasp_height_mm, l_um) != 0)
        l_um[0] = l_um[1] = 0;
    const int64_t sum_um = l_um[0] + l_um[1], r_um2 = sum_um > 2000 ? sum_um - 2000 : 0;
    pl->l_e_q4 = mg_div_even64(sum_um, 125); /* never a tie */
    pl->circle_r2 = r_um2 * r_um2 / 15625;
    /* sonar_regions.py sonar_q of planner_params_001's SonarConfig */
    int32_t s, co;
    pl->sonar.k_s = 5;
    pl->sonar.a_g_urad = (int64_t)p->sonar_a_g_mrad * 1000;
    pl->sonar.d_e_q4 = (int64_t)milli(param(given, s001, "D_e")) * 16;
    pl->sonar.r_r_q4 = (int64_t)p->r_r_mm * 16;
    pl->sonar.tol_q4 = 130 * 16; /* sonar_shared_echo_mm */
    pl->sonar.offset_q4 = (int64_t)p->sonar_offset_mm * 16;
    pl->sonar.arc_bound = 1; /* ARC_BOUND_001 */
    mg_sincos_urad_q14((pl->sonar.a_g_urad + 1) / 2, &s, &co);
    pl->sonar.cot_half_q12 = (int32_t)((2 * (int64_t)co * 4096 + s) / (2 * (int64_t)s));
    *v_limit_mm_s = (int32_t)mg_div_even64(v_max, E9 / 1000);
}

void mg_config_replanner001(const mg_config_t *c, const mg_task_params_t *p,
                            mg_board_replanner001_t *b)
{
    mg_config_t dflt;
    const int64_t v0 = param(given_or_default(c, "001", &dflt), schema_of("001"), "v0");
    mg_config_params001(c, p, &b->params, &b->v_limit_mm_s);
    b->cfg.sonar = b->params.sonar;
    b->cfg.target_q4[0] = b->cfg.target_q4[1] = 0;
    b->cfg.echo_tol_q4 = b->params.echo_tol_q4;
    b->cfg.memory = 16;
    b->cfg.check_samples = 32;
    b->cfg.n_levels = 2;          /* slow_factors (1.0, 0.5) */
    b->cfg.keep_going_q4 = 19200; /* keep_going_m 1.2 */
    for (int32_t i = 0; i < MG_REPLAN_LEVELS; i++)
        b->level_v0_mm_s[i] = (int32_t)mg_div_even64(v0, (E9 / 1000) << (i < 1 ? i : 1));
    b->v0_div = 1;
}

void mg_config_set_method(mg_config_t *c, const char *method)
{
    const schema_t *from = schema_of(c->method), *to = schema_of(method);
    mg_config_t old = *c;
    mg_task_text(c->method, sizeof c->method, 0, method);
    defaults_of(c, to);
    for (int32_t i = 0; from != NULL && to != NULL && i < from->n_params; i++)
        for (int32_t j = 0; j < to->n_params; j++)
            if (old.given[i] && strcmp(from->params[i].name, to->params[j].name) == 0) {
                c->given[j] = 1;
                c->value_e9[j] = old.value_e9[i];
            }
}
