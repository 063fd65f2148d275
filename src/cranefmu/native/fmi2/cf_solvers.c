/* Fixed-step solvers, operation for operation as cranefmu/adapter/integrators.py, so that the native FMU's
   states equal the pythonfmu FMU's to the last bit (euler, rk2, rk4).  trbdf2 follows the same steps
   (Bank et al. 1985, gamma = 2 - sqrt(2); simplified Newton with the inverse of I - c h J kept over the
   sub-steps while Newton converges, halving a sub-step at most 8 times), but its inverse and
   matrix-vector products are this file's Gauss-Jordan elimination and plain sums, not LAPACK and BLAS:
   equal to round-off, not bitwise (docs/fmus.md). */
#include "cf_solvers.h"
#include "cf_fmi2.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define N_MAX CF_MAX_STATES

void cf_rhs(CfRhs *f, double t, const double *x, double *dx) {
    if (!f->moving) {
        cf_derivatives(f->m, t, x, f->u0, dx);
        return;
    }
    /* u0 + s (r1 + s/2 r2), as fmi_adapter._list_rhs: half = 0.5 * s; a + s * (b + half * c) */
    double s = t - f->t0, half = 0.5 * s;
    for (int i = 0; i < f->n_inputs; i++) f->u[i] = f->u0[i] + s * (f->r1[i] + half * f->r2[i]);
    cf_derivatives(f->m, t, x, f->u, dx);
}

long cf_substeps(double h, double max_step) {
    double n = ceil(h / max_step - 1e-9);
    if (!(n <= (double)CF_MAX_SUBSTEPS)) return -1;
    return n < 1.0 ? 1 : (long)n;
}

/* --- explicit steps (integrators._euler, _rk2, rk4_list) ------------------------------------- */
static void euler_step(CfRhs *f, double t, double *x, int n, double h) {
    double k1[N_MAX];
    cf_rhs(f, t, x, k1);
    for (int i = 0; i < n; i++) x[i] = x[i] + h * k1[i];
}

static void rk2_step(CfRhs *f, double t, double *x, int n, double h) {
    double k1[N_MAX], k2[N_MAX], xs[N_MAX];
    cf_rhs(f, t, x, k1);
    for (int i = 0; i < n; i++) xs[i] = x[i] + h * k1[i];
    cf_rhs(f, t + h, xs, k2);
    double half_h = 0.5 * h;  /* x + 0.5 * h * (k1 + k2): numpy multiplies the scalars first */
    for (int i = 0; i < n; i++) x[i] = x[i] + half_h * (k1[i] + k2[i]);
}

static void rk4_step(CfRhs *f, double t, double *x, int n, double dt) {
    double k1[N_MAX], k2[N_MAX], k3[N_MAX], k4[N_MAX], xs[N_MAX];
    double half = 0.5 * dt, sixth = dt / 6.0;
    cf_rhs(f, t, x, k1);
    for (int i = 0; i < n; i++) xs[i] = x[i] + half * k1[i];
    cf_rhs(f, t + 0.5 * dt, xs, k2);
    for (int i = 0; i < n; i++) xs[i] = x[i] + half * k2[i];
    cf_rhs(f, t + 0.5 * dt, xs, k3);
    for (int i = 0; i < n; i++) xs[i] = x[i] + dt * k3[i];
    cf_rhs(f, t + dt, xs, k4);
    for (int i = 0; i < n; i++) x[i] = x[i] + sixth * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* --- TR-BDF2 (integrators._trbdf2) ------------------------------------------------------------- */
#define NEWTON_ITERATIONS 12

typedef struct {
    double gamma, c, w_g, w_0;
} Trbdf2Constants;

static Trbdf2Constants trbdf2_constants(void) {
    Trbdf2Constants k;
    k.gamma = 2.0 - sqrt(2.0);
    k.c = 0.5 * k.gamma;
    k.w_g = 1.0 / (k.gamma * (2.0 - k.gamma));
    k.w_0 = pow(1.0 - k.gamma, 2.0) / (k.gamma * (2.0 - k.gamma));
    return k;
}

/* inverse of I - ch J (J by forward differences at (t, x)); 1 when the matrix is singular */
static int fresh_inverse(CfRhs *f, double t, const double *x, int n, double ch, double *inv) {
    double fx[N_MAX], fp[N_MAX], xp[N_MAX], a[N_MAX * N_MAX];
    cf_rhs(f, t, x, fx);
    for (int j = 0; j < n; j++) {
        double dx = 1.49e-8 * (fabs(x[j]) > 1.0 ? fabs(x[j]) : 1.0);
        memcpy(xp, x, sizeof(double) * (size_t)n);
        xp[j] += dx;
        cf_rhs(f, t, xp, fp);
        for (int i = 0; i < n; i++) a[i * n + j] = (i == j ? 1.0 : 0.0) - ch * ((fp[i] - fx[i]) / dx);
    }
    /* Gauss-Jordan with partial pivoting on [a | I] */
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) inv[i * n + j] = i == j ? 1.0 : 0.0;
    for (int col = 0; col < n; col++) {
        int piv = col;
        for (int r = col + 1; r < n; r++)
            if (fabs(a[r * n + col]) > fabs(a[piv * n + col])) piv = r;
        if (a[piv * n + col] == 0.0 || !isfinite(a[piv * n + col])) return 1;
        if (piv != col)
            for (int j = 0; j < n; j++) {
                double s = a[col * n + j]; a[col * n + j] = a[piv * n + j]; a[piv * n + j] = s;
                s = inv[col * n + j]; inv[col * n + j] = inv[piv * n + j]; inv[piv * n + j] = s;
            }
        double d = a[col * n + col];
        for (int j = 0; j < n; j++) {
            a[col * n + j] /= d;
            inv[col * n + j] /= d;
        }
        for (int r = 0; r < n; r++) {
            if (r == col) continue;
            double factor = a[r * n + col];
            if (factor == 0.0) continue;
            for (int j = 0; j < n; j++) {
                a[r * n + j] -= factor * a[col * n + j];
                inv[r * n + j] -= factor * inv[col * n + j];
            }
        }
    }
    return 0;
}

