/* One candidate curve of the Bezier planners checked as host/planning/candidates.py does
 * (evaluate_batch): the power-form coefficients of eq. (6) of 000, t_tau's exact minimum over
 * [0, 1] before the first sample, then per sample tau_j in the order of the Python's checks
 * (grasp circle and infeasible regions for 001, then time increasing, speed, acceleration, and
 * the turning radius for 000), stopping at the first violation as the board would. The
 * derivatives of eq. (7) are evaluated by Horner's rule; speed, a_t and kappa by the Python's
 * formulas (bezier.py evaluate), so both agree to a few ulp and decide alike. */
#include "bezier.h"
#include "dsqrt.h"

static double min_t_tau(const double *k)
{
    /* k: the t coefficients c0..c3; t_tau = c1 + 2 c2 tau + 3 c3 tau^2 (candidates.min_t_tau) */
    const double c1 = k[1], c2 = k[2], c3 = k[3];
    const double end = c1 + 2.0 * c2 + 3.0 * c3;
    double m = c1 < end ? c1 : end;
    if (c3 > 0.0) {
        const double tv = -c2 / (3.0 * c3);
        if (tv > 0.0 && tv < 1.0) {
            const double vertex = c1 + 2.0 * c2 * tv + 3.0 * c3 * tv * tv;
            if (vertex < m)
                m = vertex;
        }
    }
    return m;
}

static int in_region(const double *r, double x, double y)
{
    const double px = x - r[0], py = y - r[1];
    const double along = px * r[2] + py * r[3];
    if (!(along > 0.0))
        return 0;
    const double across = __builtin_fabs(py * r[2] - px * r[3]);
    if (!(across <= along * r[4]))
        return 0;
    const double rx = x - r[5], ry = y - r[6];
    const double d2 = rx * rx + ry * ry;
    if (!(d2 >= r[7]) || !(d2 <= r[8]))
        return 0;
    if (r[9] != 0.0) {
        /* |atan2(a, b)| <= bound  <=>  b >= |(rx, ry)| cos(bound): squared, by the sign of
         * cos(bound) (r[10]), without a root or an arctangent */
        const double b = rx * r[2] + ry * r[3];
        const double bb = b * b, lim = d2 * r[11];
        if (r[10] != 0.0 ? !(b >= 0.0 && bb >= lim) : !(b >= 0.0 || bb <= lim))
            return 0;
    }
    return 1;
}

int32_t mg_bezier_curve(const double *ctrl, int32_t n, const double *lim, const double *geo,
                        int32_t n_reg, int32_t *first, double *len, double *kint)
{
    /* coefficients of eq. (6) per coordinate c (x, y, t): k0 = P0, k1 = 3 (P1 - P0),
     * k2 = 3 (P0 - 2 P1 + P2), k3 = -P0 + 3 P1 - 3 P2 + P3 */
    double k[3][4], d1[3], d2[3];
    for (int c = 0; c < 3; c++) {
        const double p0 = ctrl[c], p1 = ctrl[3 + c], p2 = ctrl[6 + c], p3 = ctrl[9 + c];
        k[c][0] = p0;
        k[c][1] = 3.0 * (p1 - p0);
        k[c][2] = 3.0 * (p0 - 2.0 * p1 + p2);
        k[c][3] = -p0 + 3.0 * p1 - 3.0 * p2 + p3;
        d1[c] = 2.0 * k[c][2];  /* x_tau = k1 + tau (2 k2 + tau 3 k3) */
        d2[c] = 3.0 * k[c][3];
    }
    const double v_max = lim[0], a_max = lim[1], kappa_max = lim[2];
    const int normal = lim[3] != 0.0;
    const double step = 1.0 / (double)(n - 1);
    double tau_prev = 0.0, s_prev = 0.0, ak_prev = 0.0, l_sum = 0.0, k_sum = 0.0;
    for (int32_t j = 0; j < n; j++) {
        const double tau = j == n - 1 ? 1.0 : (double)j * step;  /* numpy linspace */
        int32_t why = MG_OK;
        if (geo != 0) {
            const double x = k[0][0] + tau * (k[0][1] + tau * (k[0][2] + tau * k[0][3]));
            const double y = k[1][0] + tau * (k[1][1] + tau * (k[1][2] + tau * k[1][3]));
            const double dx = x - geo[0], dy = y - geo[1];
            if (dx * dx + dy * dy < geo[2]) {
                why = MG_CIRCLE;
            } else if (j > 0) {  /* the start is where the robot already is */
                for (int32_t r = 0; r < n_reg; r++)
                    if (in_region(geo + MG_GEO_HEAD + MG_REGION_WORDS * r, x, y)) {
                        why = MG_OBSTACLE;
                        break;
                    }
            }
        }
        if (why == MG_OK && j == 0 && !(min_t_tau(k[2]) > 0.0))
            why = MG_TIME;
        double s = 0.0, ak = 0.0;
        if (why == MG_OK) {
            const double xt = k[0][1] + tau * (d1[0] + tau * d2[0]);
            const double yt = k[1][1] + tau * (d1[1] + tau * d2[1]);
            const double tt = k[2][1] + tau * (d1[2] + tau * d2[2]);
            s = mg_dsqrt(xt * xt + yt * yt);
            if (!(tt > 0.0) || !(s > 0.0)) {
                why = MG_TIME;
            } else {
                const double v = s / tt;
                const double x2 = d1[0] + k[0][3] * (6.0 * tau);  /* 2 k2 + 6 k3 tau */
                const double y2 = d1[1] + k[1][3] * (6.0 * tau);
                if (!(v <= v_max)) {
                    why = MG_SPEED;
                } else if (normal) {
                    const double kappa = (xt * y2 - x2 * yt) / (s * s * s);
                    ak = __builtin_fabs(kappa);
                    if (!(v * v * ak <= a_max))
                        why = MG_ACCEL;
                } else {
                    const double t2 = d1[2] + k[2][3] * (6.0 * tau);
                    const double s_dot = (xt * x2 + yt * y2) / s;
                    const double a_t = (s_dot * tt - s * t2) / (tt * tt) / tt;
                    if (!(__builtin_fabs(a_t) <= a_max)) {
                        why = MG_ACCEL;
                    } else {
                        ak = __builtin_fabs((xt * y2 - x2 * yt) / (s * s * s));
                        if (kappa_max >= 0.0 && !(ak <= kappa_max))
                            why = MG_RADIUS;
                    }
                }
            }
        }
        if (why != MG_OK) {
            *first = j;
            return why;
        }
        if (j > 0) {  /* trapezoid rule over tau (bezier.py _trapezoid) */
            const double d = tau - tau_prev;
            l_sum += 0.5 * (s + s_prev) * d;
            k_sum += 0.5 * (ak + ak_prev) * d;
        }
        tau_prev = tau;
        s_prev = s;
        ak_prev = ak;
    }
    *first = n;
    *len = l_sum;
    *kint = k_sum;
    return MG_OK;
}

double mg_sqrt(double x)
{
    return mg_dsqrt(x);
}
