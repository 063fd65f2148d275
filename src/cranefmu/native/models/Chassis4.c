/* Truck body and slewing platform on FOUR elastic outrigger pads in 3-D (heave, pitch, roll): C twin of
   cranefmu.physics.chassis4 (seed 000 Tables 1-2, its four stays).

   Frame (derived, as Chassis in the working plane): x from the boom foot O2 toward the rear, y up, z to
   the side the boom reaches at +90 deg.  States: heave y of O2 (up), pitch gamma (positive when the +x
   side goes down, seed 000 eq. 4) and roll beta (positive when the +z side goes down); pad i at
   (x_i, z_i) sinks by q_i = gamma x_i + beta z_i - y.  Pads 1..4: front-left, front-right, rear-left,
   rear-right.

       M_q [y'', gamma'', beta'']^T = [Fy - M g + sum N_i,
                                       g M x_G - Mz + Fx h_foot - sum N_i x_i,
                                       Mx + Fz h_foot - sum N_i z_i]

   with the chassis' [[M, -M x_G, 0], [-M x_G, J_O, 0], [0, 0, J_roll]] (seed 000 eq. 6, 10) plus, with
   boom_inertia = carried, the boom's [[m_b, -S_x, -S_z], [-S_x, J_p, J_pr], [-S_z, J_pr, J_r]].
   Soil (seed 000 "C0 = q0 F"): each pad c = q0 F, damping b = (damping per outrigger position) / 2;
   unilateral: N_i = max(0, c q_i + b q_i') while q_i > 0, else 0.  Integrated with rk4 (no closed form).
   The crane rocks on three pads (one pad off, free above the soil: the model runs on); tipping is 1 while
   two pads or more carry nothing (the resultant outside the support polygon: it overturns); pads_lifted
   counts the pads carrying nothing.

   Statics (initial state): the rigid chassis on the pads in contact (four, else each set of three) with
   every N_i >= 0 and every other pad clear of the soil; without one (the resultant outside the support
   polygon) it rests on the two pads of the edge the resultant lies beyond (it starts to overturn).

   The 3x3 inverse, solves and the mass matrix times the force go through cf_inverse3, cf_solve3 and
   cf_matvec3 (cf_dense.h): the fixed order of cranefmu.physics.small_linalg, which the Python model
   follows too, so that both give the same bits (issue 33). */
#include <math.h>
#include <string.h>

#include "cf_model.h"
#include "cf_dense.h"
#include "cf_repr.h"
#include "Chassis4_tables.h"

const int cf_has_exact_step = 0;

typedef struct Chassis4Data {
    double xs[4], zs[4];      /* pad positions from O2 [m] */
    double mass;              /* M [kg] */
    double first_moment;      /* M x_G [kg m] */
    double own[9];            /* the chassis' own mass matrix */
    double own_inverse[9];
    double stiffness;         /* c per pad [N/m] */
    double pad_damping;       /* b per pad [N s/m] */
} Chassis4Data;

typedef char chassis4_data_fits[sizeof(Chassis4Data) <= sizeof(double) * CF_MODEL_DATA ? 1 : -1];

#define DATA(m) ((Chassis4Data *)(m)->data)
#define CDATA(m) ((const Chassis4Data *)(m)->data)

/* Python's max(a, b): a unless b > a; min(a, b): a unless b < a */
static double py_max(double a, double b)
{
    return b > a ? b : a;
}

static double py_min(double a, double b)
{
    return b < a ? b : a;
}

int cf_check_params(CfModel *m)
{
    const double *p = m->p;
    char a[CF_REPR_SIZE], b[CF_REPR_SIZE];
    if (!(0.0 <= p[P_x_slew] && p[P_x_slew] <= p[P_outrigger_base]))   /* ChassisParams.check */
        return cf_fail(m, "chassis.x_slew = %s is not allowed: the slewing centre must lie "
                       "between the outriggers, [0, %s] m", cf_repr(p[P_x_slew], a), cf_repr(p[P_outrigger_base], b));
    if ((int)p[P_pads_per_outrigger] != 2)
        return cf_fail(m, "chassis.pads_per_outrigger = %d is not allowed for the four-pad chassis: its pads are "
                       "one left and one right at each outrigger, allowed 2", (int)p[P_pads_per_outrigger]);
    return 0;
}

