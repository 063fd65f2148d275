/* Hoist rope between a suspension point ("top") and the hook: C twin of cranefmu.physics.rope, operation
   by operation (the FMU's unpinned law; the regime pinning of RopeModel.pin serves the Python reference
   solver only).

   Kelvin-Voigt rope with length-dependent stiffness and damping (seed 001 eq. 8-9, seed 000 eq. 25-28):
   the reeving of n_lines parallel lines acts as one spring-damper
       L_u   = length + payout / n_lines                       unstretched length of one line  [m]
       L_e   = L_u + n_lines (run_length + run_extension)      elastic length (seed 000 eq. 28) [m]
       c     = n_lines E A / L_e                               stiffness of the reeving        [N/m]
       m_eff = 0.5 m_load + rho A L_u                          (eq. 9, i_w = n_lines)          [kg]
       b     = 2 zeta sqrt(c m_eff)                            damping                         [N s/m]
       T     = max(0, c delta + b delta_dot)  if delta > 0 else 0
   with delta = |p_hook - p_top| - L_u.  The drum sees one line: T / n_lines.

   Modified Bouc-Wen (model = bouc_wen, seed 001 eq. 1-3, cf_boucwen.h): the reeving is one Bouc-Wen
   element with x = delta, x' = delta_dot from the geometry,
       T = max(0, F_2(delta) (z + F_1(delta)))  if delta > 0 else 0,   z' = rope_z_rate(delta, delta', z)
   with the nine parameters given for ONE line of 1 m and scaled to n_lines lines of the elastic length
   by cf_bw_for_length.  The hysteresis state z [N] is the internal state; after_step projects it onto
   its admissible set (z = 0 while slack, no compression).  Initial state: the virgin curve at the
   initial elongation (a rope at rest under its load is in equilibrium).

   Static start: the input load [N] is the force the rope carries at rest at the start; both laws stretch
   a reeving of unstretched length L_u by L_u eps(load), eps the strain of a 1 m reeving (Kelvin-Voigt
   load / (n E A), Bouc-Wen the virgin curve).  Output hang_length = L_u (1 + eps) + (L_e - L_u) eps.
   start = taut: the hoist has taken the rope up until it carries load between the end points it has at
   initialization, then paid out start_slack:
       L_u(0) = (chord - (L_e - L_u) eps(load)) / (1 + eps(load)) + start_slack,
   and the unstretched length at zero payout is then a state (constant, derivative 0).

   State layout: [z (Bouc-Wen)] + [length0 (start = taut)].

   Errors that the Python model raises inside derivatives or outputs (a payout that leaves no rope, a
   load the Bouc-Wen curve does not reach) cannot be returned through the void functions of the
   contract: they give NaN there, which the layer reports as a non-finite state or output. */
#include <math.h>
#include <stdio.h>

#include "cf_model.h"
#include "cf_boucwen.h"
#include "cf_repr.h"
#include "Rope_tables.h"

const int cf_has_exact_step = 0;

#define LENGTH_DEFAULT 10.0   /* RopeParams.length's default (the only value allowed with start = taut) */
#define VIRGIN_RTOL 1e-10     /* boucwen.virgin_elongation's default rtol */

typedef struct RopeData {
    int bw;               /* model = bouc_wen */
    int taut;             /* start = taut: length0 is a state */
    int nz;               /* index of length0 in the state (1 with Bouc-Wen, else 0) */
    CfBoucWen line;       /* the nine parameters of one 1 m line (RopeParams.bouc_wen) */
    /* caches of pure functions of their key (RopeModel.strain and bouc_wen_at): the load is constant
       in a run, the elastic length changes only with payout and the run */
    double strain_load, strain;
    int strain_failed;
    double scaled_le;
    CfBoucWen scaled;
} RopeData;

typedef char rope_data_fits[sizeof(RopeData) <= sizeof(double) * CF_MODEL_DATA ? 1 : -1];

/* The caches are filled from const entry points: the layer owns a writable CfModel, and a cache entry
   is a pure function of its key, so the results do not depend on what was cached before. */
#define DATA(m) ((RopeData *)(m)->data)

/* Python's max(a, b) on floats: the first argument unless the second compares larger */
static double py_max(double a, double b) { return b > a ? b : a; }

/* Rope force [N] of a slack-capable Kelvin-Voigt element (no compression). */
static double kelvin_voigt_tension(double delta, double delta_dot, double c, double b)
{
    if (delta <= 0.0)
        return 0.0;
    return py_max(0.0, c * delta + b * delta_dot);
}

