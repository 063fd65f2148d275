/* Overhead crane girder and drum bearing carrying the trolley (seed 001 eq. 6 and 10, Table 6, Fig. 4):
   C twin of cranefmu.physics.girder.

   The bridge girder is reduced to a mass m1 at mid-span on a spring c1 with damper b1; the rope drum
   (m3) sits on it through the drum-bearing stiffness c3 (Fig. 4, E_p term 0.5 c3 (q1 - q3)^2).
   Lagrange equations of eq. 6 restricted to q1, q3 (derived), q positive up from the unloaded,
   weightless girder:

       m1 q1'' = -c1 q1 - b1 q1' + c3 (q3 - q1) + b3 (q3' - q1') - m1 g
       m3 q3'' = -c3 (q3 - q1) - b3 (q3' - q1') - m3 g + Fy_rope

   bearing = rigid ties the drum to the girder (q3 = q1, one degree of freedom of mass m1 + m3; the q3
   states copy q1).  mass_model = beam: m1 = 17/35 of the girder's mass (Rayleigh, static deflection
   shape of a simply supported beam).  damping_model = decrement: eq. 10, delta = 3.8 h / L - 0.13, and
   b1 = 2 delta sqrt(c1 m) / sqrt(4 pi^2 + delta^2) with m = m1 + m3 (the exact single-degree-of-freedom
   relation; derived).  Linear: solver exact steps it in closed form (cf_linear_step). */
#include <math.h>
#include <string.h>

#include "cf_model.h"
#include "cf_linear_step.h"
#include "cf_repr.h"
#include "Girder_tables.h"

const int cf_has_exact_step = 1;

typedef struct GirderData {
    double m1;          /* reduced mass in use [kg] */
    double modal_mass;  /* m1 + m3 [kg] */
    double b1;          /* girder damping in use [N s/m] */
    CfLinearStep linear;
} GirderData;

typedef char girder_data_fits[sizeof(GirderData) <= sizeof(double) * CF_MODEL_DATA ? 1 : -1];

#define DATA(m) ((GirderData *)(m)->data)
#define CDATA(m) ((const GirderData *)(m)->data)

/* Logarithmic decrement of a welded box girder, delta = 3.8 h / L - 0.13 [1] (seed 001 eq. 10). */
static double eq10_decrement(double height, double span)
{
    return 3.8 * height / span - 0.13;
}

/* Rayleigh's reduced mass of a uniform simply supported beam at mid-span, static deflection shape */
#define CF_PI 3.141592653589793   /* math.pi */
#define BEAM_MASS_FRACTION (17.0 / 35.0)

/* Viscous damping [N s/m] giving the logarithmic decrement delta to an oscillator (c, m) (derived, eq. 10). */
static double damping_from_decrement(double delta, double c, double m)
{
    return 2.0 * delta * sqrt(c * m) / sqrt(4.0 * pow(CF_PI, 2.0) + pow(delta, 2.0));
}

int cf_check_params(CfModel *m)
{
    const double *p = m->p;
    char a[CF_REPR_SIZE], b[CF_REPR_SIZE];
    if ((int)p[P_mass_model] == SW_mass_model_beam && p[P_m1] != 5000.0)
        return cf_fail(m, "girder.m1 = %s is not used with girder.mass_model = 'beam' (m1 is 17/35 "
                       "of girder_mass): allowed 5000.0 here, or set mass_model = 'table'", cf_repr(p[P_m1], a));
    if ((int)p[P_damping_model] == SW_damping_model_decrement
        && eq10_decrement(p[P_girder_height], p[P_span]) <= 0.0)
        return cf_fail(m, "girder.girder_height = %s is too low for eq. 10: delta = 3.8 h / L - 0.13 must be > 0, "
                       "allowed girder_height > %.6g m at span %s m", cf_repr(p[P_girder_height], a),
                       0.13 / 3.8 * p[P_span], cf_repr(p[P_span], b));
    return 0;
}

