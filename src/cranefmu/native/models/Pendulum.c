/* Hook (and payload) hanging from the rope, with optional ground contact and air drag:
   cranefmu.physics.pendulum.PendulumModel in C, operation by operation.

   Coordinates: x along the reach, y up, z lateral; g_vec = (0, -g, 0).  dimension restricts the
   translational motion: 1 = vertical only (hoisting, seed 001), 2 = the working plane x-y (seed 000),
   3 = free (seed 002).  A frozen direction is carried by a constraint (its force components are
   dropped, its accelerations are zero: the mask m).

   Hook (payload = none): one point mass, mass a = F_rope + mass g_vec + N_ground e_y + F_drag (Newton).
   With J_hook the load turns with the rope link (seed 000 eq. 19, T_1 = 0.5 m_1 v_1^2 + 0.5 J_1 theta'^2):
   (m I + J_hook / l^2 P_r) a = F on the free directions (derived; top at rest).

   Hook + payload (seed 002; seed 001 Fig. 4, hook stiffness c_2), unit vector hook -> payload
       e(theta, phi) = ( sin(theta) cos(phi), -cos(theta) cos(phi), sin(phi) )
   rigid sling (derived by Newton-Euler, seed 002's eq. 2-53 being illegible):
       S = mu ( e.(f_p - F_h/m_h) + L (cos^2 p theta'^2 + phi'^2) ),  mu = m_h m_p / (m_h + m_p)
       theta'' = ( e_t.(f_p - a_h) + 2 L sin p cos p theta' phi' ) / (L cos^2 p)
       phi''   = ( e_p.(f_p - a_h) -   L sin p cos p theta'^2 ) / L
   with the hook-pin damper c_pin and the rotational inertias J_payload, J_hook: one 3x3 solve
   (rigid_body below, PendulumModel._rigid_body).
   elastic sling (seed 001 eq. 6, term 0.5 c_2 (q_2 - q_4)^2; damper as the rope's, seed 001 eq. 9):
       S = c (l - L) + b e.(v_p - v_h),  b = 2 zeta sqrt(c mu),  m_h a_h = F_h + S e,  m_p a_p = m_p f_p - S e
   Ground contact (seed 001 eq. 7, damper b_p of Fig. 4 / Table 6) on the lowest body:
       pen = ground_height - y,  N = max(0, c_g pen - b_g v_y) if pen > 0 else 0.
   Air drag (derived, quadratic drag in still air): F_drag = -0.5 rho C_d A |v| v.

   The 3-vector dot products (a0 b0 + a1 b1 + a2 b2, left to right), the 3x3 products and the solve on the
   free directions are cf_dense.h's fixed order (cf_matvec3, cf_solve_free3), which the Python model follows
   too (cranefmu.physics.small_linalg): the same bits on any machine, without mirroring a BLAS (issue 33). */
#include <math.h>

#include "Pendulum_tables.h"
#include "cf_dense.h"
#include "cf_model.h"
#include "cf_pymath.h"
#include "cf_repr.h"

const int cf_has_exact_step = 1;

typedef struct PendulumData {
    int dim;            /* 1, 2 or 3 */
    int payload;        /* SW_payload_* */
    int start;          /* SW_start_* */
    int has_ground;
    int body;           /* rigid sling with c_pin, J_payload or J_hook: the general solve */
    double m[3];        /* mask of the free directions (_MASKS) */
    double total;       /* mass + m_payload [kg] */
    double mu;          /* reduced mass [kg] */
    double b_sling;     /* elastic sling damping [N s/m] */
    double k_load;      /* 0.5 rho C_d A of the load [kg/m] */
    double k_hook;      /* 0.5 rho C_d A of the hook with a payload [kg/m] */
    double rest_tension;
} PendulumData;

typedef char pendulum_data_fits[sizeof(PendulumData) <= CF_MODEL_DATA * sizeof(double) ? 1 : -1];

#define DATA(m) ((const PendulumData *)(m)->data)