/* Reeving stiffness c = n E A / L_e [N/m] (seed 001 eq. 8, seed 000 eq. 25). */
static double stiffness(const double *p, double l_e)
{
    return p[P_n_lines] * p[P_E] * p[P_A] / l_e;
}

/* Length L_e [m] of one line whose n-line reeving is as stiff as the reeving in series with the run of
   run_length + extension [m]: L_e = L_u + n run (seed 000 eq. 26-28 as printed: 1/c = run / (E F) +
   s / (n_p E F)). */
static double elastic_length(const double *p, double l_u, double extension)
{
    double run = p[P_run_length] + extension;
    return run != 0.0 ? l_u + p[P_n_lines] * run : l_u;
}

/* Damping coefficient b = 2 zeta sqrt(c m_eff) [N s/m] (seed 001 eq. 9, i_w = n_lines). */
static double damping(const double *p, double c, double l_u, double m_load)
{
    double m_eff = 0.5 * m_load + p[P_rho] * p[P_A] * l_u;
    return 2.0 * p[P_zeta] * sqrt(c * m_eff);
}

/* rope.geometry: unit vector top->hook e, chord length [m], unstretched length L_u [m] and
   dL/dt - dL_u/dt [m/s] with length0 [m] the unstretched length at zero payout.  Returns 1 (msg written
   if m is writable) when the payout leaves no rope. */
static int geometry(const double *p, const double *u, double length0, double e[3], double *length,
                    double *l_u, double *delta_dot)
{
    double dx = u[IN_x_hook] - u[IN_x_top], dy = u[IN_y_hook] - u[IN_y_top], dz = u[IN_z_hook] - u[IN_z_top];
    *length = sqrt(dx * dx + dy * dy + dz * dz);
    *l_u = length0 + u[IN_payout] / p[P_n_lines];
    if (*l_u <= 0.0)
        return 1;
    if (*length > 0.0) {
        e[0] = dx / *length;
        e[1] = dy / *length;
        e[2] = dz / *length;
    } else {
        e[0] = 0.0;
        e[1] = -1.0;
        e[2] = 0.0;
    }
    *delta_dot = e[0] * (u[IN_vx_hook] - u[IN_vx_top]) + e[1] * (u[IN_vy_hook] - u[IN_vy_top])
               + e[2] * (u[IN_vz_hook] - u[IN_vz_top]) - u[IN_payout_rate] / p[P_n_lines];
    return 0;
}

static int no_rope(CfModel *m, double payout, double l_u)
{
    return cf_fail(m, "rope.payout = %.6g m leaves no rope: unstretched length %.6g m must stay > 0", payout, l_u);
}

/* static_strain: strain [1] of the reeving at rest carrying load [N] (all lines): load / (n E A) for
   Kelvin-Voigt, the virgin loading curve of a 1 m reeving for Bouc-Wen (RopeModel.strain, cached).
   Returns 1 when the Bouc-Wen curve does not reach the load. */
static int strain(const CfModel *m, double load, double *eps)
{
    RopeData *d = DATA(m);
    const double *p = m->p;
    if (d->strain_load != load) {
        d->strain_failed = 0;
        if (d->bw) {
            CfBoucWen one;
            cf_bw_for_length(&d->line, 1.0, p[P_n_lines], 1.0, &one);
            d->strain_failed = cf_bw_virgin_elongation(load, &one, VIRGIN_RTOL, &d->strain);
        } else {
            d->strain = py_max(0.0, load) / (p[P_n_lines] * p[P_E] * p[P_A]);
        }
        d->strain_load = load;
    }
    *eps = d->strain;
    return d->strain_failed;
}

static int strain_failed(CfModel *m, double load)
{
    char a[CF_REPR_SIZE];
    return cf_fail(m, "rope tension %s N is not reached by the Bouc-Wen loading curve", cf_repr(load, a));
}

/* RopeModel.bouc_wen_at: the Bouc-Wen set of the whole reeving at elastic line length l_e [m] (cached) */
static const CfBoucWen *bouc_wen_at(const CfModel *m, double l_e)
{
    RopeData *d = DATA(m);
    if (d->scaled_le != l_e) {
        cf_bw_for_length(&d->line, l_e, m->p[P_n_lines], 1.0, &d->scaled);
        d->scaled_le = l_e;
    }
    return &d->scaled;
}