int cf_prepare(CfModel *m)
{
    const double *p = m->p;
    GirderData *d = DATA(m);
    double a[16], bias[4], big_b[12];
    int rigid = (int)p[P_bearing] == SW_bearing_rigid;

    /* reduced_mass, modal_mass, girder_damping */
    d->m1 = (int)p[P_mass_model] == SW_mass_model_table ? p[P_m1] : BEAM_MASS_FRACTION * p[P_girder_mass];
    d->modal_mass = d->m1 + p[P_m3];
    d->b1 = (int)p[P_damping_model] == SW_damping_model_table
          ? p[P_b1] : damping_from_decrement(eq10_decrement(p[P_girder_height], p[P_span]), p[P_c1], d->modal_mass);
    m->n_states = 4;

    /* linear_system: A, b, B of x' = A x + b + B u (derivatives written as matrices; derived) */
    memset(a, 0, sizeof a);
    memset(big_b, 0, sizeof big_b);
    a[0 * 4 + 1] = 1.0;
    if (rigid) {   /* q3, v3 copy q1, v1 */
        double mm = d->modal_mass;
        a[2 * 4 + 1] = 1.0;
        a[1 * 4 + 0] = a[3 * 4 + 0] = -p[P_c1] / mm;
        a[1 * 4 + 1] = a[3 * 4 + 1] = -d->b1 / mm;
        big_b[1 * 3 + IN_Fy_rope] = big_b[3 * 3 + IN_Fy_rope] = 1.0 / mm;
    } else {
        double m1 = d->m1, m3 = p[P_m3];
        a[2 * 4 + 3] = 1.0;
        a[1 * 4 + 0] = (-p[P_c1] - p[P_c3]) / m1;
        a[1 * 4 + 1] = (-d->b1 - p[P_b3]) / m1;
        a[1 * 4 + 2] = p[P_c3] / m1;
        a[1 * 4 + 3] = p[P_b3] / m1;
        a[3 * 4 + 0] = p[P_c3] / m3;
        a[3 * 4 + 1] = p[P_b3] / m3;
        a[3 * 4 + 2] = -p[P_c3] / m3;
        a[3 * 4 + 3] = -p[P_b3] / m3;
        big_b[3 * 3 + IN_Fy_rope] = 1.0 / m3;
    }
    bias[0] = 0.0;
    bias[1] = -p[P_g];
    bias[2] = 0.0;
    bias[3] = -p[P_g];
    if (cf_linear_init(&d->linear, 4, 3, a, bias, big_b, 0))
        return cf_fail(m, "girder: linear system too large for the exact step");
    return 0;
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    /* static_deflections: static q1 (girder) and q3 (suspension point) under the rope force and gravity */
    const double *p = m->p;
    const GirderData *d = CDATA(m);
    double fy = u[IN_Fy_rope];
    double q1 = (fy - d->modal_mass * p[P_g]) / p[P_c1];
    double q3 = (int)p[P_bearing] == SW_bearing_rigid ? q1 : q1 + (fy - p[P_m3] * p[P_g]) / p[P_c3];
    x[0] = q1;
    x[1] = 0.0;
    x[2] = q3;
    x[3] = 0.0;
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    const double *p = m->p;
    const GirderData *d = CDATA(m);
    double q1 = x[0], v1 = x[1], q3 = x[2], v3 = x[3];
    double fy = u[IN_Fy_rope], b1 = d->b1, f3, a1, a3;
    (void)t;
    if ((int)p[P_bearing] == SW_bearing_rigid) {
        a1 = (-p[P_c1] * q1 - b1 * v1 + fy) / d->modal_mass - p[P_g];
        dx[0] = v1;
        dx[1] = a1;
        dx[2] = v1;
        dx[3] = a1;
        return;
    }
    f3 = p[P_c3] * (q3 - q1) + p[P_b3] * (v3 - v1);
    a1 = (-p[P_c1] * q1 - b1 * v1 + f3) / d->m1 - p[P_g];
    a3 = (fy - f3) / p[P_m3] - p[P_g];
    dx[0] = v1;
    dx[1] = a1;
    dx[2] = v3;
    dx[3] = a3;
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    const double *p = m->p;
    double q1 = x[0], v1 = x[1], q3 = x[2], v3 = x[3];
    (void)t;
    (void)u;
    if ((int)p[P_bearing] == SW_bearing_rigid) {
        q3 = q1;
        v3 = v1;
    }
    y[OUT_x_top] = p[P_x_pos];
    y[OUT_y_top] = p[P_height] + q3;
    y[OUT_z_top] = p[P_z_pos];
    y[OUT_vx_top] = 0.0;
    y[OUT_vy_top] = v3;
    y[OUT_vz_top] = 0.0;
    y[OUT_deflection] = q3;
    y[OUT_girder_deflection] = q1;
}

int cf_frozen(const CfModel *m)
{
    (void)m;
    return 0;
}

CF_APPLIES_ALWAYS

int cf_exact_step(CfModel *m, double t, const double *x, double h, const double *u0, const double *r1,
                  const double *r2, double max_step, double *x1)
{
    /* closed-form step of the linear model: x(h) = [expm(Z h) z]_x, z = (x, 1, u0, r1, r2) */
    GirderData *d = DATA(m);
    double z[CF_LS_MAX_SIZE];
    const CfLinearMaps *maps = cf_linear_maps(&d->linear, h, 1);
    (void)t;
    (void)max_step;
    cf_linear_augment(&d->linear, x, u0, r1, r2, z);
    cf_linear_apply(&d->linear, maps->end, 4, z, x1);
    return 1;
}

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    static const char *names[] = {"q1", "v1", "q3", "v3"};
    (void)m;
    return i >= 0 && i < 4 ? names[i] : "?";
}