/* simplified Newton for y = a + ch f(t, y) from y; 0, or 1 when it does not converge (message) */
static int solve_stage(CfRhs *f, double t, const double *a, double *y, int n, double ch, const double *inv,
                       double tol, const Trbdf2Constants *k, char *msg, size_t msg_size) {
    double fy[N_MAX], r[N_MAX], dy[N_MAX];
    for (int it = 0; it < NEWTON_ITERATIONS; it++) {
        cf_rhs(f, t, y, fy);
        for (int i = 0; i < n; i++) r[i] = y[i] - a[i] - ch * fy[i];
        for (int i = 0; i < n; i++) {
            double s = 0.0;
            for (int j = 0; j < n; j++) s += inv[i * n + j] * r[j];
            dy[i] = s;
        }
        int converged = 1;
        for (int i = 0; i < n; i++) {
            y[i] = y[i] - dy[i];
            if (!(fabs(dy[i]) <= tol * (1.0 + fabs(y[i])))) converged = 0;
        }
        if (converged) return 0;
    }
    snprintf(msg, msg_size, "solver trbdf2: Newton iteration did not converge at t = %.6g s (sub-step %.3g s)", t,
             ch / k->c);
    return 1;
}

static int trbdf2_step(CfRhs *f, double t, double *x, int n, double dt, const double *inv, double tol,
                       const Trbdf2Constants *k, char *msg, size_t msg_size) {
    double fx[N_MAX], a[N_MAX], xg[N_MAX], fg[N_MAX], y[N_MAX];
    double ch = k->c * dt, g_dt = k->gamma * dt, rest_dt = (1.0 - k->gamma) * dt;
    cf_rhs(f, t, x, fx);
    double tg = t + k->gamma * dt;
    for (int i = 0; i < n; i++) {
        a[i] = x[i] + ch * fx[i];
        xg[i] = x[i] + g_dt * fx[i];
    }
    if (solve_stage(f, tg, a, xg, n, ch, inv, tol, k, msg, msg_size)) return 1;
    cf_rhs(f, tg, xg, fg);
    for (int i = 0; i < n; i++) {
        a[i] = k->w_g * xg[i] - k->w_0 * x[i];
        y[i] = xg[i] + rest_dt * fg[i];
    }
    if (solve_stage(f, t + dt, a, y, n, ch, inv, tol, k, msg, msg_size)) return 1;
    memcpy(x, y, sizeof(double) * (size_t)n);
    return 0;
}

