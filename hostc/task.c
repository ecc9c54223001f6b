/* The table of the C host's methods (host/task's method table in Python). */
#include "task.h"

#include <string.h>

#include "task_method000.h"
#include "task_method001.h"
#include "task_paper.h"

/* the method's paper task with the configuration's parameters, started at 0 (host/app_factory.py
 * build_host_app) */
static void paper_init(mg_paper_task_t *paper, const mg_config_t *cfg, const char *method)
{
    mg_task_params_t params;
    mg_config_task_params(cfg, &params);
    mg_paper_task_init(paper, mg_task_method_find(method), &params, 0);
}

static void method002_init(void *state, const mg_config_t *cfg)
{
    paper_init((mg_paper_task_t *)state, cfg, "002");
}

/* 000's task and the board's planner (plan000.c) with the configuration's Params000 */
typedef struct {
    mg_paper_task_t paper; /* first: the paper task's hooks take the state as one */
    mg_plan000_ctx_t planner;
} mg_method000_state_t;

static void method000_init(void *state, const mg_config_t *cfg)
{
    mg_method000_state_t *s = (mg_method000_state_t *)state;
    paper_init(&s->paper, cfg, "000");
    mg_config_params000(cfg, &s->paper.task.p, &s->planner.params, &s->planner.v_limit_mm_s);
    mg_method000_set_board_planner(&s->paper.task, &s->planner);
}

/* 001's task and the board's replanner (replan.c around plan001.c, its work space included:
 * the most of the program's static room) with the configuration's Params001 */
typedef struct {
    mg_paper_task_t paper; /* first: the paper task's hooks take the state as one */
    mg_board_replanner001_t replanner;
} mg_method001_state_t;

static void method001_init(void *state, const mg_config_t *cfg)
{
    mg_method001_state_t *s = (mg_method001_state_t *)state;
    paper_init(&s->paper, cfg, "001");
    mg_config_replanner001(cfg, &s->paper.task.p, &s->replanner);
    mg_method001_set_replanner(&s->paper.task, &mg_board_replanner001, &s->replanner);
}

/* every method's state fits the program's room for it */
typedef char mg_method000_fits[sizeof(mg_method000_state_t) <= MG_TASK_STATE_BYTES ? 1 : -1];
typedef char mg_method001_fits[sizeof(mg_method001_state_t) <= MG_TASK_STATE_BYTES ? 1 : -1];

const mg_method_t mg_methods[] = {
    {"idle", sizeof(mg_task_idle_t), mg_task_idle_init, mg_task_idle_step, mg_task_idle_needed,
     NULL},
    {"000", sizeof(mg_method000_state_t), method000_init, mg_paper_step, mg_paper_needed,
     mg_paper_fallback_of},
    {"001", sizeof(mg_method001_state_t), method001_init, mg_paper_step, mg_paper_needed,
     mg_paper_fallback_of},
    {"002", sizeof(mg_paper_task_t), method002_init, mg_paper_step, mg_paper_needed,
     mg_paper_fallback_of},
};
const int32_t mg_n_methods = (int32_t)(sizeof mg_methods / sizeof mg_methods[0]);

const mg_method_t *mg_method_find(const char *name)
{
    for (int32_t i = 0; i < mg_n_methods; i++)
        if (strcmp(mg_methods[i].method, name) == 0)
            return &mg_methods[i];
    return NULL;
}

mg_task_if_t mg_method_bind(const mg_method_t *m, void *state, const mg_config_t *cfg)
{
    m->init(state, cfg);
    const mg_task_if_t t = {state, m->step, m->detectors_needed, m->fallback_of};
    return t;
}
