/* Truck body and slewing platform of the truck crane 55713-1K on two elastic outriggers (seed 000):
   C twin of cranefmu.physics.chassis.

   Rigid body in the working plane (seed 000 eq. 3-10, Table 1): body 9 and slewing platform 8 fixed to
   each other; front outrigger 1 and rear outrigger 2 are l7 apart; the boom foot O2 is above C8
   (eq. 11).  States: the vertical displacement y of O2 (up positive) and the tilt gamma (positive when
   the boom side goes down, gamma = (q2 - q1)/l7, eq. 4); pad i sinks by q_i = gamma x_i - y.

       [M      -M x_G] [y'']       [-M g + Fy_base + N1 + N2                              ]
       [-M x_G  J_O  ] [gamma''] = [ M g x_G - N1 x1 - N2 x2 - M_base + Fx_base h_foot    ]

   with M = m8 + m9, M x_G = m8 x8 + m9 x9, J_O = J8 + J9 + m8 x8^2 + m9 x9^2 (eq. 6, 10 in these
   coordinates).  boom_inertia = carried adds the boom's [[m_b, -S], [-S, J_b]] (inputs m_boom,
   Sx_boom, J_boom; seed 000 eq. 24) to the mass matrix.

   Soil (seed 000 "C0 = q0 F", Table 2): c = n q0 F per outrigger, damping b per outrigger; unilateral
   contact (derived): N_i = max(0, c q_i + b q_i') while q_i > 0, else 0.  tipping is 1 while an
   outrigger carries nothing.

   Exact step (solver exact; derived): while both pads press on the soil the model is linear,
   x' = A x + b + B u, stepped by the augmented matrix exponential (cf_linear_step).  The step is taken
   only if at every sub-point s = j d (d <= max_step) both pads stay loaded with a margin for what the
   reaction can do between sub-points (d^2/8 max|N''|, with |N''| <= 4 omega_max^2 (N1 + N2));
   otherwise (lift-off, touch-down) the layer integrates with rk4 at max_step.  The sub-point states are
   sub^j z (sub = expm(Z d)); Python evaluates the same as (settle sub^j) z: equal to round-off.

   With the boom's inertia carried (the mass matrix new at every step while the boom telescopes) the same
   closed form and contact check go through the two modes of (M, K) instead (cranefmu.physics.modal_step:
   the soil's damping is proportional to its stiffness), operation by operation as Python on plain floats:
   M q'' + r K q' + K q = f0 + f1 s + f2 s^2/2, per mode eta'' + beta eta' + lambda eta = g(s), a
   polynomial particular part plus the free motion exp(X s) = e^(mu s) [C I + S (X - mu I)] (Putzer). */
#include <math.h>
#include <string.h>

#include "cf_model.h"
#include "cf_dense.h"
#include "cf_linear_step.h"
#include "cf_repr.h"
#include "Chassis_tables.h"

const int cf_has_exact_step = 1;

typedef struct ChassisData {
    double x1, x2;            /* pad positions from O2 [m] */
    double mass;              /* M = m8 + m9 [kg] */
    double first_moment;      /* M x_G [kg m] */
    double inertia;           /* J_O [kg m2] */
    double stiffness;         /* c1 = c2 [N/m] */
    double own_inverse[4];    /* inverse of the chassis' own mass matrix */
    CfLinearStep linear;      /* the linear system while both pads are loaded */
    int modes_ready;          /* modes below valid for modes_key (boom_inertia = carried) */
    double modes_key[3];      /* (m_b, S_x, J_b) */
    double modes[2][3];       /* per mode: lambda, mode shape (phi_1, phi_2), M-orthonormal */
    double modes_mass[3];     /* m11, m12, m22 */
    double modes_r;           /* damping / stiffness [s] */
} ChassisData;

typedef char chassis_data_fits[sizeof(ChassisData) <= sizeof(double) * CF_MODEL_DATA ? 1 : -1];

#define DATA(m) ((ChassisData *)(m)->data)
#define CDATA(m) ((const ChassisData *)(m)->data)

static int carries(const CfModel *m)
{
    return (int)m->p[P_boom_inertia] == SW_boom_inertia_carried;
}