int cf_prepare(CfModel *m)
{
    const double *p = m->p;
    Chassis4Data *d = DATA(m);
    double x1 = -p[P_x_slew], x2 = p[P_outrigger_base] - p[P_x_slew], h = 0.5 * p[P_outrigger_width];
    double x8 = p[P_x_platform] - p[P_x_slew], x9 = p[P_x_body] - p[P_x_slew], inertia;
    /* pad_positions: front-left, front-right, rear-left, rear-right */
    d->xs[0] = d->xs[1] = x1;
    d->xs[2] = d->xs[3] = x2;
    d->zs[0] = d->zs[2] = -h;
    d->zs[1] = d->zs[3] = h;
    d->mass = p[P_m_platform] + p[P_m_body];
    d->first_moment = p[P_m_platform] * x8 + p[P_m_body] * x9;
    inertia = p[P_J_platform] + p[P_J_body] + p[P_m_platform] * pow(x8, 2.0) + p[P_m_body] * pow(x9, 2.0);
    memset(d->own, 0, sizeof d->own);
    d->own[0] = d->mass;
    d->own[1] = d->own[3] = -d->first_moment;
    d->own[4] = inertia;
    d->own[8] = p[P_J_roll];
    d->stiffness = p[P_soil_coefficient] * p[P_pad_area];
    d->pad_damping = p[P_damping] / p[P_pads_per_outrigger];
    if (cf_inverse3(d->own, d->own_inverse))
        return cf_fail(m, "chassis: the mass matrix is singular (m_body, J_body, m_platform, J_platform, J_roll)");
    m->n_states = 6;
    return 0;
}

/* applied_loads: vertical load W [N] (down positive), moments about O2 toward +x and toward +z [N m] */
static void applied_loads(const CfModel *m, const double *u, double *w, double *mg, double *mbeta)
{
    const double *p = m->p;
    const Chassis4Data *d = CDATA(m);
    *w = d->mass * p[P_g] - u[IN_Fy_base];
    *mg = p[P_g] * d->first_moment - u[IN_Mz_base] + u[IN_Fx_base] * p[P_h_foot];
    *mbeta = u[IN_Mx_base] + u[IN_Fz_base] * p[P_h_foot];
}

/* contact_statics: 1 with the chassis' (-y, gamma, beta) in xi when a set of pads in contact holds */
static int contact_statics(const Chassis4Data *d, double w, double m_gamma, double m_beta, double *xi)
{
    static const int sets[5][4] = {{0, 1, 2, 3}, {0, 1, 2, -1}, {0, 1, 3, -1}, {0, 2, 3, -1}, {1, 2, 3, -1}};
    double f[3], rows[4][3];
    int s, i, j, r;
    f[0] = w;
    f[1] = m_gamma;
    f[2] = m_beta;
    for (i = 0; i < 4; i++) {
        rows[i][0] = 1.0;
        rows[i][1] = d->xs[i];
        rows[i][2] = d->zs[i];
    }
    for (s = 0; s < 5; s++) {
        double ktd[3][4], mat[9], q[4];
        int active[4] = {0, 0, 0, 0}, n_active = s == 0 ? 4 : 3, ok = 1;
        for (r = 0; r < n_active; r++)
            active[sets[s][r]] = 1;
        /* (stiffness * da.T) @ da */
        for (r = 0; r < n_active; r++)
            for (i = 0; i < 3; i++)
                ktd[i][r] = d->stiffness * rows[sets[s][r]][i];
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                double sum = 0.0;
                for (r = 0; r < n_active; r++)
                    sum += ktd[i][r] * rows[sets[s][r]][j];
                mat[i * 3 + j] = sum;
            }
        if (cf_solve3(mat, f, xi))
            continue;
        for (i = 0; i < 4; i++) {
            q[i] = rows[i][0] * xi[0] + rows[i][1] * xi[1] + rows[i][2] * xi[2];
            if (active[i] ? !(q[i] >= 0.0) : !(q[i] <= 0.0))
                ok = 0;
        }
        if (ok)
            return 1;
    }
    return 0;
}

