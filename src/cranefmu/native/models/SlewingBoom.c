/* Slewing telescopic boom: cranefmu.physics.slewing.SlewingBoomModel in C, operation by operation.

   The boom of cf_boom.c (seed 000, rigid luffing cylinder, telescoping law) turned about the vertical
   axis through the foot O2 by the slewing angle sigma (a trapezoid law from slew_angle_start, or
   slew_angle_start + the input slew_command).  Kinematics (derived): e_r = (cos sigma, 0, sin sigma),
   e_n = (-sin sigma, 0, cos sigma); the chassis' pitch gamma and roll beta tilt the boom plane by
   gamma_e = gamma cos sigma + beta sin sigma, psi = phi1 - gamma_e, and the tip is at
       x = x_foot + L cos psi cos sigma,  y = y_foot + y_base + L sin psi,  z = L cos psi sin sigma.
   Loads at O2 in the chassis frame: F = F_r e_r + F_y e_y + F_n e_n,
       Mx = -M sin sigma + F_n L sin psi cos sigma,  Mz = M cos sigma + F_n L sin psi sin sigma.
   The boom's slewing inertia is neglected in the loads.  No internal states. */
#include <math.h>

#include "SlewingBoom_tables.h"
#include "cf_boom.h"
#include "cf_model.h"
#include "cf_motion_laws.h"
#include "cf_repr.h"

typedef struct SlewingData {
    CfBoom b;
    double slew_angle_start, slew_angle, slew_speed, slew_t_acc, slew_start, slew_input;
} SlewingData;

typedef char slewing_data_fits[sizeof(SlewingData) <= CF_MODEL_DATA * sizeof(double) ? 1 : -1];

const int cf_has_exact_step = 0;

static void fill(SlewingData *d, const double *p)
{
    CF_BOOM_FROM_PARAMS(&d->b, p);
    d->slew_angle_start = p[P_slew_angle_start];
    d->slew_angle = p[P_slew_angle];
    d->slew_speed = p[P_slew_speed];
    d->slew_t_acc = p[P_slew_t_acc];
    d->slew_start = p[P_slew_start];
    d->slew_input = p[P_slew_source] == SW_slew_source_input;
}

int cf_check_params(CfModel *m)
{
    static const char *tips[2] = {"dynamic", "kinematic"}, *cylinders[2] = {"prescribed", "spring_damper"};
    char r[CF_REPR_SIZE];
    SlewingData d;

    fill(&d, m->p);
    if (cf_boom_check(m, &d.b))
        return 1;
    if (m->p[P_tip] != SW_tip_dynamic || m->p[P_cylinder] != SW_cylinder_prescribed)
        return cf_fail(m, "boom.tip = '%s', boom.cylinder = '%s' are not allowed for the slewing boom: allowed tip "
                       "'dynamic' with cylinder 'prescribed'", tips[(int)m->p[P_tip]],
                       cylinders[(int)m->p[P_cylinder]]);
    if (d.slew_angle != 0.0 && d.slew_t_acc > fabs(d.slew_angle) / d.slew_speed)
        return cf_fail(m, "boom.slew_t_acc = %s is too long: allowed <= |slew_angle| / slew_speed = %.6g s",
                       cf_repr(d.slew_t_acc, r), fabs(d.slew_angle) / d.slew_speed);
    return 0;
}

int cf_prepare(CfModel *m)
{
    fill((SlewingData *)m->data, m->p);
    m->n_states = 0;
    return 0;
}