/* --- 3-vectors ----------------------------------------------------------------------------------- */
/* a . b, left to right (small_linalg's order) */
static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* np.cross(a, b) */
static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* --- parameters ------------------------------------------------------------------------------ */
static int dimension_of(const double *p)
{
    int code = (int)p[P_dimension];
    return code == SW_dimension_1 ? 1 : code == SW_dimension_2 ? 2 : 3;
}

static const char *start_name(int code)
{
    return code == SW_start_below_top ? "below_top" : code == SW_start_on_ground ? "on_ground" : "position";
}

static const char *payload_name(int code)
{
    return code == SW_payload_rigid ? "rigid" : code == SW_payload_elastic ? "elastic" : "none";
}

/* PendulumParams.check */
int cf_check_params(CfModel *m)
{
    const double *p = m->p;
    char a[CF_REPR_SIZE], b[CF_REPR_SIZE];
    int start = (int)p[P_start], payload = (int)p[P_payload], dim = dimension_of(p);
    /* the fields a start does not use, and their defaults */
    static const int below_top[] = {P_x0, P_y0, P_z0}, on_ground[] = {P_y0, P_theta0, P_phi0},
                     position[] = {P_theta0, P_phi0};
    static const char *const names[N_PARAMS] = {[P_x0] = "x0", [P_y0] = "y0", [P_z0] = "z0",
                                                [P_theta0] = "theta0", [P_phi0] = "phi0"};
    static const double defaults[N_PARAMS] = {[P_y0] = -10.0};
    const int *unused = start == SW_start_below_top ? below_top : start == SW_start_on_ground ? on_ground : position;
    int n_unused = start == SW_start_position ? 2 : 3;
    for (int i = 0; i < n_unused; i++) {
        int k = unused[i];
        if (p[k] != defaults[k])
            return cf_fail(m, "pendulum.%s = %s is not used with pendulum.start = '%s' (the start is derived "
                           "there): allowed %s here, or choose another start", names[k], cf_repr(p[k], a),
                           start_name(start), cf_repr(defaults[k], b));
    }
    if (p[P_theta0] != 0.0 && dim < 2)
        return cf_fail(m, "pendulum.theta0 = %s needs dimension >= 2 (it is %d): allowed 0 here",
                       cf_repr(p[P_theta0], a), dim);
    if (p[P_phi0] != 0.0 && dim < 3)
        return cf_fail(m, "pendulum.phi0 = %s needs dimension >= 3 (it is %d): allowed 0 here",
                       cf_repr(p[P_phi0], a), dim);
    if (start == SW_start_on_ground && (int)p[P_ground] == SW_ground_none)
        return cf_fail(m, "pendulum.start = 'on_ground' needs a ground: allowed with ground = "
                       "'spring_damper', or choose another start");
    if (payload == SW_payload_none && p[P_m_payload] != 0.0)
        return cf_fail(m, "pendulum.m_payload = %s needs payload = 'rigid' or 'elastic' (with payload = 'none' "
                       "the load is part of pendulum.mass): allowed 0 here", cf_repr(p[P_m_payload], a));
    if (payload != SW_payload_none && p[P_m_payload] <= 0.0)
        return cf_fail(m, "pendulum.m_payload = %s with payload = '%s': allowed (0, inf) kg",
                       cf_repr(p[P_m_payload], a), payload_name(payload));
    return 0;
}

