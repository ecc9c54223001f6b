/* The methods the C host can run: one module per method, each with its own state struct, and
 * one row of mg_methods (task.c) to add one (host/task's methods are the Python ones). */
#ifndef MOBIGRASP_HOSTC_TASK_H
#define MOBIGRASP_HOSTC_TASK_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "config.h"

/* the largest method state (001: task and replanner with its plan's work space, 393 kB) */
#define MG_TASK_STATE_BYTES 409600

typedef struct {
    const char *method;
    size_t state_bytes;
    void (*init)(void *state, const mg_config_t *cfg); /* cfg: its configuration */
    void (*step)(void *state, mg_app_t *app, int64_t now_us, const mg_detection_t *detections,
                 const int32_t *present, mg_task_output_t *out);
    uint32_t (*detectors_needed)(void *state);
    int32_t (*fallback_of)(void *state, int32_t det); /* NULL: no fallbacks */
} mg_method_t;

extern const mg_method_t mg_methods[];
extern const int32_t mg_n_methods;

/* the row of method name, or NULL */
const mg_method_t *mg_method_find(const char *name);
/* the task interface of a method over its state (initialised here with cfg) */
mg_task_if_t mg_method_bind(const mg_method_t *m, void *state, const mg_config_t *cfg);

/* task_idle.c: holds still in INIT and commands nothing (the HAL, the drivers and the protocol
 * without a paper method: a smoke test of the C host in the loop) */
typedef struct {
    int64_t steps;
} mg_task_idle_t;
void mg_task_idle_init(void *state, const mg_config_t *cfg);
void mg_task_idle_step(void *state, mg_app_t *app, int64_t now_us,
                       const mg_detection_t *detections, const int32_t *present,
                       mg_task_output_t *out);
uint32_t mg_task_idle_needed(void *state);

#endif