/* sigma [rad], its rate and acceleration from the slewing law or slew_angle_start + the command */
static void slew_at(const SlewingData *d, double t, const double command[3], double out[3])
{
    if (d->slew_input) {
        out[0] = d->slew_angle_start + command[0];
        out[1] = command[1];
        out[2] = command[2];
        return;
    }
    cf_trapezoid_motion(t, d->slew_start, d->slew_angle, d->slew_speed, d->slew_t_acc, out);
    out[0] = d->slew_angle_start + out[0];
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    (void)m, (void)u, (void)x;
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    (void)m, (void)t, (void)x, (void)u, (void)dx;
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    const SlewingData *d = (const SlewingData *)m->data;
    const CfBoom *b = &d->b;
    double yb = u[IN_y_base], gamma = u[IN_gamma], beta = u[IN_beta], vyb = u[IN_vy_base];
    double gr = u[IN_gamma_rate], br = u[IN_beta_rate], fx = u[IN_Fx_tip], fy = u[IN_Fy_tip], fz = u[IN_Fz_tip];
    double sig[3], luff[3], cs, ss, tilt, tilt_rate, psi, psi_rate, cp, sp, L, Ld, r, r_rate, f_r, f_n;
    double react[3], fbr, fby, m_plane, m_r, s3, lever, phi2, j, s;
    CfTelescope tele;
    CfMassState ms;

    (void)x;
    slew_at(d, t, u + IN_slew_command, sig);
    cs = cos(sig[0]);
    ss = sin(sig[0]);
    tilt = gamma * cs + beta * ss;
    tilt_rate = gr * cs + br * ss + (beta * cs - gamma * ss) * sig[1];
    cf_boom_luff_at(t, b, u + IN_luff_command, luff);
    psi = luff[0] - tilt;
    psi_rate = luff[1] - tilt_rate;
    cf_boom_telescope_at(t, b, u + IN_extension_command, &tele);
    cf_boom_mass_state_at(&tele, b, &ms);
    cp = cos(psi);
    sp = sin(psi);
    L = ms.length;
    Ld = ms.length_rate;
    r = L * cp;
    r_rate = Ld * cp - L * sp * psi_rate;
    f_r = fx * cs + fz * ss;
    f_n = fz * cs - fx * ss;
    cf_boom_base_reactions(&ms, psi, psi_rate, luff[2], f_r, fy, b->g, react);
    fbr = react[0];
    fby = react[1];
    m_plane = react[2];
    m_r = f_n * L * sp;
    cf_boom_cylinder_geometry(luff[0], b, &s3, &lever, &phi2);
    j = ms.J;
    s = ms.S;
    y[OUT_x_tip] = b->x_foot + r * cs;
    y[OUT_y_tip] = b->y_foot + yb + L * sp;
    y[OUT_z_tip] = r * ss;
    y[OUT_vx_tip] = r_rate * cs - r * ss * sig[1];
    y[OUT_vy_tip] = vyb + Ld * sp + L * cp * psi_rate;
    y[OUT_vz_tip] = r_rate * ss + r * cs * sig[1];
    y[OUT_Fx_base] = fbr * cs - f_n * ss;
    y[OUT_Fy_base] = fby;
    y[OUT_Fz_base] = fbr * ss + f_n * cs;
    y[OUT_Mx_base] = -m_plane * ss + m_r * cs;
    y[OUT_Mz_base] = m_plane * cs + m_r * ss;
    y[OUT_boom_length] = L;
    y[OUT_slew_angle_out] = sig[0];
    y[OUT_slew_rate] = sig[1];
    y[OUT_radius] = r;
    y[OUT_cylinder_force] = -m_plane / lever;
    y[OUT_extension] = L - b->boom_length_start;
    y[OUT_m_carried] = ms.mass;
    y[OUT_Sx_carried] = s * cp * cs;
    y[OUT_Sz_carried] = s * cp * ss;
    y[OUT_Jp_carried] = j * (sp * sp + cp * cp * cs * cs);
    y[OUT_Jr_carried] = j * (sp * sp + cp * cp * ss * ss);
    y[OUT_Jpr_carried] = j * cp * cp * cs * ss;
}

int cf_frozen(const CfModel *m)
{
    (void)m;
    return 0; /* Model.frozen's default (no states: the layer integrates nothing) */
}

CF_NO_EXACT_STEP

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    (void)m, (void)i;
    return "";
}