/* Python's max(a, 0.0): a unless 0.0 > a */
static double max0(double a)
{
    return 0.0 > a ? 0.0 : a;
}

/* the inverse of the mass matrix with the boom's inertia (mb, sb, jb) carried (carry()) */
static int carried_inverse(const ChassisData *d, double mb, double sb, double jb, double *inv)
{
    double mm[4];
    mm[0] = d->mass + mb;
    mm[1] = -d->first_moment - sb;
    mm[2] = -d->first_moment - sb;
    mm[3] = d->inertia + jb;
    return cf_inverse(2, mm, inv);
}

/* the inverse mass matrix at the inputs u */
static void inverse_at(const CfModel *m, const double *u, double *inv)
{
    const ChassisData *d = CDATA(m);
    if (!carries(m) || (u[IN_m_boom] == 0.0 && u[IN_Sx_boom] == 0.0 && u[IN_J_boom] == 0.0)) {
        memcpy(inv, d->own_inverse, sizeof d->own_inverse);
        return;
    }
    if (carried_inverse(d, u[IN_m_boom], u[IN_Sx_boom], u[IN_J_boom], inv))
        inv[0] = inv[1] = inv[2] = inv[3] = NAN;   /* a singular mass matrix: the state check names it */
}

/* _pads: settlements q1, q2 [m] (down positive) and the unilateral soil reactions N1, N2 [N] */
static void pads(const CfModel *m, const double *x, double *q1, double *q2, double *n1, double *n2)
{
    const ChassisData *d = CDATA(m);
    double y = x[0], gamma = x[1], vy = x[2], rate = x[3];
    double x1 = d->x1, x2 = d->x2, c = d->stiffness, b = m->p[P_damping];
    *q1 = gamma * x1 - y;
    *q2 = gamma * x2 - y;
    *n1 = *q1 > 0.0 ? max0(c * *q1 + b * (rate * x1 - vy)) : 0.0;
    *n2 = *q2 > 0.0 ? max0(c * *q2 + b * (rate * x2 - vy)) : 0.0;
}

/* linear_system: A, b, B of x' = A x + b + B u while both pads press on the soil (derived from
   cf_derivatives: N1 + N2 and N1 x1 + N2 x2 are linear in x there), with the inverse mass inv */
static int build_linear(CfModel *m, const double *inv)
{
    const double *p = m->p;
    ChassisData *d = DATA(m);
    double x1 = d->x1, x2 = d->x2, c = d->stiffness, dd = p[P_damping];
    double s1 = x1 + x2, s2 = x1 * x1 + x2 * x2;
    double forces[2][4], loads[2], input[2][3], a[16], bias[4], big_b[12];
    int j;
    forces[0][0] = -2.0 * c;   /* N1 + N2 */
    forces[0][1] = c * s1;
    forces[0][2] = -2.0 * dd;
    forces[0][3] = dd * s1;
    forces[1][0] = c * s1;     /* -(N1 x1 + N2 x2) */
    forces[1][1] = -c * s2;
    forces[1][2] = dd * s1;
    forces[1][3] = -dd * s2;
    loads[0] = -d->mass * p[P_g];
    loads[1] = p[P_g] * d->first_moment;
    input[0][0] = 0.0;
    input[0][1] = 1.0;
    input[0][2] = 0.0;
    input[1][0] = p[P_h_foot];
    input[1][1] = 0.0;
    input[1][2] = -1.0;
    memset(a, 0, sizeof a);
    memset(big_b, 0, sizeof big_b);
    a[0 * 4 + 2] = a[1 * 4 + 3] = 1.0;
    for (j = 0; j < 4; j++) {
        a[2 * 4 + j] = inv[0] * forces[0][j] + inv[1] * forces[1][j];
        a[3 * 4 + j] = inv[2] * forces[0][j] + inv[3] * forces[1][j];
    }
    bias[0] = bias[1] = 0.0;
    bias[2] = inv[0] * loads[0] + inv[1] * loads[1];
    bias[3] = inv[2] * loads[0] + inv[3] * loads[1];
    for (j = 0; j < 3; j++) {   /* the boom's loads; its carried inertia is in the mass matrix */
        big_b[2 * 3 + j] = inv[0] * input[0][j] + inv[1] * input[1][j];
        big_b[3 * 3 + j] = inv[2] * input[0][j] + inv[3] * input[1][j];
    }
    if (cf_linear_init(&d->linear, 4, 3, a, bias, big_b, 1))
        return cf_fail(m, "chassis: linear system too large for the exact step");
    return 0;
}


