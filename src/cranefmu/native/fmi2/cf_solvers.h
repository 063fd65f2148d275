/* The fixed-step internal solvers of the native FMU, operation for operation as
   cranefmu.adapter.integrators (euler, rk2, rk4 as rk4_list, trbdf2; rk45 as scipy's RK45), over a model's right-hand side with the
   inputs u0 + s r1 + s^2/2 r2 (s: time into the communication step), as cranefmu.adapter.fmi_adapter.advance. */
#ifndef CF_SOLVERS_H
#define CF_SOLVERS_H

#include <stddef.h>

#include "cf_model.h"

typedef struct CfRhs {
    const CfModel *m;
    double t0;              /* start of the communication step [s] */
    const double *u0, *r1, *r2;
    int moving;             /* 0: the inputs are u0 over the whole step */
    int n_inputs;
    double *u;              /* scratch for the inputs at t (n_inputs) */
} CfRhs;

/* dx = f(t, x) with the inputs at t */
void cf_rhs(CfRhs *f, double t, const double *x, double *dx);

/* Number of equal sub-steps over h (integrators.substeps): max(1, ceil(h / max_step - 1e-9)); -1 if
   that is not a number or more than CF_MAX_SUBSTEPS. */
#define CF_MAX_SUBSTEPS 100000000L
long cf_substeps(double h, double max_step);

/* x1 = x0 advanced over h from t0 with method CF_EULER, CF_RK2, CF_RK4, CF_TRBDF2 or CF_RK45 (rtol: its
   relative tolerance, absolute 1e-3 rtol, as cranefmu.adapter.fmi_adapter.advance); n states; returns 0, or 1 with
   one line in msg. x1 may not alias x0. */
int cf_integrate(CfRhs *f, int method, double t0, const double *x0, int n, double h, double max_step, double rtol,
                 double *x1, char *msg, size_t msg_size);

#endif