/* PendulumModel.__init__ */
int cf_prepare(CfModel *m)
{
    const double *p = m->p;
    PendulumData *d = (PendulumData *)m->data;
    d->dim = dimension_of(p);
    d->payload = (int)p[P_payload];
    d->start = (int)p[P_start];
    d->m[0] = d->dim >= 2 ? 1.0 : 0.0;   /* _MASKS: 1 (0, 1, 0), 2 (1, 1, 0), 3 (1, 1, 1) */
    d->m[1] = 1.0;
    d->m[2] = d->dim == 3 ? 1.0 : 0.0;
    d->total = p[P_mass] + p[P_m_payload];
    d->mu = p[P_mass] * p[P_m_payload] / d->total;
    d->b_sling = 2.0 * p[P_zeta_sling] * sqrt(p[P_c_sling] * d->mu);
    double half = 0.5 * p[P_rho_air] * p[P_drag_coefficient];
    d->k_load = half * p[P_drag_area];
    d->k_hook = d->payload != SW_payload_none ? half * p[P_drag_area_hook] : 0.0;
    d->has_ground = (int)p[P_ground] != SW_ground_none;
    d->body = d->payload == SW_payload_rigid
              && (p[P_c_pin] != 0.0 || p[P_J_payload] != 0.0 || p[P_J_hook] != 0.0);
    /* _start_tension: the rope force that holds the start at rest */
    if (d->start == SW_start_on_ground)
        d->rest_tension = d->payload != SW_payload_none ? p[P_mass] * p[P_g] : 0.0;
    else
        d->rest_tension = d->total * p[P_g] * cos(p[P_theta0]) * cos(p[P_phi0]);
    m->n_states = d->payload == SW_payload_rigid ? 10 : d->payload == SW_payload_elastic ? 12 : 6;
    return 0;
}

/* --- helpers (PendulumModel._ground_force, _drag, _hook_force, _payload_accel) ------------------- */
/* seed 001 eq. 7 with damper: unilateral, never pulls */
static double ground_force(const CfModel *m, double y, double vy)
{
    const double *p = m->p;
    if (!DATA(m)->has_ground) return 0.0;
    double pen = p[P_ground_height] - y;
    if (pen <= 0.0) return 0.0;
    double n = p[P_c_ground] * pen - p[P_b_ground] * vy;
    return n > 0.0 ? n : 0.0;   /* max(0.0, n): 0.0 unless n > 0 */
}

static void drag(double k, double vx, double vy, double vz, double out[3])
{
    if (k == 0.0) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    double s = -k * sqrt(vx * vx + vy * vy + vz * vz);
    out[0] = s * vx;
    out[1] = s * vy;
    out[2] = s * vz;
}

/* rope + weight + drag on the hook of a hook-payload pair, frozen directions dropped */
static void hook_force(const CfModel *m, const double *x, const double *u, double fh[3])
{
    const double *p = m->p, *mk = DATA(m)->m;
    double dr[3];
    drag(DATA(m)->k_hook, x[3], x[4], x[5], dr);
    fh[0] = (u[IN_Fx_rope] + dr[0]) * mk[0];
    fh[1] = (u[IN_Fy_rope] - p[P_mass] * p[P_g] + dr[1]) * mk[1];
    fh[2] = (u[IN_Fz_rope] + dr[2]) * mk[2];
}

/* applied acceleration f_p of the payload (gravity, ground, drag); returns the ground reaction N */
static double payload_accel(const CfModel *m, double y, const double v[3], double fp[3])
{
    const double *p = m->p, *mk = DATA(m)->m;
    double n = ground_force(m, y, v[1]), dr[3];
    drag(DATA(m)->k_load, v[0], v[1], v[2], dr);
    double inv = 1.0 / p[P_m_payload];
    fp[0] = dr[0] * inv * mk[0];
    fp[1] = ((n + dr[1]) * inv - p[P_g]) * mk[1];
    fp[2] = dr[2] * inv * mk[2];
    return n;
}

/* --- rigid sling ------------------------------------------------------------------------------- */
typedef struct Rigid {
    double ah[3], ddth, ddph, s, n, e[3], vp[3];
} Rigid;

