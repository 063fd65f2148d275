/* Telescopic boom of the truck crane 55713-1K, luffed by a hydraulic cylinder (seed 000):
   cranefmu.physics.boom.BoomModel in C, operation by operation.

   Geometry seed 000 Fig. 1, eq. 1, 11-18, Table 1 (cf_boom.c).  Modes: tip = dynamic with a rigid
   (prescribed) cylinder holds phi1 = phi_cmd(t) and the boom turns with the chassis; with the
   spring-damper cylinder one degree of freedom, the elevation psi (derived, Lagrange with rheonomic
   telescoping):
       J_O psi'' + J_O' psi' = -g S cos psi + L (Fy cos psi - Fx sin psi) + F_cyl ds3/dphi1
       F_cyl = k (s_free - s3) + b (s_free' - ds3/dphi1 (psi' + gamma'))      (push > 0)
   with s_free = s3(phi_cmd) + offset (the state oil_offset, constant).  tip = kinematic: the tip
   follows the laws from a fixed foot, carried by seed 002's crane motions (travel, steering, an
   auxiliary boom).  States (psi, psi_rate, oil_offset) in every mode; frozen unless elastic. */
#include <math.h>

#include "Boom_tables.h"
#include "cf_boom.h"
#include "cf_model.h"

typedef struct BoomData {
    CfBoom b;
    double elastic;     /* tip dynamic and cylinder spring_damper */
    double crane_moves; /* travel_distance, steer_delta or aux_length not 0 */
} BoomData;

typedef char boom_data_fits[sizeof(BoomData) <= CF_MODEL_DATA * sizeof(double) ? 1 : -1];

const int cf_has_exact_step = 0;

static const BoomData *data(const CfModel *m)
{
    return (const BoomData *)m->data;
}

int cf_check_params(CfModel *m)
{
    CfBoom b;
    CF_BOOM_FROM_PARAMS(&b, m->p);
    return cf_boom_check(m, &b);
}

int cf_prepare(CfModel *m)
{
    BoomData *d = (BoomData *)m->data;
    CF_BOOM_FROM_PARAMS(&d->b, m->p);
    d->elastic = !d->b.tip_kinematic && d->b.cylinder_spring_damper;
    d->crane_moves = d->b.travel_distance != 0.0 || d->b.steer_delta != 0.0 || d->b.aux_length != 0.0;
    m->n_states = 3;
    return 0;
}

/* (y_base, gamma, vy_base, gamma_rate) from the chassis; 0 for a kinematic tip */
static void base(const BoomData *d, const double *u, double out[4])
{
    if (d->b.tip_kinematic) {
        out[0] = out[1] = out[2] = out[3] = 0.0;
        return;
    }
    out[0] = u[IN_y_base];
    out[1] = u[IN_gamma];
    out[2] = u[IN_vy_base];
    out[3] = u[IN_gamma_rate];
}

static void mass_state(const BoomData *d, double t, const double *u, CfMassState *ms)
{
    CfTelescope tele;
    cf_boom_telescope_at(t, &d->b, u + IN_extension_command, &tele);
    cf_boom_mass_state_at(&tele, &d->b, ms);
}

/* push force [N] of the spring-damper cylinder and its lever ds3/dphi1 [m] */
static double cylinder_force(const BoomData *d, double t, double psi, double psi_rate, double offset,
                             const double *u, double *lever)
{
    const CfBoom *b = &d->b;
    double gamma = u[IN_gamma], gamma_rate = u[IN_gamma_rate];
    double luff[3], s3c, lever_c, s3, phi2;

    cf_boom_luff_at(t, b, u + IN_luff_command, luff);
    cf_boom_cylinder_geometry(luff[0], b, &s3c, &lever_c, &phi2);
    cf_boom_cylinder_geometry(psi + gamma, b, &s3, lever, &phi2);
    return b->cylinder_stiffness * (s3c + offset - s3)
           + b->cylinder_damping * (lever_c * luff[1] - *lever * (psi_rate + gamma_rate));
}

static double psi_acc(const BoomData *d, double t, const double *x, const double *u, const CfMassState *ms)
{
    double psi = x[0], psi_rate = x[1], offset = x[2], lever, force, c, s, moment;

    force = cylinder_force(d, t, psi, psi_rate, offset, u, &lever);
    c = cos(psi);
    s = sin(psi);
    moment = -d->b.g * ms->S * c + ms->length * (c * u[IN_Fy_tip] - s * u[IN_Fx_tip]) + force * lever;
    return (moment - ms->J_rate * psi_rate) / ms->J;
}