static int trbdf2(CfRhs *f, double t0, double *x, int n, double dt, long steps, double tol, int depth,
                  char *msg, size_t msg_size) {
    Trbdf2Constants k = trbdf2_constants();
    double inv[N_MAX * N_MAX], trial[N_MAX];
    int have_inverse = 0;
    for (long i = 0; i < steps; i++) {
        double t = t0 + (double)i * dt;
        int failed = 0;
        if (!have_inverse) {
            if (fresh_inverse(f, t, x, n, k.c * dt, inv)) {
                snprintf(msg, msg_size, "solver trbdf2: singular Newton matrix at t = %.6g s", t);
                failed = 1;
            } else {
                have_inverse = 1;
            }
        }
        if (!failed) {
            memcpy(trial, x, sizeof(double) * (size_t)n);
            if (trbdf2_step(f, t, trial, n, dt, inv, tol, &k, msg, msg_size)) {
                if (fresh_inverse(f, t, x, n, k.c * dt, inv)) {
                    snprintf(msg, msg_size, "solver trbdf2: singular Newton matrix at t = %.6g s", t);
                    failed = 1;
                } else {
                    memcpy(trial, x, sizeof(double) * (size_t)n);
                    failed = trbdf2_step(f, t, trial, n, dt, inv, tol, &k, msg, msg_size);
                }
            }
            if (!failed) memcpy(x, trial, sizeof(double) * (size_t)n);
        }
        if (failed) {
            if (depth >= 8) return 1;
            if (trbdf2(f, t, x, n, 0.5 * dt, 2, tol, depth + 1, msg, msg_size)) return 1;
            have_inverse = 0;
        }
    }
    return 0;
}

/* --- rk45: Dormand-Prince 5(4) with scipy's step control (scipy.integrate.RK45 as solve_ivp runs it
   from t0 to t0 + h: its initial step selection, error norm, safety factors and step rejection). Its
   dot products are plain sums where scipy calls BLAS: equal to round-off while both take the same
   steps (docs/fmus.md). ------------------------------------------------------------------------- */
static const double RK45_C[6] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0};
static const double RK45_A[6][5] = {
    {0.0, 0.0, 0.0, 0.0, 0.0},
    {1.0 / 5, 0.0, 0.0, 0.0, 0.0},
    {3.0 / 40, 9.0 / 40, 0.0, 0.0, 0.0},
    {44.0 / 45, -56.0 / 15, 32.0 / 9, 0.0, 0.0},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0.0},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656}};
static const double RK45_B[6] = {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84};
static const double RK45_E[7] = {-71.0 / 57600, 0.0, 71.0 / 16695, -71.0 / 1920, 17253.0 / 339200, -22.0 / 525,
                                 1.0 / 40};

static double rms_norm(const double *v, int n) {  /* np.linalg.norm(v) / v.size ** 0.5 */
    double s = 0.0;
    for (int i = 0; i < n; i++) s += v[i] * v[i];
    return sqrt(s) / pow((double)n, 0.5);
}

static double rk45_initial_step(CfRhs *f, double t0, const double *y0, const double *f0, int n, double t_bound,
                                double max_step, double direction, double rtol, double atol) {
    double scale[N_MAX], v[N_MAX], y1[N_MAX], f1[N_MAX];
    double interval = fabs(t_bound - t0), h0, h1, d0, d1, d2;
    if (interval == 0.0) return 0.0;
    for (int i = 0; i < n; i++) scale[i] = atol + fabs(y0[i]) * rtol;
    for (int i = 0; i < n; i++) v[i] = y0[i] / scale[i];
    d0 = rms_norm(v, n);
    for (int i = 0; i < n; i++) v[i] = f0[i] / scale[i];
    d1 = rms_norm(v, n);
    h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (interval < h0) h0 = interval;
    double step = h0 * direction;
    for (int i = 0; i < n; i++) y1[i] = y0[i] + step * f0[i];
    cf_rhs(f, t0 + h0 * direction, y1, f1);
    for (int i = 0; i < n; i++) v[i] = (f1[i] - f0[i]) / scale[i];
    d2 = rms_norm(v, n) / h0;
    if (d1 <= 1e-15 && d2 <= 1e-15)
        h1 = 1e-6 > h0 * 1e-3 ? 1e-6 : h0 * 1e-3;
    else
        h1 = pow(0.01 / (d2 > d1 ? d2 : d1), 1.0 / 5);
    double h = 100 * h0;
    if (h1 < h) h = h1;
    if (interval < h) h = interval;
    if (max_step < h) h = max_step;
    return h;
}