/* _tipping_settlements: pad settlements [m] with the load w on the edge pads beyond which the resultant
   (x_r, z_r) lies, split by the lever along the edge; the opposite pads on the same plane, the lower
   one just clear of the soil (q = -1e-9 of the edge's larger settlement: it carries nothing) */
static void tipping_settlements(const CfModel *m, double w, double x_r, double z_r, double *q)
{
    const Chassis4Data *d = CDATA(m);
    const double *xs = d->xs, *zs = d->zs;
    double half = 0.5 * m->p[P_outrigger_width];
    double excess[4], share, lift;
    const double *along;
    double s_r;
    int pairs[4][2] = {{2, 3}, {0, 1}, {1, 3}, {0, 2}}, e, best = 0, i, j, k, mm, other[2], n_other = 0;
    excess[0] = x_r - xs[2];
    excess[1] = xs[0] - x_r;
    excess[2] = z_r - half;
    excess[3] = -half - z_r;
    for (e = 1; e < 4; e++)   /* max(): the first of equals */
        if (excess[e] > excess[best])
            best = e;
    i = pairs[best][0];
    j = pairs[best][1];
    along = best < 2 ? zs : xs;
    s_r = best < 2 ? z_r : x_r;
    share = py_min(py_max((s_r - along[i]) / (along[j] - along[i]), 0.0), 1.0);   /* of w on pad j */
    q[0] = q[1] = q[2] = q[3] = 0.0;
    q[i] = (1.0 - share) * w / d->stiffness;
    q[j] = share * w / d->stiffness;
    for (k = 0; k < 4; k++)
        if (k != i && k != j)
            other[n_other++] = k;
    k = other[0];
    mm = other[1];
    if (fabs(xs[k] - xs[i]) + fabs(zs[k] - zs[i]) > fabs(xs[k] - xs[j]) + fabs(zs[k] - zs[j])) {
        k = other[1];   /* k opposite i, m opposite j */
        mm = other[0];
    }
    lift = -py_max(q[i], q[j]) * (1.0 + 1e-9);   /* 1e-9 of it clear: round-off cannot press it */
    q[k] = q[i] + lift;
    q[mm] = q[j] + lift;
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    const Chassis4Data *d = CDATA(m);
    double w, mg, mbeta, xi[3];
    int i;
    applied_loads(m, u, &w, &mg, &mbeta);
    for (i = 0; i < 6; i++)
        x[i] = 0.0;
    if (w <= 0.0)
        return 0;
    if (!contact_statics(d, w, mg, mbeta, xi)) {
        /* lstsq of [1, x_i, z_i] xi = q: the settlements lie on a plane (a rectangle of pads), so the
           normal equations give it to round-off */
        double q[4], ata[9], atq[3], rows[4][3];
        int j, r;
        tipping_settlements(m, w, mg / w, mbeta / w, q);
        for (r = 0; r < 4; r++) {
            rows[r][0] = 1.0;
            rows[r][1] = d->xs[r];
            rows[r][2] = d->zs[r];
        }
        for (i = 0; i < 3; i++) {
            double s = 0.0;
            for (j = 0; j < 3; j++) {
                double t = 0.0;
                for (r = 0; r < 4; r++)
                    t += rows[r][i] * rows[r][j];
                ata[i * 3 + j] = t;
            }
            for (r = 0; r < 4; r++)
                s += rows[r][i] * q[r];
            atq[i] = s;
        }
        if (cf_solve3(ata, atq, xi))
            return cf_fail(m, "chassis: the pads lie on a line (outrigger_base, outrigger_width)");
    }
    x[0] = -xi[0];
    x[1] = xi[1];
    x[2] = xi[2];
    return 0;
}

