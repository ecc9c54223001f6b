/* A paper method's task (task_machine.h, its row of task_method.h) as the host program steps
 * it (app.h mg_task_if_t): the telemetry to the task's inputs (app_factory.h), one vision
 * job's results to the method's frame, the step's outputs to the program's (host/app.py
 * _apply reads TaskOutputs the same way: the transitions, the state, the trace detail). */
#ifndef MOBIGRASP_HOSTC_TASK_PAPER_H
#define MOBIGRASP_HOSTC_TASK_PAPER_H

#include <stdint.h>

#include "app.h"
#include "app_factory.h"
#include "task_machine.h"
#include "task_method.h"

typedef struct {
    mg_task_t task;
    mg_input_builder_t inputs;
    union {
        int64_t align;
        unsigned char bytes[MG_FRAME_BYTES];
    } frame;
    int32_t transitions_lost; /* transitions of one step past MG_TASK_TRANSITIONS */
} mg_paper_task_t;

/* the task of the method's row with its parameters at start_us: 0, or -1 (see mg_task_init) */
int mg_paper_task_init(mg_paper_task_t *p, const mg_task_method_t *rules,
                       const mg_task_params_t *params, int64_t start_us);
/* the task's step's outputs (o) as the program's (out: its strings point into the task) */
void mg_paper_outputs(mg_paper_task_t *p, const mg_task_outputs_t *o, mg_task_output_t *out);
/* mg_task_if_t's hooks over an mg_paper_task_t (ctx) */
void mg_paper_step(void *ctx, mg_app_t *app, int64_t now_us, const mg_detection_t *detections,
                   const int32_t *present, mg_task_output_t *out);
uint32_t mg_paper_needed(void *ctx);
int32_t mg_paper_fallback_of(void *ctx, int32_t det);

#endif