static int rk45(CfRhs *f, double t0, double *y, int n, double h_total, double rtol_set, double max_step, char *msg,
                size_t msg_size) {
    double atol = 1e-3 * rtol_set, rtol = rtol_set < 100 * 2.220446049250313e-16 ? 100 * 2.220446049250313e-16
                                                                                 : rtol_set;
    double t = t0, t_bound = t0 + h_total, direction = t_bound > t0 ? 1.0 : t_bound < t0 ? -1.0 : 1.0;
    double fy[N_MAX], K[7][N_MAX], ys[N_MAX], y_new[N_MAX], err[N_MAX];
    cf_rhs(f, t, y, fy);
    double h_abs_next = rk45_initial_step(f, t, y, fy, n, t_bound, max_step, direction, rtol, atol);
    while (t != t_bound) {
        double min_step = 10 * fabs(nextafter(t, direction * HUGE_VAL) - t);
        double h_abs = h_abs_next > max_step ? max_step : h_abs_next < min_step ? min_step : h_abs_next;
        double t_new = t, h = 0.0;
        int accepted = 0, rejected = 0;
        while (!accepted) {
            if (h_abs < min_step) {
                snprintf(msg, msg_size, "solver rk45 failed at t = %.6g s: Required step size is less than spacing "
                         "between numbers.", t0);
                return 1;
            }
            h = h_abs * direction;
            t_new = t + h;
            if (direction * (t_new - t_bound) > 0) t_new = t_bound;
            h = t_new - t;
            h_abs = fabs(h);
            memcpy(K[0], fy, sizeof(double) * (size_t)n);
            for (int s = 1; s < 6; s++) {
                for (int i = 0; i < n; i++) {
                    double dot = 0.0;
                    for (int j = 0; j < s; j++) dot += K[j][i] * RK45_A[s][j];
                    ys[i] = y[i] + dot * h;
                }
                cf_rhs(f, t + RK45_C[s] * h, ys, K[s]);
            }
            for (int i = 0; i < n; i++) {
                double dot = 0.0;
                for (int j = 0; j < 6; j++) dot += K[j][i] * RK45_B[j];
                y_new[i] = y[i] + h * dot;
            }
            cf_rhs(f, t + h, y_new, K[6]);
            for (int i = 0; i < n; i++) {
                double dot = 0.0, big = fabs(y[i]) > fabs(y_new[i]) ? fabs(y[i]) : fabs(y_new[i]);
                for (int j = 0; j < 7; j++) dot += K[j][i] * RK45_E[j];
                err[i] = dot * h / (atol + big * rtol);
            }
            double error_norm = rms_norm(err, n);
            if (error_norm < 1) {
                double factor = 10.0;
                if (error_norm != 0) {
                    double grow = 0.9 * pow(error_norm, -1.0 / 5);
                    factor = grow < 10.0 ? grow : 10.0;
                }
                if (rejected && !(factor < 1.0)) factor = 1.0;
                h_abs *= factor;
                accepted = 1;
            } else {
                double shrink = 0.9 * pow(error_norm, -1.0 / 5);
                h_abs *= shrink > 0.2 ? shrink : 0.2;
                rejected = 1;
            }
        }
        t = t_new;
        memcpy(y, y_new, sizeof(double) * (size_t)n);
        memcpy(fy, K[6], sizeof(double) * (size_t)n);
        h_abs_next = h_abs;
        if (direction * (t - t_bound) >= 0) break;
    }
    return 0;
}

int cf_integrate(CfRhs *f, int method, double t0, const double *x0, int n, double h, double max_step, double rtol,
                 double *x1, char *msg, size_t msg_size) {
    memcpy(x1, x0, sizeof(double) * (size_t)n);
    if (n == 0 || h == 0.0) return 0;
    if (method == CF_RK45) return rk45(f, t0, x1, n, h, rtol, max_step, msg, msg_size);
    long steps = cf_substeps(h, max_step);
    if (steps < 0) {
        snprintf(msg, msg_size, "h = %.9g s over max_step = %.9g s needs more than %ld sub-steps", h, max_step,
                 CF_MAX_SUBSTEPS);
        return 1;
    }
    double dt = h / (double)steps;
    if (method == CF_TRBDF2) return trbdf2(f, t0, x1, n, dt, steps, 1e-10, 0, msg, msg_size);
    for (long i = 0; i < steps; i++) {
        double t = t0 + (double)i * dt;
        if (method == CF_EULER)
            euler_step(f, t, x1, n, dt);
        else if (method == CF_RK2)
            rk2_step(f, t, x1, n, dt);
        else
            rk4_step(f, t, x1, n, dt);
    }
    return 0;
}
