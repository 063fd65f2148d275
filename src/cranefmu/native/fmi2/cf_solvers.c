/* Fixed-step solvers, operation for operation as cranefmu/integrators.py, so that the native FMU's
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

int cf_integrate(CfRhs *f, int method, double t0, const double *x0, int n, double h, double max_step,
                 double *x1, char *msg, size_t msg_size) {
    memcpy(x1, x0, sizeof(double) * (size_t)n);
    if (n == 0 || h == 0.0) return 0;
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
