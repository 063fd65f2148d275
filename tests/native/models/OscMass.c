/* Test model of the native FMI layer (not shipped): the C twin of
   cranefmu_support.oscillator.OscMass (mass m on a spring k and damper d to the ground, pushed by a
   coupling force F: m a = F + f - k x - d v), operation for operation as the Python model. */
#include "cf_model.h"
#include "OscMass_tables.h"

int cf_check_params(CfModel *m) {
    if (m->p[P_start] == SW_start_equilibrium && m->p[P_k] <= 0)
        return cf_fail(m, "mass.k must be > 0 for start = 'equilibrium'");
    return 0;
}

int cf_prepare(CfModel *m) {
    m->n_states = 2;
    return 0;
}

int cf_initial_state(CfModel *m, const double *u, double *x) {
    const double *p = m->p;
    if (p[P_start] == SW_start_equilibrium) {
        x[0] = (p[P_f] + u[IN_F]) / p[P_k];
        x[1] = 0.0;
    } else {
        x[0] = p[P_x0];
        x[1] = p[P_v0];
    }
    return 0;
}

static double acc(const double *p, const double *x, const double *u) {
    return (u[IN_F] + p[P_f] - p[P_k] * x[0] - p[P_d] * x[1]) / p[P_m];
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx) {
    (void)t;
    dx[0] = x[1];
    dx[1] = acc(m->p, x, u);
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y) {
    (void)t;
    y[OUT_x] = x[0];
    y[OUT_v] = x[1];
    y[OUT_a] = acc(m->p, x, u);
    y[OUT_flag] = x[0] > m->p[P_x_flag] ? 1.0 : 0.0;
}

int cf_frozen(const CfModel *m) { (void)m; return 0; }
int cf_exact_applies(const CfModel *m) { (void)m; return 1; }

int cf_exact_step(CfModel *m, double t, const double *x, double h, const double *u0, const double *r1,
                  const double *r2, double max_step, double *x1) {
    (void)m; (void)t; (void)x; (void)h; (void)u0; (void)r1; (void)r2; (void)max_step; (void)x1;
    return 0;
}

void cf_after_step(const CfModel *m, double t, double *x, const double *u) { (void)m; (void)t; (void)x; (void)u; }

const char *cf_state_name(const CfModel *m, int i) {
    static const char *const names[] = {"x", "v"};
    (void)m;
    return i >= 0 && i < 2 ? names[i] : "?";
}

const int cf_has_exact_step = 0;