/* (psi, psi_rate, psi_acc, phi1) at t */
static void angles(const BoomData *d, double t, const double *x, const double *u, double out[4])
{
    double bs[4], luff[3], gamma, gamma_rate;

    base(d, u, bs);
    gamma = bs[1];
    gamma_rate = bs[3];
    if (d->elastic) {
        CfMassState ms;
        mass_state(d, t, u, &ms);
        out[0] = x[0];
        out[1] = x[1];
        out[2] = psi_acc(d, t, x, u, &ms);
        out[3] = x[0] + gamma;
        return;
    }
    cf_boom_luff_at(t, &d->b, u + IN_luff_command, luff);
    /* rigid cylinder: the boom turns with the chassis; the chassis' angular acceleration is unknown here */
    out[0] = luff[0] - gamma;
    out[1] = luff[1] - gamma_rate;
    out[2] = luff[2];
    out[3] = luff[0];
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    /* static equilibrium: the boom at the commanded angle (laws at t = 0), the oil column
       pre-compressed to hold the tip load and the weight, at rest */
    const BoomData *d = data(m);
    const CfBoom *b = &d->b;
    double bs[4], luff[3], psi, psi_rate, c, s, moment, s3, lever, phi2;
    CfMassState ms;

    base(d, u, bs);
    cf_boom_luff_at(0.0, b, u + IN_luff_command, luff);
    psi = luff[0] - bs[1];
    psi_rate = luff[1] - bs[3];
    x[0] = psi;
    x[1] = psi_rate;
    x[2] = 0.0;
    if (!d->elastic)
        return 0;
    mass_state(d, 0.0, u, &ms);
    c = cos(psi);
    s = sin(psi);
    moment = -b->g * ms.S * c + ms.length * (c * u[IN_Fy_tip] - s * u[IN_Fx_tip]) - ms.J_rate * psi_rate;
    cf_boom_cylinder_geometry(luff[0], b, &s3, &lever, &phi2);
    x[2] = -moment / lever / b->cylinder_stiffness;
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    const BoomData *d = data(m);
    CfMassState ms;

    if (!d->elastic) {
        dx[0] = dx[1] = dx[2] = 0.0;
        return;
    }
    mass_state(d, t, u, &ms);
    dx[0] = x[1];
    dx[1] = psi_acc(d, t, x, u, &ms);
    dx[2] = 0.0;
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    const BoomData *d = data(m);
    const CfBoom *b = &d->b;
    double bs[4], ang[4], psi, psi_rate, c, s, L, Ld, tip[3], vtip[3], react[3];
    double s3, lever, phi2, residual, force;
    CfMassState ms;

    base(d, u, bs);
    angles(d, t, x, u, ang);
    psi = ang[0];
    psi_rate = ang[1];
    mass_state(d, t, u, &ms);
    c = cos(psi);
    s = sin(psi);
    L = ms.length;
    Ld = ms.length_rate;
    tip[0] = b->x_foot + L * c;
    tip[1] = b->y_foot + bs[0] + L * s;
    vtip[0] = Ld * c - L * psi_rate * s;
    vtip[1] = bs[2] + Ld * s + L * psi_rate * c;
    tip[2] = vtip[2] = 0.0;
    if (d->crane_moves)
        cf_boom_crane_motion_tip(t, b, psi, psi_rate, L, Ld, tip, vtip);
    if (b->tip_kinematic) {
        double travel = u[IN_x_travel], speed = u[IN_vx_travel];
        if (travel != 0.0 || speed != 0.0) { /* commanded travel (untouched otherwise) */
            tip[0] = tip[0] + travel;
            vtip[0] = vtip[0] + speed;
        }
    }
    cf_boom_base_reactions(&ms, psi, psi_rate, ang[2], u[IN_Fx_tip], u[IN_Fy_tip], b->g, react);
    cf_boom_cylinder_geometry(ang[3], b, &s3, &lever, &phi2);
    residual = cf_boom_constraint_residual(ang[3], phi2, s3, b);
    if (d->elastic) {
        double lever_now;
        force = cylinder_force(d, t, psi, psi_rate, x[2], u, &lever_now);
    } else {
        force = -react[2] / lever; /* the cylinder carries the whole moment about the pivot O2 */
    }
    y[OUT_x_tip] = tip[0];
    y[OUT_y_tip] = tip[1];
    y[OUT_z_tip] = tip[2];
    y[OUT_vx_tip] = vtip[0];
    y[OUT_vy_tip] = vtip[1];
    y[OUT_vz_tip] = vtip[2];
    y[OUT_Fx_base] = react[0];
    y[OUT_Fy_base] = react[1];
    y[OUT_M_base] = react[2];
    y[OUT_boom_length] = L;
    y[OUT_luff_angle_out] = ang[3];
    y[OUT_cylinder_force] = force;
    y[OUT_cylinder_length] = s3;
    y[OUT_constraint_residual] = residual;
    y[OUT_extension] = L - b->boom_length_start;
    if (b->tip_kinematic) {
        y[OUT_m_carried] = y[OUT_Sx_carried] = y[OUT_J_carried] = 0.0;
    } else if (d->elastic) { /* the elastic boom keeps its own elevation: the foot carries only its mass */
        y[OUT_m_carried] = ms.mass;
        y[OUT_Sx_carried] = y[OUT_J_carried] = 0.0;
    } else {
        y[OUT_m_carried] = ms.mass;
        y[OUT_Sx_carried] = ms.S * c;
        y[OUT_J_carried] = ms.J;
    }
}

int cf_frozen(const CfModel *m)
{
    return !data(m)->elastic;
}

CF_NO_EXACT_STEP

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    static const char *names[3] = {"psi", "psi_rate", "oil_offset"};
    (void)m;
    return i >= 0 && i < 3 ? names[i] : "";
}
