/* Fuzzy approaching of paper 002 section 3 (host/control/fuzzy.py): inputs e (mrad) and e_c
 * (mrad/s) quantised by k_e = 1/e_th, k_ec = 1/e_cth; 7 x 5 triangular sets, the 35 rules of
 * Table 1, min inference and the centroid of eq. (1); wheel speeds by eq. (2). Integer (Q12):
 * the scaled inputs put the set peaks on multiples of 4096, so memberships are exact. */
#ifndef MOBIGRASP_HOSTC_FUZZY_H
#define MOBIGRASP_HOSTC_FUZZY_H

#include <stdint.h>

#include "budget.h"

typedef struct {
    int32_t e_th_mrad, e_cth_mrad_s, u_th_mrad; /* 002 section 5: 1430, 5000, 1000 */
    int32_t v_avg_mm_s;                          /* V_avg = 150 mm/s */
    int32_t k_uc_q12;                            /* k_uc = 1 per rad of u */
    int32_t t_d_px;                              /* stop when the rings are T_d = 45 px apart */
} mg_fuzzy_params_t;

typedef struct {
    mg_fuzzy_params_t p;
    int32_t no_rule_fired; /* the impossible empty case (covering triangles), counted */
} mg_fuzzy_controller_t;

typedef struct {
    int32_t left_mm_s, right_mm_s, u_mrad, stop;
} mg_fuzzy_command_t;

typedef struct {
    mg_fuzzy_controller_t ctl;
    int32_t has_prev; /* the previous e and its time, for e_c */
    int64_t prev_t_us;
    int32_t prev_e_mrad;
} mg_fuzzy_approach_t;

void mg_fuzzy_controller_init(mg_fuzzy_controller_t *c, const mg_fuzzy_params_t *p);
void mg_fuzzy_quantise(const mg_fuzzy_controller_t *c, int32_t e_mrad, int64_t ec_mrad_s,
                       int32_t *x_e, int32_t *x_ec);
int32_t mg_fuzzy_infer_q12(mg_fuzzy_controller_t *c, int32_t x_e, int32_t x_ec);
int32_t mg_fuzzy_u_mrad(mg_fuzzy_controller_t *c, int32_t e_mrad, int64_t ec_mrad_s);
void mg_fuzzy_wheels_mm_s(const mg_fuzzy_controller_t *c, int32_t u_mrad, int32_t *left,
                          int32_t *right);
void mg_fuzzy_approach_init(mg_fuzzy_approach_t *a, const mg_fuzzy_params_t *p);
/* one step: has_e 0 when the marker is not seen (stop and wait); has_d_pixel 0 when the rings'
 * distance is unknown */
mg_fuzzy_command_t mg_fuzzy_approach_step(mg_fuzzy_approach_t *a, int64_t t_us, int32_t has_e,
                                          int32_t e_mrad, int32_t has_d_pixel,
                                          int32_t d_pixel);
mg_ops_t mg_fuzzy_eval_ops(void);

#endif