/* --- the carried case: two modes (cranefmu.physics.modal_step.TwoModes) ------------------------- */
static int two_modes(CfModel *m, double m11, double m12, double m22, double k11, double k12, double k22,
                     double r)
{
    ChassisData *d = DATA(m);
    char a1[CF_REPR_SIZE], a2[CF_REPR_SIZE], a3[CF_REPR_SIZE];
    double l11 = sqrt(m11), l21 = m12 / l11, l22 = sqrt(m22 - l21 * l21);
    double y11, y12, y21, y22, c11, c12, c22, theta, co, si, lam1, lam2, v[2][2];
    int i;
    if (!(l22 > 0.0))
        return cf_fail(m, "mass matrix not positive definite: [[%s, %s], [%s, %s]]", cf_repr(m11, a1),
                       cf_repr(m12, a2), cf_repr(m12, a2), cf_repr(m22, a3));
    /* C = L^-1 K L^-T (symmetric): first Y = L^-1 K, then C = Y L^-T */
    y11 = k11 / l11;
    y12 = k12 / l11;
    y21 = (k12 - l21 * y11) / l22;
    y22 = (k22 - l21 * y12) / l22;
    c11 = y11 / l11;
    c12 = (y12 - c11 * l21) / l22;
    c22 = (y22 - (y21 / l11) * l21) / l22;
    theta = 0.5 * atan2(2.0 * c12, c11 - c22);   /* Jacobi rotation diagonalising C */
    co = cos(theta);
    si = sin(theta);
    lam1 = c11 * co * co + 2.0 * c12 * si * co + c22 * si * si;
    lam2 = c11 * si * si - 2.0 * c12 * si * co + c22 * co * co;
    /* Phi = L^-T V, V = [[co, -si], [si, co]]: columns are the M-orthonormal modes */
    v[0][0] = co;
    v[0][1] = si;
    v[1][0] = -si;
    v[1][1] = co;
    for (i = 0; i < 2; i++) {
        double p2 = v[i][1] / l22;
        double p1 = (v[i][0] - l21 * p2) / l11;
        d->modes[i][0] = i == 0 ? lam1 : lam2;
        d->modes[i][1] = p1;
        d->modes[i][2] = p2;
    }
    d->modes_mass[0] = m11;
    d->modes_mass[1] = m12;
    d->modes_mass[2] = m22;
    d->modes_r = r;
    return 0;
}

/* max |eigenvalue| [1/s] of the first-order system (the largest modal |mu +- delta|) */
static double modes_radius(const ChassisData *d)
{
    double best = 0.0;
    int i;
    for (i = 0; i < 2; i++) {
        double lam = d->modes[i][0], beta = d->modes_r * lam, d2 = 0.25 * beta * beta - lam;
        double value = d2 <= 0.0 ? sqrt(lam) : 0.5 * beta + sqrt(d2);
        if (value > best)   /* max(best, value) */
            best = value;
    }
    return best;
}

/* per mode: lambda, beta, shape a, b, particular p0, p1, p2, free eta - P and eta' - P' at s = 0 */
typedef struct { double lam, beta, a, b, p0, p1, p2, e0, e1; } Prepared;