/* PendulumModel._rigid_body: hook acceleration a_h, sling tension S and the payload's applied
   acceleration with the pin's transverse force R_t, from
       [m_h I + m_p e e^T + kappa m_p P_e + J_h / l^2 P_r] a_h
           = F_h + G + m_p (f_p.e + L |w|^2) e + kappa m_p P_e f_p - (1 - kappa) tau x e / L
       S = m_p (f_p.e - a_h.e + L |w|^2),   R_t = kappa m_p P_e (a_h - f_p) + (1 - kappa) tau x e / L
   kappa = J_p / (J_p + m_p L^2), P_e = I - e e^T, P_r = I - e_r e_r^T (derived: Newton-Euler of the
   payload body turning with the sling, the hook turning with the rope link top -> hook of length l;
   the pin damper tau = -c_pin (w_s - w_r), w_r = e_r x (v_h - v_top) / l, w_s = e x (v_p - v_h) / L). */
static void rigid_body(const CfModel *m, const double *x, const double *u, const double e[3], const double et[3],
                       const double ep[3], double dth, double dph, double fp[3], const double fh[3], double w2,
                       double ah[3], double *s)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    double L = p[P_L_sling];
    double d[3] = {x[0] - u[IN_x_top], x[1] - u[IN_y_top], x[2] - u[IN_z_top]};
    double ell = sqrt(dot3(d, d));
    double er[3], tau[3] = {0.0, 0.0, 0.0}, g_h[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < 3; i++) er[i] = d[i] / ell;
    if (p[P_c_pin] != 0.0) {
        double vrel[3] = {(x[3] - u[IN_vx_top]) / ell, (x[4] - u[IN_vy_top]) / ell, (x[5] - u[IN_vz_top]) / ell};
        double w[3], wr[3], ws[3], ner[3];
        cross3(er, vrel, wr);
        for (int i = 0; i < 3; i++) w[i] = et[i] * dth + ep[i] * dph;
        cross3(e, w, ws);
        for (int i = 0; i < 3; i++) tau[i] = -p[P_c_pin] * (ws[i] - wr[i]);
        for (int i = 0; i < 3; i++) ner[i] = -er[i] / ell;
        cross3(tau, ner, g_h);
    }
    double mp = p[P_m_payload], kappa = p[P_J_payload] / (p[P_J_payload] + p[P_m_payload] * L * L);
    double pe[9], a[9], te[3], pin[3], pf[3], rhs[3];   /* row-major 3x3 */
    double kmp = kappa * mp, jl = p[P_J_hook] / (ell * ell);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double eye = i == j ? 1.0 : 0.0;
            pe[3 * i + j] = eye - e[i] * e[j];
            a[3 * i + j] = p[P_mass] * eye + mp * (e[i] * e[j]) + kmp * pe[3 * i + j] + jl * (eye - er[i] * er[j]);
        }
    cross3(tau, e, te);
    for (int i = 0; i < 3; i++) pin[i] = (1.0 - kappa) * te[i] / L;
    double fe = dot3(fp, e);
    cf_matvec3(pe, fp, pf);
    double along = mp * (fe + w2);
    for (int i = 0; i < 3; i++) rhs[i] = fh[i] + g_h[i] + along * e[i] + kmp * pf[i] - pin[i];
    if (cf_solve_free3(dd->m, a, rhs, ah))   /* not with mass > 0: the matrix is positive definite */
        ah[0] = ah[1] = ah[2] = NAN;
    *s = mp * (fe - dot3(ah, e) + w2);
    double diff[3], pd[3];
    for (int i = 0; i < 3; i++) diff[i] = ah[i] - fp[i];
    cf_matvec3(pe, diff, pd);
    for (int i = 0; i < 3; i++) {
        double r_t = kmp * pd[i] + pin[i];
        fp[i] = (fp[i] + r_t / mp) * dd->m[i];
    }
}