/* the unstretched length at zero payout in use: the taken-up state, or the parameter */
static double length0_of(const CfModel *m, const double *x)
{
    const RopeData *d = DATA(m);
    return d->taut ? x[d->nz] : m->p[P_length];
}

int cf_check_params(CfModel *m)
{
    const double *p = m->p;
    char a[CF_REPR_SIZE], b[CF_REPR_SIZE], c[CF_REPR_SIZE], e[CF_REPR_SIZE];
    if ((int)p[P_start] == SW_start_taut && p[P_length] != LENGTH_DEFAULT)
        return cf_fail(m, "rope.length = %s is not used with rope.start = 'taut' (the length is taken up at "
                       "initialization): allowed %s here, or set start = 'length'", cf_repr(p[P_length], a),
                       cf_repr(LENGTH_DEFAULT, b));
    if ((int)p[P_start] == SW_start_length && p[P_start_slack] != 0.0)
        return cf_fail(m, "rope.start_slack = %s needs rope.start = 'taut': allowed 0 here", cf_repr(p[P_start_slack], a));
    if ((int)p[P_model] == SW_model_bouc_wen) {
        /* BoucWenParams.check: refuses an inadmissible set (unbounded or energy-generating loops); each
           field's range is the Rope field's own, checked by the layer */
        CfBoucWen bw = {p[P_k1], p[P_k2], p[P_k3], p[P_b], p[P_c], p[P_alpha], p[P_beta], p[P_gamma], p[P_n]};
        double zu;
        if (!(bw.beta + bw.gamma > 0.0))
            return cf_fail(m, "rope.gamma = %s is not allowed: beta + gamma must be > 0 (beta = %s), else the "
                           "hysteretic state z grows without bound", cf_repr(bw.gamma, a), cf_repr(bw.beta, b));
        if (!(bw.gamma <= bw.beta))
            return cf_fail(m, "rope.gamma = %s is not allowed: need -beta < gamma <= beta (beta = %s), else a "
                           "closed loop can generate energy", cf_repr(bw.gamma, a), cf_repr(bw.beta, b));
        zu = cf_bw_z_bound(&bw);
        if (!(isfinite(zu) && zu > 0.0))
            return cf_fail(m, "rope.alpha = %s gives an ultimate hysteretic force (alpha/(beta+gamma))^(1/n) = %s N: "
                           "allowed a finite positive value (beta + gamma = %s, n = %s)", cf_repr(bw.alpha, a),
                           cf_repr(zu, b), cf_repr(bw.beta + bw.gamma, c), cf_repr(bw.n, e));
    }
    return 0;
}