/* f: the force polynomial's coefficients f0, f1, f2 (two components each) */
static void modes_prepare(const ChassisData *d, const double *q, const double *v, const double *f,
                          Prepared *out)
{
    double m11 = d->modes_mass[0], m12 = d->modes_mass[1], m22 = d->modes_mass[2];
    double mq0 = m11 * q[0] + m12 * q[1], mq1 = m12 * q[0] + m22 * q[1];
    double mv0 = m11 * v[0] + m12 * v[1], mv1 = m12 * v[0] + m22 * v[1];
    int i;
    for (i = 0; i < 2; i++) {
        double lam = d->modes[i][0], a = d->modes[i][1], b = d->modes[i][2];
        double beta = d->modes_r * lam;
        double g0 = a * f[0] + b * f[1], g1 = a * f[2] + b * f[3], g2 = a * f[4] + b * f[5];
        double p2 = g2 / (2.0 * lam);
        double p1 = (g1 - 2.0 * beta * p2) / lam;
        double p0 = (g0 - beta * p1 - 2.0 * p2) / lam;
        double eta = a * mq0 + b * mq1, deta = a * mv0 + b * mv1;
        out[i].lam = lam;
        out[i].beta = beta;
        out[i].a = a;
        out[i].b = b;
        out[i].p0 = p0;
        out[i].p1 = p1;
        out[i].p2 = p2;
        out[i].e0 = eta - p0;
        out[i].e1 = deta - p1;
    }
}

/* (q1, q2, q1', q2') at s into the step */
static void modes_state(const Prepared *pr, double s, double *x)
{
    double q1 = 0.0, q2 = 0.0, v1 = 0.0, v2 = 0.0;
    int i;
    for (i = 0; i < 2; i++) {
        double lam = pr[i].lam, beta = pr[i].beta, e0 = pr[i].e0, e1 = pr[i].e1;
        double mu = -0.5 * beta, d2 = 0.25 * beta * beta - lam, c, sh, decay, eta, deta;
        if (d2 > 0.0) {
            double dd = sqrt(d2);
            if (dd * s < 1.0) {
                decay = exp(mu * s);
                c = decay * cosh(dd * s);
                sh = decay * (sinh(dd * s) / dd);
            } else {   /* e^(mu s) cosh(d s) as two exponentials: no overflow when heavily overdamped */
                double ep = exp((mu + dd) * s), em = exp((mu - dd) * s);
                c = 0.5 * (ep + em);
                sh = (ep - em) / (2.0 * dd);
            }
        } else if (d2 < 0.0) {
            double w = sqrt(-d2);
            decay = exp(mu * s);
            c = decay * cos(w * s);
            sh = decay * (sin(w * s) / w);
        } else {
            decay = exp(mu * s);
            c = decay;
            sh = decay * s;
        }
        eta = pr[i].p0 + (pr[i].p1 + pr[i].p2 * s) * s + (c * e0 + sh * (0.5 * beta * e0 + e1));
        deta = pr[i].p1 + 2.0 * pr[i].p2 * s + (c * e1 + sh * (-lam * e0 - 0.5 * beta * e1));
        q1 = q1 + pr[i].a * eta;
        q2 = q2 + pr[i].b * eta;
        v1 = v1 + pr[i].a * deta;
        v2 = v2 + pr[i].b * deta;
    }
    x[0] = q1;
    x[1] = q2;
    x[2] = v1;
    x[3] = v2;
}