/* PendulumModel._rigid: hook acceleration, payload angular accelerations, S and N (header comment) */
static void rigid(const CfModel *m, const double *x, const double *u, Rigid *r)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    const double *mk = dd->m;
    double L = p[P_L_sling];
    double th = x[6], ph = x[7], dth = x[8], dph = x[9];
    double st = sin(th), ct = cos(th), sp = sin(ph), cp = cos(ph);
    double *e = r->e, et[3], ep[3], fp[3], fh[3], *ah = r->ah;
    e[0] = st * cp;
    e[1] = -ct * cp;
    e[2] = sp;
    et[0] = ct * cp;
    et[1] = st * cp;
    et[2] = 0.0;
    ep[0] = -st * sp;
    ep[1] = ct * sp;
    ep[2] = cp;
    r->vp[0] = x[3] + L * (et[0] * dth + ep[0] * dph);
    r->vp[1] = x[4] + L * (et[1] * dth + ep[1] * dph);
    r->vp[2] = x[5] + L * ep[2] * dph;
    r->n = payload_accel(m, x[1] + L * e[1], r->vp, fp);
    hook_force(m, x, u, fh);
    double mh = p[P_mass];
    double w2 = L * (cp * cp * dth * dth + dph * dph);
    if (dd->body) {
        rigid_body(m, x, u, e, et, ep, dth, dph, fp, fh, w2, ah, &r->s);
    } else {
        r->s = dd->mu * (e[0] * (fp[0] - fh[0] / mh) + e[1] * (fp[1] - fh[1] / mh) + e[2] * (fp[2] - fh[2] / mh)
                         + w2);
        for (int i = 0; i < 3; i++) ah[i] = (fh[i] + r->s * e[i]) / mh * mk[i];
    }
    double rr[3] = {fp[0] - ah[0], fp[1] - ah[1], fp[2] - ah[2]};
    if (dd->dim == 1) {
        r->ddth = r->ddph = 0.0;
    } else {
        r->ddth = (et[0] * rr[0] + et[1] * rr[1] + 2.0 * L * sp * cp * dth * dph) / (L * cp * cp);
        r->ddph = dd->dim == 3 ? (ep[0] * rr[0] + ep[1] * rr[1] + ep[2] * rr[2] - L * sp * cp * dth * dth) / L : 0.0;
    }
}

/* --- elastic sling (PendulumModel._elastic) ------------------------------------------------------ */
typedef struct Elastic {
    double ah[3], ap[3], s, n, e[3];
} Elastic;

static void elastic(const CfModel *m, const double *x, const double *u, Elastic *r)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    const double *mk = dd->m;
    double d0 = x[6] - x[0], d1 = x[7] - x[1], d2 = x[8] - x[2];
    double length = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    double *e = r->e, fp[3], fh[3];
    if (length > 0.0) {
        e[0] = d0 / length;
        e[1] = d1 / length;
        e[2] = d2 / length;
    } else {
        e[0] = 0.0;
        e[1] = -1.0;
        e[2] = 0.0;
    }
    double rate = e[0] * (x[9] - x[3]) + e[1] * (x[10] - x[4]) + e[2] * (x[11] - x[5]);
    r->s = p[P_c_sling] * (length - p[P_L_sling]) + dd->b_sling * rate;
    r->n = payload_accel(m, x[7], x + 9, fp);
    hook_force(m, x, u, fh);
    double mh = p[P_mass], mp = p[P_m_payload];
    for (int i = 0; i < 3; i++) {
        r->ah[i] = (fh[i] + r->s * e[i]) / mh * mk[i];
        r->ap[i] = (fp[i] - r->s * e[i] / mp) * mk[i];
    }
}

/* --- lone hook turning with the rope link (PendulumModel._turning_load) --------------------------- */
static void turning_load(const CfModel *m, const double *x, const double *u, const double force[3], double acc[3])
{
    const double *p = m->p;
    double d[3] = {x[0] - u[IN_x_top], x[1] - u[IN_y_top], x[2] - u[IN_z_top]};
    double ell2 = dot3(d, d), ell = sqrt(ell2), er[3], a[9];
    for (int i = 0; i < 3; i++) er[i] = d[i] / ell;
    double jl = p[P_J_hook] / ell2;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double eye = i == j ? 1.0 : 0.0;
            a[3 * i + j] = p[P_mass] * eye + jl * (eye - er[i] * er[j]);
        }
    if (cf_solve_free3(DATA(m)->m, a, force, acc))   /* not with mass > 0 */
        acc[0] = acc[1] = acc[2] = NAN;
}