/* pads: settlements q_i [m] and unilateral soil reactions N_i [N] of the four pads */
static void pads(const CfModel *m, const double *x, double *qs, double *ns)
{
    const Chassis4Data *d = CDATA(m);
    double y = x[0], gamma = x[1], beta = x[2], vy = x[3], gr = x[4], br = x[5];
    double c = d->stiffness, b = d->pad_damping;
    int i;
    for (i = 0; i < 4; i++) {
        double xi = d->xs[i], zi = d->zs[i];
        double q = gamma * xi + beta * zi - y;
        qs[i] = q;
        ns[i] = q > 0.0 ? py_max(c * q + b * (gr * xi + br * zi - vy), 0.0) : 0.0;
    }
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    const Chassis4Data *d = CDATA(m);
    double w, mg, mbeta, qs[4], ns[4], force[3], inv[9], sum, nx, nz;
    int i;
    (void)t;
    if ((int)m->p[P_boom_inertia] == SW_boom_inertia_carried) {   /* carry(u) */
        double mm[9];
        double mb = u[IN_m_boom], sx = u[IN_Sx_boom], sz = u[IN_Sz_boom];
        double jp = u[IN_Jp_boom], jr = u[IN_Jr_boom], jpr = u[IN_Jpr_boom];
        mm[0] = d->own[0] + mb;
        mm[1] = d->own[1] + -sx;
        mm[2] = d->own[2] + -sz;
        mm[3] = d->own[3] + -sx;
        mm[4] = d->own[4] + jp;
        mm[5] = d->own[5] + jpr;
        mm[6] = d->own[6] + -sz;
        mm[7] = d->own[7] + jpr;
        mm[8] = d->own[8] + jr;
        if (cf_inverse3(mm, inv))
            for (i = 0; i < 9; i++)
                inv[i] = NAN;   /* a singular mass matrix: the state check names it */
    } else {
        memcpy(inv, d->own_inverse, sizeof inv);
    }
    applied_loads(m, u, &w, &mg, &mbeta);
    pads(m, x, qs, ns);
    sum = ns[0] + ns[1] + ns[2] + ns[3];
    nx = ns[0] * d->xs[0] + ns[1] * d->xs[1] + ns[2] * d->xs[2] + ns[3] * d->xs[3];
    nz = ns[0] * d->zs[0] + ns[1] * d->zs[1] + ns[2] * d->zs[2] + ns[3] * d->zs[3];
    force[0] = sum - w;
    force[1] = mg - nx;
    force[2] = mbeta - nz;
    dx[0] = x[3];
    dx[1] = x[4];
    dx[2] = x[5];
    cf_matvec3(inv, force, dx + 3);
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    double qs[4], ns[4], lifted = 0.0;
    int i;
    (void)t;
    (void)u;
    pads(m, x, qs, ns);
    for (i = 0; i < 6; i++)
        y[i] = x[i];
    for (i = 0; i < 4; i++) {
        y[OUT_q1 + i] = qs[i];
        y[OUT_N1 + i] = ns[i];
        if (ns[i] == 0.0)
            lifted += 1.0;
    }
    y[OUT_pads_lifted] = lifted;
    y[OUT_tipping] = lifted >= 2.0 ? 1.0 : 0.0;   /* a second pad off: the crane overturns */
}

int cf_frozen(const CfModel *m)
{
    (void)m;
    return 0;
}

CF_NO_EXACT_STEP

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    static const char *names[] = {"y", "gamma", "beta", "vy", "gamma_rate", "beta_rate"};
    (void)m;
    return i >= 0 && i < 6 ? names[i] : "?";
}