/* _modal_step: the exact step with the boom's inertia carried */
static int modal_step(CfModel *m, const double *x, double h, const double *u0, const double *r1,
                      const double *r2, double max_step, double *x1)
{
    const double *p = m->p;
    ChassisData *d = DATA(m);
    double mb = u0[IN_m_boom], sb = u0[IN_Sx_boom], jb = u0[IN_J_boom];
    double f[3][2], q[2], v[2], xs[2], st[4], c = d->stiffness, dd = p[P_damping], margin;
    double settle_min = INFINITY, react_min = INFINITY, react_max = -INFINITY;
    Prepared pr[2];
    int k, j, i;
    if (!d->modes_ready || !(mb == d->modes_key[0] && sb == d->modes_key[1] && jb == d->modes_key[2])) {
        double x1p = d->x1, x2p = d->x2;
        if (two_modes(m, d->mass + mb, -d->first_moment - sb, d->inertia + jb, 2.0 * c, -c * (x1p + x2p),
                      c * (x1p * x1p + x2p * x2p), p[P_damping] / c))
            return -1;
        d->modes_key[0] = mb;
        d->modes_key[1] = sb;
        d->modes_key[2] = jb;
        d->modes_ready = 1;
    }
    k = (int)ceil(h / max_step - 1e-9);   /* contact checked at sub-points <= max_step apart */
    if (k < 1)
        k = 1;
    f[0][0] = u0[IN_Fy_base] - d->mass * p[P_g];
    f[0][1] = p[P_g] * d->first_moment - u0[IN_M_base] + u0[IN_Fx_base] * p[P_h_foot];
    f[1][0] = r1[IN_Fy_base];
    f[1][1] = -r1[IN_M_base] + r1[IN_Fx_base] * p[P_h_foot];
    f[2][0] = r2[IN_Fy_base];
    f[2][1] = -r2[IN_M_base] + r2[IN_Fx_base] * p[P_h_foot];
    q[0] = x[0];
    q[1] = x[1];
    v[0] = x[2];
    v[1] = x[3];
    modes_prepare(d, q, v, &f[0][0], pr);
    xs[0] = d->x1;
    xs[1] = d->x2;
    for (j = 0; j <= k; j++) {
        modes_state(pr, j == k ? h : j * (h / k), st);
        for (i = 0; i < 2; i++) {
            double settle = st[1] * xs[i] - st[0];
            double react = c * (st[1] * xs[i] - st[0]) + dd * (st[3] * xs[i] - st[2]);
            if (settle < settle_min)
                settle_min = settle;
            if (react < react_min)
                react_min = react;
            if (react > react_max)
                react_max = react;
        }
    }
    margin = 0.5 * pow(modes_radius(d) * h / k, 2.0);   /* d^2/8 * 4 omega^2 */
    if (settle_min <= 0.0 || react_min <= 2.0 * margin * react_max)   /* N1 + N2 <= 2 max N */
        return 0;
    for (i = 0; i < 4; i++)
        x1[i] = st[i];
    return 1;
}

int cf_check_params(CfModel *m)
{
    const double *p = m->p;
    char a[CF_REPR_SIZE], b[CF_REPR_SIZE];
    if (!(0.0 <= p[P_x_slew] && p[P_x_slew] <= p[P_outrigger_base]))
        return cf_fail(m, "chassis.x_slew = %s is not allowed: the slewing centre must lie "
                       "between the outriggers, [0, %s] m", cf_repr(p[P_x_slew], a), cf_repr(p[P_outrigger_base], b));
    return 0;
}