/* --- interface --------------------------------------------------------------------------------- */
static void unit_vector(double theta, double phi, double e[3])
{
    double cp = cos(phi);
    e[0] = sin(theta) * cp;
    e[1] = -cos(theta) * cp;
    e[2] = sin(phi);
}

/* PendulumModel.initial_state: at rest (apart from the given hook velocity), consistent with the rope
   force in u; the hook at its start (_hook_start: the parameters, or drop from the suspension point at
   the release angles; on_ground: placed on the ground).  Hanging: S = -(m_p / M) F.e; on the ground the
   load sinks in by N / c_g with N = max(0, M g - F_y) and S = -F.e + m_h g e_y. */
int cf_initial_state(CfModel *m, const double *u, double *x)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    const double *mk = dd->m;
    double v[3] = {p[P_vx0] * mk[0], p[P_vy0] * mk[1], p[P_vz0] * mk[2]};
    double F[3] = {u[IN_Fx_rope] * mk[0], u[IN_Fy_rope] * mk[1], u[IN_Fz_rope] * mk[2]};
    double hook[3], e[3];
    if (dd->start == SW_start_below_top) {
        double drop = u[IN_drop];
        unit_vector(p[P_theta0], p[P_phi0], e);
        hook[0] = u[IN_x_top] + drop * e[0];
        hook[1] = u[IN_y_top] + drop * e[1];
        hook[2] = u[IN_z_top] + drop * e[2];
    } else if (dd->start == SW_start_on_ground) {
        hook[0] = p[P_x0];
        hook[1] = -INFINITY;
        hook[2] = p[P_z0];
    } else {
        hook[0] = p[P_x0];
        hook[1] = p[P_y0];
        hook[2] = p[P_z0];
    }
    if (dd->payload == SW_payload_none) {
        if (dd->has_ground && hook[1] <= p[P_ground_height]) {
            double w = p[P_mass] * p[P_g] - F[1];
            hook[1] = p[P_ground_height] - (w > 0.0 ? w : 0.0) / p[P_c_ground];
        }
        for (int i = 0; i < 3; i++) {
            x[i] = hook[i];
            x[3 + i] = v[i];
        }
        return 0;
    }
    if (dd->start == SW_start_on_ground) hook[1] = p[P_ground_height];
    double th = dd->dim >= 2 ? p[P_theta_payload0] : 0.0;
    double ph = dd->dim == 3 ? p[P_phi_payload0] : 0.0;
    unit_vector(th, ph, e);
    double f_e = F[0] * e[0] + F[1] * e[1] + F[2] * e[2];
    double n = 0.0, L = p[P_L_sling];
    int on_ground = dd->has_ground && hook[1] + L * e[1] <= p[P_ground_height];
    if (on_ground) {
        double w = dd->total * p[P_g] - F[1];
        n = w > 0.0 ? w : 0.0;
    }
    double s = n > 0.0 ? -f_e + p[P_mass] * p[P_g] * e[1] : -p[P_m_payload] / dd->total * f_e;
    double length = dd->payload == SW_payload_elastic ? L + s / p[P_c_sling] : L;
    if (on_ground) hook[1] = p[P_ground_height] - n / p[P_c_ground] - length * e[1];
    for (int i = 0; i < 3; i++) {
        x[i] = hook[i];
        x[3 + i] = v[i];
    }
    if (dd->payload == SW_payload_rigid) {
        x[6] = th;
        x[7] = ph;
        x[8] = x[9] = 0.0;
    } else {
        for (int i = 0; i < 3; i++) {
            x[6 + i] = hook[i] + length * e[i];
            x[9 + i] = v[i];
        }
    }
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    const double *mk = dd->m;
    (void)t;
    dx[0] = x[3];
    dx[1] = x[4];
    dx[2] = x[5];
    if (dd->payload == SW_payload_none) {
        double fx = u[IN_Fx_rope], fy = u[IN_Fy_rope], fz = u[IN_Fz_rope];
        if (dd->has_ground) fy = fy + ground_force(m, x[1], x[4]);
        if (dd->k_load != 0.0) {
            double dr[3];
            drag(dd->k_load, x[3], x[4], x[5], dr);
            fx = fx + dr[0];
            fy = fy + dr[1];
            fz = fz + dr[2];
        }
        double mass = p[P_mass];
        if (p[P_J_hook] != 0.0) {
            double force[3] = {fx, fy - mass * p[P_g], fz};
            turning_load(m, x, u, force, dx + 3);
            return;
        }
        dx[3] = fx / mass * mk[0];
        dx[4] = (fy / mass - p[P_g]) * mk[1];
        dx[5] = fz / mass * mk[2];
        return;
    }
    if (dd->payload == SW_payload_rigid) {
        /* (the Python model's _rigid_free is the same arithmetic without the zero forces) */
        Rigid r;
        rigid(m, x, u, &r);
        dx[3] = r.ah[0];
        dx[4] = r.ah[1];
        dx[5] = r.ah[2];
        dx[6] = dd->dim >= 2 ? x[8] : 0.0;
        dx[7] = dd->dim == 3 ? x[9] : 0.0;
        dx[8] = r.ddth;
        dx[9] = r.ddph;
        return;
    }
    Elastic r;
    elastic(m, x, u, &r);
    for (int i = 0; i < 3; i++) {
        dx[3 + i] = r.ah[i];
        dx[6 + i] = x[9 + i];
        dx[9 + i] = r.ap[i];
    }
}