int cf_prepare(CfModel *m)
{
    const double *p = m->p;
    RopeData *d = DATA(m);
    CfBoucWen line = {p[P_k1], p[P_k2], p[P_k3], p[P_b], p[P_c], p[P_alpha], p[P_beta], p[P_gamma], p[P_n]};
    d->bw = (int)p[P_model] == SW_model_bouc_wen;
    d->taut = (int)p[P_start] == SW_start_taut;
    d->nz = d->bw ? 1 : 0;
    d->line = line;
    d->strain_load = NAN;
    d->strain = 0.0;
    d->strain_failed = 0;
    d->scaled_le = NAN;
    m->n_states = d->nz + (d->taut ? 1 : 0);
    return 0;
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    /* Bouc-Wen: z on the virgin curve at the initial elongation (static equilibrium at rest);
       start = taut: the length taken up */
    const double *p = m->p;
    const RopeData *d = DATA(m);
    double e[3], length, l_u, delta_dot, length0 = p[P_length];
    int k = 0;
    if (d->taut) {
        double chord, eps, chord_falls;
        if (geometry(p, u, p[P_length], e, &chord, &l_u, &delta_dot))
            return no_rope(m, u[IN_payout], l_u);
        if (strain(m, u[IN_load], &eps))
            return strain_failed(m, u[IN_load]);
        /* chord = L_u (1 + eps) + eps (L_e - L_u): the run stretches too (L_e - L_u = n run) */
        chord_falls = chord - eps * elastic_length(p, 0.0, u[IN_run_extension]);
        length0 = chord_falls / (1.0 + eps) + p[P_start_slack] - u[IN_payout] / p[P_n_lines];
        if (chord == 0.0 || !(length0 > 0.0))   /* end points not known yet (inputs at their start values) */
            length0 = p[P_length];
    }
    if (d->bw) {
        if (geometry(p, u, length0, e, &length, &l_u, &delta_dot))
            return no_rope(m, u[IN_payout], l_u);
        x[k++] = cf_bw_virgin_z(length - l_u, bouc_wen_at(m, elastic_length(p, l_u, u[IN_run_extension])));
    }
    if (d->taut)
        x[k++] = length0;
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    const double *p = m->p;
    const RopeData *d = DATA(m);
    double e[3], length, l_u, delta_dot, delta, rate;
    (void)t;
    if (!d->bw) {
        int i;
        for (i = 0; i < m->n_states; i++)
            dx[i] = 0.0;
        return;
    }
    if (geometry(p, u, length0_of(m, x), e, &length, &l_u, &delta_dot)) {
        rate = NAN;   /* Python raises FloatingPointError: no rope left */
    } else {
        delta = length - l_u;
        rate = cf_bw_rope_z_rate(delta, delta_dot, x[0], bouc_wen_at(m, elastic_length(p, l_u, u[IN_run_extension])));
    }
    dx[0] = rate;
    if (d->taut)
        dx[1] = 0.0;
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    const double *p = m->p;
    const RopeData *d = DATA(m);
    double e[3], length, l_u, delta_dot, z, m_load, l_e, tension, fx, fy, fz, eps, hang;
    int i;
    (void)t;
    if (geometry(p, u, length0_of(m, x), e, &length, &l_u, &delta_dot)) {
        for (i = 0; i < N_OUTPUTS; i++)
            y[i] = NAN;   /* Python raises FloatingPointError: no rope left; the layer reports m->msg */
        if (m->msg != NULL) {
            char a[32], b[32];
            snprintf(a, sizeof a, "%.6g", u[IN_payout]);
            snprintf(b, sizeof b, "%.6g", l_u);
            snprintf(m->msg, CF_MSG_SIZE, "rope.payout = %s m leaves no rope: unstretched length %s m must stay > 0",
                     a, b);
        }
        return;
    }
    z = d->bw ? x[0] : 0.0;
    m_load = u[IN_m_load];
    l_e = elastic_length(p, l_u, u[IN_run_extension]);
    if (!d->bw) {
        double c = stiffness(p, l_e);
        tension = kelvin_voigt_tension(length - l_u, delta_dot, c, damping(p, c, l_u, m_load));
    } else {
        tension = cf_bw_tension(length - l_u, z, bouc_wen_at(m, l_e));
    }
    fx = -tension * e[0];
    fy = -tension * e[1];
    fz = -tension * e[2];
    if (strain(m, u[IN_load], &eps))
        eps = NAN;   /* Python raises ParameterError: the Bouc-Wen curve does not reach the load */
    hang = l_u * (1.0 + eps) + (l_e - l_u) * eps;   /* the run stretches too (0 without one) */
    y[OUT_tension] = tension;
    y[OUT_drum_force] = tension / p[P_n_lines];
    y[OUT_Fx_hook] = fx;
    y[OUT_Fy_hook] = fy;
    y[OUT_Fz_hook] = fz;
    y[OUT_Fx_top] = -fx;
    y[OUT_Fy_top] = -fy;
    y[OUT_Fz_top] = -fz;
    y[OUT_rope_length] = length;
    y[OUT_elongation] = length - l_u;
    y[OUT_slack] = tension == 0.0 ? 1.0 : 0.0;
    y[OUT_z_hysteresis] = z;
    y[OUT_hang_length] = hang;
}

int cf_frozen(const CfModel *m)
{
    return !DATA(m)->bw;   /* Kelvin-Voigt: no state, or only the constant taken-up length */
}

CF_NO_EXACT_STEP

void cf_after_step(const CfModel *m, double t, double *x, const double *u)
{
    /* boucwen.project_state: removes the solver's round-off drift off the zero-force line */
    const double *p = m->p;
    double e[3], length, l_u, delta_dot;
    (void)t;
    if (!DATA(m)->bw)
        return;
    if (geometry(p, u, length0_of(m, x), e, &length, &l_u, &delta_dot)) {
        x[0] = NAN;   /* Python raises FloatingPointError: no rope left */
        return;
    }
    x[0] = cf_bw_project_state(length - l_u, x[0], bouc_wen_at(m, elastic_length(p, l_u, u[IN_run_extension])));
}

const char *cf_state_name(const CfModel *m, int i)
{
    const RopeData *d = DATA(m);
    if (d->bw && i == 0)
        return "z_hysteresis";
    if (d->taut && i == d->nz)
        return "length0";
    return "?";
}
