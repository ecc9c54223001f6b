/* The host program's configuration (`--config FILE`, what `mobigrasp run` gives its host:
 * host/app_factory.py build_host_app, checked by tools/commands/host.py as
 * mcu_sim/world/scenario.py parse_host_config checks it): the method, its paper parameters
 * by the paper's names (each method's Method.paper_params: the kind, the range, the ordered
 * pairs; a name the method does not have is refused), the camera's f_px, and the task's
 * settings (SEARCH's and the other states' timeouts, 001's object place P_i). The paper
 * parameters reach the task's parameters as the method's paper_to_task maps them
 * (host/app_factory.py task_params). Integer only: a number is read from its decimal text,
 * exactly, in billionths (a tie past the ninth decimal rounds to even), and rounded to the
 * host's units as Python's round() rounds the float (the two differ only where the float's
 * binary error crosses a half: no value a scenario gives). */
#ifndef MOBIGRASP_HOSTC_CONFIG_H
#define MOBIGRASP_HOSTC_CONFIG_H

#include <stddef.h>
#include <stdint.h>

#include "plan000.h"
#include "plan001.h"
#include "task_method001.h"
#include "task_machine.h"

#define MG_CONFIG_MAX_PARAMS 24 /* the most paper parameters of a method */
#define MG_CONFIG_METHOD 32     /* bytes of the method's name, its 0 included */
#define MG_CONFIG_WHY 512       /* bytes of a refusal's reason */
#define MG_CONFIG_E9 1000000000LL

typedef struct {
    char method[MG_CONFIG_METHOD];
    int32_t f_px; /* the camera's, rounded (the detectors'; the task's camera is its method's) */
    int32_t u0_px, v0_px; /* its principal point, rounded (the detectors') */
    /* the method's paper parameters (its table's order), in billionths; given: in the file */
    int32_t n_params;
    int32_t given[MG_CONFIG_MAX_PARAMS];
    int64_t value_e9[MG_CONFIG_MAX_PARAMS];
    /* task.timeouts_us (has: given, by state) and task.object_xy_mm */
    int32_t has_timeout[MG_N_TASK_STATES];
    int64_t timeouts_us[MG_N_TASK_STATES];
    int32_t has_object_xy, n_object_xy, object_xy_mm[2];
} mg_config_t;

/* the defaults: method "000", f_px 611, u0_px 160, v0_px 120, no parameter or setting given */
void mg_config_default(mg_config_t *c);
/* a configuration's JSON text: 0, or -1 with the key and why in why (one line) */
int mg_config_parse(const char *text, size_t n, mg_config_t *c, char *why, size_t cap);
/* another method (`--method`): the parameters given that it has by name kept
 * (host/app_factory.py task_params maps the names the method has) */
void mg_config_set_method(mg_config_t *c, const char *method);
/* the task's parameters of c's method (its row's defaults, then the paper parameters as
 * paper_to_task maps them, then the task settings); 0, or -1 when c's method has no row */
int mg_config_task_params(const mg_config_t *c, mg_task_params_t *p);
/* 000's planner parameters (Params000 from the task's planner settings, its stand-off the
 * task's approach_standoff_mm) and the follower's wheel limit (Vmax, mm/s) */
void mg_config_params000(const mg_config_t *c, const mg_task_params_t *p, mg_params000_t *pl,
                         int32_t *v_limit_mm_s);
/* 001's planner parameters in integers (planner_params_001 over Params001: the paper's Vmax,
 * Amax, v0, T_s, k1, k2, T_D, n_e and D_e of c, the task's sonar ring and grasp height in p,
 * l_e of eq. (5) by mg_grasp_radius_um) and the follower's wheel limit (Vmax, mm/s) */
void mg_config_params001(const mg_config_t *c, const mg_task_params_t *p, mg_params001_t *pl,
                         int32_t *v_limit_mm_s);
/* the board's 001 replanner's settings (method001.py start_001: Replanner over
 * planner_params_001 with its defaults: 16 regions remembered, 32 check samples, v0 then v0 / 2
 * by the slow-down level, keep going 1.2 m), the target left for its start */
void mg_config_replanner001(const mg_config_t *c, const mg_task_params_t *p,
                            mg_board_replanner001_t *b);

#endif