/* sway angles of a chord: theta in the x-y plane, phi out of it (rad) (_angles) */
static void angles(double dx, double dy_down, double dz, double *theta, double *phi)
{
    *theta = atan2(dx, dy_down);
    *phi = atan2(dz, cf_py_hypot(dx, dy_down));
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    double n, s = 0.0, th_p = 0.0, ph_p = 0.0, pp[3], vp[3];
    (void)t;
    angles(x[0] - u[IN_x_top], u[IN_y_top] - x[1], x[2] - u[IN_z_top], &y[OUT_theta], &y[OUT_phi]);
    if (dd->payload == SW_payload_none) {
        n = ground_force(m, x[1], x[4]);
        for (int i = 0; i < 3; i++) {
            pp[i] = x[i];
            vp[i] = x[3 + i];
        }
    } else if (dd->payload == SW_payload_rigid) {
        Rigid r;
        double L = p[P_L_sling];
        rigid(m, x, u, &r);
        s = r.s;
        n = r.n;
        for (int i = 0; i < 3; i++) {
            pp[i] = x[i] + L * r.e[i];
            vp[i] = r.vp[i];
        }
        angles(r.e[0], -r.e[1], r.e[2], &th_p, &ph_p);
    } else {
        Elastic r;
        elastic(m, x, u, &r);
        s = r.s;
        n = r.n;
        for (int i = 0; i < 3; i++) {
            pp[i] = x[6 + i];
            vp[i] = x[9 + i];
        }
        angles(r.e[0], -r.e[1], r.e[2], &th_p, &ph_p);
    }
    y[OUT_x] = x[0];
    y[OUT_y] = x[1];
    y[OUT_z] = x[2];
    y[OUT_vx] = x[3];
    y[OUT_vy] = x[4];
    y[OUT_vz] = x[5];
    y[OUT_N_ground] = n;
    y[OUT_x_payload] = pp[0];
    y[OUT_y_payload] = pp[1];
    y[OUT_z_payload] = pp[2];
    y[OUT_vx_payload] = vp[0];
    y[OUT_vy_payload] = vp[1];
    y[OUT_vz_payload] = vp[2];
    y[OUT_theta_payload] = th_p;
    y[OUT_phi_payload] = ph_p;
    y[OUT_sling_force] = s;
    y[OUT_lifted] = n == 0.0 ? 1.0 : 0.0;
    y[OUT_x_suspension] = u[IN_x_top];
    y[OUT_y_suspension] = u[IN_y_top];
    y[OUT_z_suspension] = u[IN_z_top];
    y[OUT_suspended_mass] = dd->total;
    y[OUT_rest_tension] = dd->rest_tension;
}

