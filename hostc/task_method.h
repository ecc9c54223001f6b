/* What differs between the papers' methods, behind one interface the machine calls
 * (host/task/method.py): one row per method in mg_task_methods (task_method.c), each method's
 * own state its module's struct. A fourth method is one module and one row. */
#ifndef MOBIGRASP_HOSTC_TASK_METHOD_H
#define MOBIGRASP_HOSTC_TASK_METHOD_H

#include <stddef.h>
#include <stdint.h>

#include "task_machine.h"

struct mg_path_method;

typedef struct mg_task_method {
    const char *name;
    size_t ms_bytes;                     /* its State's size (at most MG_TASK_MS_BYTES) */
    void (*ms_init)(void *ms);           /* a fresh State */
    void (*params)(mg_task_params_t *p); /* TaskParams.for_method(name) of the ported fields */
    /* the reason FAILED gives (Method.failure_reason) */
    void (*failure_reason)(const mg_task_t *t, const char *reason, char *out, size_t cap);
    /* the wheels' last gate (Method.guard_wheels); NULL: none ported */
    void (*guard_wheels)(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
    /* the height (mm above the ground) the posture adjustment looks at: the object's look
     * (top) or the grasp's (Method.look_height_mm) */
    int32_t (*look_height_mm)(const mg_task_params_t *p, int32_t top);
    /* ADJUST (adjust.py): what it closes in on (the name, the place of its result, whether it
     * is the object itself), its stop rule (Method.adjust_done; det: the result), the goal of
     * its close approach and its speed */
    const char *adjust_detector;
    mg_task_position_fn adjust_position;
    int32_t adjust_is_object;
    int (*adjust_done)(mg_task_t *t, int64_t now_us, const void *det, int32_t dist_mm);
    void (*adjust_goal_mm)(const mg_task_t *t, int32_t *goal_mm, int32_t *tol_mm);
    int32_t (*adjust_vmax_mmps)(const mg_task_params_t *p);
    int32_t grasp_alpha_mrad;
    mg_camera_model_t camera;
    mg_arm_geometry_t geom; /* l2, l3, l4 of the arm the method assumes, Q4 mm */
    /* APPROACH's path hooks (task_approach.h; approach.py PathMethod); NULL: no path */
    const struct mg_path_method *path;
} mg_task_method_t;

extern const mg_task_method_t mg_task_methods[];
extern const int32_t mg_n_task_methods;
const mg_task_method_t *mg_task_method_find(const char *name); /* NULL: unknown */

/* TaskParams(): the defaults of the ported fields (000 section IV's where it gives them); a
 * method's params hook changes its own (param_defaults) */
void mg_task_params_default(mg_task_params_t *p);
/* Method.failure_reason's default: the reason as it is */
void mg_task_reason_as_is(const mg_task_t *t, const char *reason, char *out, size_t cap);

#endif
