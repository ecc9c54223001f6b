/* Fixed-point arithmetic of the host (host/fixedpoint.py): Q12 scalars, sine, cosine and atan2
 * on integer mrad, the exact integer square root, rounded division and 3x3 Q12 rotations, with
 * the op counts each call is charged on the ARM920T (budget.h). Formats as there: 1.0 ==
 * MG_ONE_Q12; angles are integer mrad; products round half up. Arithmetic right shifts of
 * negative numbers floor, as Python's >> does (gcc on both targets). */
#ifndef MOBIGRASP_HOSTC_FIXEDPOINT_H
#define MOBIGRASP_HOSTC_FIXEDPOINT_H

#include <stdint.h>

#include "budget.h"
#include "trig.h"

#define MG_Q12_SHIFT 12
#define MG_ONE_Q12 4096
#define MG_PI_MRAD 3142
#define MG_HALF_PI_MRAD 1571

/* fixedpoint.c */
int64_t mg_isqrt(int64_t n);                          /* floor(sqrt(n)), n >= 0 (else -1) */
int64_t mg_hypot_int(int64_t x, int64_t y);           /* floor(sqrt(x^2 + y^2)) */
int64_t mg_mul_q12(int64_t a, int64_t b);             /* (a b + 2048) >> 12 */
int64_t mg_div_round64(int64_t num, int64_t den);     /* halves away from zero; den != 0 */
int64_t mg_div_even64(int64_t num, int64_t den);      /* halves to even (Python's round); den > 0 */
int64_t mg_div_q12(int64_t a, int64_t b);             /* (a << 12) / b rounded; b != 0 */
int64_t mg_floor_div(int64_t a, int64_t b);           /* Python's a // b; b != 0 */
int64_t mg_floor_mod(int64_t a, int64_t b);           /* Python's a % b; b != 0 */
int32_t mg_urad_to_mrad(int64_t urad);                /* rounded, halves away from zero */

typedef int32_t mg_mat_q12[3][3];
void mg_rot_x_q12(int32_t angle_mrad, mg_mat_q12 out);
void mg_rot_y_q12(int32_t angle_mrad, mg_mat_q12 out);
void mg_rot_z_q12(int32_t angle_mrad, mg_mat_q12 out);
void mg_matvec_q12(const mg_mat_q12 m, const int32_t v[3], int32_t out[3]);
void mg_matmul_q12(const mg_mat_q12 a, const mg_mat_q12 b, mg_mat_q12 out);
void mg_transpose_q12(const mg_mat_q12 m, mg_mat_q12 out);

/* What one call costs on the ARM920T (host/fixedpoint.py *_ops). */
mg_ops_t mg_sin_ops(void);
mg_ops_t mg_atan2_ops(void);
mg_ops_t mg_isqrt_ops(int64_t n);
mg_ops_t mg_mul_q12_ops(int32_t k);
mg_ops_t mg_matvec_ops(void);
mg_ops_t mg_rot_ops(void);

#endif