int cf_frozen(const CfModel *m)
{
    (void)m;
    return 0;
}

/* the closed form is the lone hook's; with a payload solver = auto takes rk4 */
int cf_exact_applies(const CfModel *m)
{
    return DATA(m)->payload == SW_payload_none;
}

/* PendulumModel.prepare_exact_step: refuse solver = 'exact' with a payload when the FMU leaves initialization
   (the closed form is the lone hook's; issue 23), in the same words */
int cf_prepare_exact_step(CfModel *m)
{
    const PendulumData *dd = DATA(m);
    if (dd->payload != SW_payload_none)
        return cf_fail(m, "pendulum.solver = 'exact' with payload = '%s': exact is the closed form of the hook "
                       "without payload; allowed here: an integrator (rk4, rk45, radau, ...)",
                       payload_name(dd->payload));
    return 0;
}

/* Closed-form step of the lone hook in free flight (no payload, ground, drag or J_hook; derived): with
   the rope force u0 + s r1 + s^2/2 r2 over the step the acceleration is a polynomial in s, so
   v(h) = v0 + (u0 h + r1 h^2/2 + r2 h^3/6)/m + g_vec h  and
   x(h) = x0 + v0 h + (u0 h^2/2 + r1 h^3/6 + r2 h^4/24)/m + g_vec h^2/2  (frozen directions masked).
   With a payload cf_prepare_exact_step has refused 'exact' at initialization already; the check here keeps a
   caller of the bare function (the harness) from stepping a payload with the hook's closed form. */
int cf_exact_step(CfModel *m, double t, const double *x, double h, const double *u0, const double *r1,
                  const double *r2, double max_step, double *x1)
{
    const double *p = m->p;
    const PendulumData *dd = DATA(m);
    (void)t;
    (void)max_step;
    if (dd->payload != SW_payload_none) {
        cf_fail(m, "pendulum.solver = 'exact' with payload = '%s': exact is the closed form of the hook without "
                "payload; allowed here: an integrator (rk4, rk45, radau, ...)", payload_name(dd->payload));
        return -1;
    }
    if (dd->has_ground || dd->k_load != 0.0 || p[P_J_hook] != 0.0) return 0;
    double h2 = h * h, h3 = h * h * h, inv_m = 1.0 / p[P_mass];
    for (int i = 0; i < 3; i++) {
        double mi = dd->m[i];
        double a0 = u0[i] * inv_m, a1 = r1[i] * inv_m, a2 = r2[i] * inv_m;
        if (i == 1) a0 -= p[P_g];
        double v0 = x[3 + i];
        x1[i] = x[i] + v0 * h + mi * (a0 * h2 / 2.0 + a1 * h3 / 6.0 + a2 * h3 * h / 24.0);
        x1[3 + i] = v0 + mi * (a0 * h + a1 * h2 / 2.0 + a2 * h3 / 6.0);
    }
    return 1;
}

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    static const char *const hook[] = {"x", "y", "z", "vx", "vy", "vz"};
    static const char *const rigid_names[] = {"theta_payload", "phi_payload", "dtheta_payload", "dphi_payload"};
    static const char *const elastic_names[] = {"x_payload", "y_payload", "z_payload",
                                                "vx_payload", "vy_payload", "vz_payload"};
    if (i < 0 || i >= m->n_states) return NULL;
    if (i < 6) return hook[i];
    return DATA(m)->payload == SW_payload_rigid ? rigid_names[i - 6] : elastic_names[i - 6];
}
