/* A paper method's task in the host program (task_paper.h). */
#include "task_paper.h"

#include <string.h>

int mg_paper_task_init(mg_paper_task_t *p, const mg_task_method_t *rules,
                       const mg_task_params_t *params, int64_t start_us)
{
    memset(p, 0, sizeof *p);
    mg_input_builder_init(&p->inputs);
    return mg_task_init(&p->task, rules, params, start_us);
}

void mg_paper_outputs(mg_paper_task_t *p, const mg_task_outputs_t *o, mg_task_output_t *out)
{
    const mg_task_t *t = &p->task;
    out->has_servos = out->has_wheels = out->has_gripper = 1;
    memcpy(out->servo_mrad, o->servo_mrad, sizeof out->servo_mrad);
    out->wheels_mmps[0] = o->wheels_mmps[0], out->wheels_mmps[1] = o->wheels_mmps[1];
    out->gripper_permille = o->gripper_permille;
    out->state = mg_task_state_name(o->state);
    out->ops = t->path.ops; /* the planning work of the step (the path approach's slices) */
    out->n_transitions = 0;
    for (int32_t i = 0; i < t->n_events; i++) {
        if (i >= MG_TASK_TRANSITIONS) {
            p->transitions_lost++;
            continue;
        }
        out->transitions[i].t_us = t->events[i].t_us;
        out->transitions[i].from = mg_task_state_name(t->events[i].from);
        out->transitions[i].to = mg_task_state_name(t->events[i].to);
        out->transitions[i].why = t->events[i].why;
        out->n_transitions = i + 1;
    }
    out->n_detail = 0;
    out->detail_has_plan = 0;
    for (int32_t i = 0; i < t->n_notes && i < MG_DETAIL_MEMBERS; i++) {
        out->detail[i].key = t->notes[i].key;
        out->detail[i].json = mg_task_note_json(t, i);
        out->detail_has_plan |= strcmp(t->notes[i].key, "plan") == 0
                                && strcmp(out->detail[i].json, "null") != 0;
        out->n_detail = i + 1;
    }
}

void mg_paper_step(void *ctx, mg_app_t *app, int64_t now_us, const mg_detection_t *detections,
                   const int32_t *present, mg_task_output_t *out)
{
    mg_paper_task_t *p = (mg_paper_task_t *)ctx;
    const int32_t *words[MG_N_DETECTORS];
    int any = 0; /* a vision job's results came: a frame (its detectors may have found none) */
    for (int32_t i = 0; i < MG_N_DETECTORS; i++) {
        const int here = i < app->n_detectors && present[i];
        any |= here;
        words[i] = here && detections[i].found ? detections[i].words : NULL;
    }
    if (any)
        p->task.rules->frame_of(&p->task, words, p->frame.bytes);
    mg_task_inputs_t in;
    mg_input_builder_step(&p->inputs, &app->link, now_us, any ? p->frame.bytes : NULL, &in);
    mg_task_outputs_t o;
    mg_task_step(&p->task, now_us, &in, &o);
    mg_paper_outputs(p, &o, out);
}

uint32_t mg_paper_needed(void *ctx)
{
    return mg_task_detectors_needed(&((mg_paper_task_t *)ctx)->task);
}

int32_t mg_paper_fallback_of(void *ctx, int32_t det)
{
    return mg_task_detector_fallback(&((mg_paper_task_t *)ctx)->task, det);
}