int cf_prepare(CfModel *m)
{
    const double *p = m->p;
    ChassisData *d = DATA(m);
    double x8 = p[P_x_platform] - p[P_x_slew], x9 = p[P_x_body] - p[P_x_slew], mm[4];
    d->x1 = -p[P_x_slew];                                      /* x1, x2 from O2 */
    d->x2 = p[P_outrigger_base] - p[P_x_slew];
    d->mass = p[P_m_platform] + p[P_m_body];
    d->first_moment = p[P_m_platform] * x8 + p[P_m_body] * x9;   /* M x_G */
    d->inertia = p[P_J_platform] + p[P_J_body] + p[P_m_platform] * pow(x8, 2.0) + p[P_m_body] * pow(x9, 2.0);
    d->stiffness = p[P_pads_per_outrigger] * p[P_soil_coefficient] * p[P_pad_area];   /* c1 = c2 */
    mm[0] = d->mass;
    mm[1] = mm[2] = -d->first_moment;
    mm[3] = d->inertia;
    if (cf_inverse(2, mm, d->own_inverse))
        return cf_fail(m, "chassis: the mass matrix is singular (m_body, J_body, m_platform, J_platform)");
    d->modes_ready = 0;
    m->n_states = 4;
    return build_linear(m, d->own_inverse);   /* prepare_exact_step: the propagator, no expm yet */
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    /* static equilibrium under the inputs; if the resultant lies outside the support base the body rests
       on the loaded pad carrying the whole vertical load, the other pad just touching (it starts to tip) */
    const double *p = m->p;
    const ChassisData *d = CDATA(m);
    double w = d->mass * p[P_g] - u[IN_Fy_base];                                      /* applied_loads */
    double mo = p[P_g] * d->first_moment - u[IN_M_base] + u[IN_Fx_base] * p[P_h_foot];
    double x1 = d->x1, x2 = d->x2, n1, n2, q1, q2, gamma;
    if (w <= 0.0) {
        x[0] = x[1] = x[2] = x[3] = 0.0;
        return 0;
    }
    n2 = (mo + w * (-x1)) / (x2 - x1);   /* static_reactions: moments about the front pad */
    n1 = w - n2;
    if (n1 < 0.0) {
        n1 = 0.0;
        n2 = w;
    } else if (n2 < 0.0) {
        n1 = w;
        n2 = 0.0;
    }
    q1 = n1 / d->stiffness;
    q2 = n2 / d->stiffness;
    gamma = (q2 - q1) / (x2 - x1);
    x[0] = gamma * x1 - q1;
    x[1] = gamma;
    x[2] = 0.0;
    x[3] = 0.0;
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    const double *p = m->p;
    const ChassisData *d = CDATA(m);
    double q1, q2, n1, n2, force, moment, inv[4];
    (void)t;
    inverse_at(m, u, inv);   /* carry(u) */
    pads(m, x, &q1, &q2, &n1, &n2);
    force = u[IN_Fy_base] - d->mass * p[P_g] + n1 + n2;
    moment = p[P_g] * d->first_moment - u[IN_M_base] + u[IN_Fx_base] * p[P_h_foot] - n1 * d->x1 - n2 * d->x2;
    dx[0] = x[2];
    dx[1] = x[3];
    dx[2] = inv[0] * force + inv[1] * moment;
    dx[3] = inv[2] * force + inv[3] * moment;
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    double q1, q2, n1, n2;
    (void)t;
    (void)u;
    pads(m, x, &q1, &q2, &n1, &n2);
    y[OUT_y_base] = x[0];
    y[OUT_gamma] = x[1];
    y[OUT_vy_base] = x[2];
    y[OUT_gamma_rate] = x[3];
    y[OUT_q1] = q1;
    y[OUT_q2] = q2;
    y[OUT_N_front] = n1;
    y[OUT_N_rear] = n2;
    y[OUT_tipping] = (n1 == 0.0 || n2 == 0.0) ? 1.0 : 0.0;
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
    /* closed-form step while both pads stay loaded (see the top of the file), else 0 */
    const double *p = m->p;
    ChassisData *d = DATA(m);
    const CfLinearMaps *maps;
    double z[CF_LS_MAX_SIZE], zj[CF_LS_MAX_SIZE], next[CF_LS_MAX_SIZE];
    double c = d->stiffness, dd = p[P_damping], margin, q_min = INFINITY, n_min = INFINITY, n_max = -INFINITY;
    double xs[2];
    int k, j, i, size = d->linear.size;
    (void)t;
    if (carries(m))   /* the boom's inertia carried: through the two modes */
        return modal_step(m, x, h, u0, r1, r2, max_step, x1);
    k = (int)ceil(h / max_step - 1e-9);   /* contact checked at sub-points <= max_step apart */
    if (k < 1)
        k = 1;
    maps = cf_linear_maps(&d->linear, h, k);
    margin = 0.5 * pow(d->linear.spectral_radius * maps->h_key / k, 2.0);   /* d^2/8 * 4 omega^2 */
    cf_linear_augment(&d->linear, x, u0, r1, r2, z);
    memcpy(zj, z, sizeof(double) * size);
    xs[0] = d->x1;
    xs[1] = d->x2;
    for (j = 0; j <= k; j++) {
        if (j > 0) {
            cf_linear_apply(&d->linear, maps->sub, size, zj, next);
            memcpy(zj, next, sizeof(double) * size);
        }
        for (i = 0; i < 2; i++) {
            double q = -1.0 * zj[0] + xs[i] * zj[1];                              /* q_i of a state */
            double n = -c * zj[0] + c * xs[i] * zj[1] - dd * zj[2] + dd * xs[i] * zj[3];   /* N_i in contact */
            if (q < q_min)
                q_min = q;
            if (n < n_min)
                n_min = n;
            if (n > n_max)
                n_max = n;
        }
    }
    if (q_min <= 0.0 || n_min <= 2.0 * margin * n_max)   /* N1 + N2 <= 2 max N */
        return 0;
    cf_linear_apply(&d->linear, maps->end, 4, z, x1);
    return 1;
}

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    static const char *names[] = {"y", "gamma", "vy", "gamma_rate"};
    (void)m;
    return i >= 0 && i < 4 ? names[i] : "?";
}
