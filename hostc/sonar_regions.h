/* Sonar sub-regions and infeasible regions of 001 (eqs. (15)-(16)) in integers
 * (host/planning/sonar_regions.py): a reading's regions from a pose, and each region's words
 * (the apex, the bisector's cos and sin, tan of the half-angle, the band, the arc bound, the
 * echo arc's ends and middle). Positions, ranges and radii in 1/16 mm, angles in micro-radians,
 * trigonometry in Q14, cos^2 of the bound in Q16. No allocation, no float. */
#ifndef MG_SONAR_REGIONS_H
#define MG_SONAR_REGIONS_H

#include <stdint.h>

#include "budget.h"

#define MG_SONAR_MAX 16                          /* sonars of a ring */
#define MG_SONAR_MAX_REGIONS (2 * MG_SONAR_MAX - 1) /* eq. (15)'s sub-regions at most */

/* sonar_regions.py SonarQ: the ring's configuration in integers (tol_q4 < 0: no shared-echo
 * rule) */
typedef struct {
    int32_t k_s;
    int64_t a_g_urad, d_e_q4, r_r_q4, tol_q4, offset_q4;
    int32_t arc_bound;
    int32_t cot_half_q12;
} mg_sonar_cfg_t;

/* sonar_regions.py InfeasibleRegion */
typedef struct {
    int64_t ox_q4, oy_q4, lo_urad, hi_urad, eta_q4, r_r_q4;
    int32_t arc_bound;
} mg_region_t;

/* sonar_regions.py RegionWords */
typedef struct {
    int64_t qx, qy, cos_mid, sin_mid, tan_half, lo2, hi2;
    int32_t arc, cb_pos;
    int64_t cb2_q16, e1x, e1y, e2x, e2y, mx, my;
} mg_region_words_t;

/* eq. (15): the sub-regions of the ranges rho_q4[0..k_s) (1/16 mm) relative to the heading:
 * their lo, hi (urad) and eta (1/16 mm) in out_lo, out_hi, out_eta; returns their number
 * (k_s or 2 k_s - 1), 0 when k_s is outside 2..MG_SONAR_MAX */
int32_t mg_sonar_sub_regions(const mg_sonar_cfg_t *cfg, const int64_t *rho_q4, int64_t *out_lo,
                             int64_t *out_hi, int64_t *out_eta);
/* the infeasible regions of one reading (sonar_mm[0..k_s), mm; negative: not a reading,
 * counted in *dropped and taken as no echo) at (px, py) (1/16 mm) and heading_urad; returns
 * their number (at most MG_SONAR_MAX_REGIONS) */
int32_t mg_sonar_regions(const mg_sonar_cfg_t *cfg, int64_t px_q4, int64_t py_q4,
                         int64_t heading_urad, const int32_t *sonar_mm, mg_region_t *out,
                         int32_t *dropped);
/* a region's words (sonar_regions.py region_words) */
void mg_region_words(const mg_region_t *reg, mg_region_words_t *w);
/* bezier.h geo's MG_REGION_WORDS words of a region */
void mg_region_geo(const mg_region_t *reg, int64_t *out);
/* clearance.c's MG_CLEAR_WORDS words of a region */
void mg_region_clear(const mg_region_t *reg, int64_t *out);
/* a region's words' ARM9 cost (sonar_regions.py REGION_SETUP_OPS) */
mg_ops_t mg_region_setup_ops(void);

#endif
