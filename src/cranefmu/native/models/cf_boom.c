/* The telescopic boom of cranefmu.physics.boom (cf_boom.h), operation by operation as the Python
   functions of the same names (seed 000 Fig. 1, eq. 1, 11-18, Table 1). */
#include "cf_boom.h"

#include <math.h>

#include "cf_motion_laws.h"
#include "cf_pymath.h"
#include "cf_repr.h"

#define CF_PI 3.141592653589793 /* math.pi */

int cf_boom_check(CfModel *m, const CfBoom *b)
{
    char r[CF_REPR_SIZE];
    double dl, t2, phi[2];
    int i;

    dl = fabs(b->boom_length_end - b->boom_length_start);
    if (dl > 0.0) {
        t2 = dl / (b->telescope_speed * (1.0 + b->telescope_speed_ratio));
        if (b->t_acc > t2)
            return cf_fail(m, "boom.t_acc = %s is too long: the telescoping law reaches its steady speed only if "
                           "t_acc <= %.6g s (= |length change| / (V10 + V20)); lower t_acc or telescope_speed",
                           cf_repr(b->t_acc, r), t2);
    }
    if (b->luff_delta != 0.0 && b->luff_t_acc > fabs(b->luff_delta) / b->luff_rate)
        return cf_fail(m, "boom.luff_t_acc = %s is too long: allowed <= |luff_delta| / luff_rate = %.6g s",
                       cf_repr(b->luff_t_acc, r), fabs(b->luff_delta) / b->luff_rate);
    if (b->seg3_offset + b->l_seg3 > b->boom_length_start)
        return cf_fail(m, "boom.seg3_offset = %s is not allowed: the segment would reach beyond the retracted tip; "
                       "allowed <= boom_length_start - its length = %.6g m", cf_repr(b->seg3_offset, r),
                       b->boom_length_start - b->l_seg3);
    if (b->seg4_offset + b->l_seg4 > b->boom_length_start)
        return cf_fail(m, "boom.seg4_offset = %s is not allowed: the segment would reach beyond the retracted tip; "
                       "allowed <= boom_length_start - its length = %.6g m", cf_repr(b->seg4_offset, r),
                       b->boom_length_start - b->l_seg4);
    {
        const char *name[3] = {"travel", "steer", "aux"};
        const double delta[3] = {b->travel_distance, b->steer_delta, b->aux_delta};
        const double rate[3] = {b->travel_speed, b->steer_rate, b->aux_rate};
        const double t_acc[3] = {b->travel_t_acc, b->steer_t_acc, b->aux_t_acc};
        for (i = 0; i < 3; i++)
            if (delta[i] != 0.0 && t_acc[i] > fabs(delta[i]) / rate[i])
                return cf_fail(m, "boom.%s_t_acc = %s is too long: allowed <= |%s change| / steady rate = %.6g s",
                               name[i], cf_repr(t_acc[i], r), name[i], fabs(delta[i]) / rate[i]);
    }
    if (!b->tip_kinematic && (b->travel_distance != 0.0 || b->steer_delta != 0.0 || b->aux_length != 0.0))
        return cf_fail(m, "boom.travel_distance, steer_delta and aux_length move a kinematic tip: allowed 0 with "
                       "boom.tip = 'dynamic' (the chassis moves a dynamic boom's foot)");
    phi[0] = b->luff_angle;
    phi[1] = b->luff_angle + b->luff_delta;
    for (i = 0; i < 2; i++) {
        double rel = remainder(phi[i] - b->cyl_base_angle, 2.0 * CF_PI);
        if (!(0.0 < rel && rel < CF_PI))
            return cf_fail(m, "boom.cyl_base_angle = %s is not allowed with a luffing angle of %.6g rad: the "
                           "cylinder needs a positive lever arm, i.e. 0 < phi1 - cyl_base_angle < pi",
                           cf_repr(b->cyl_base_angle, r), phi[i]);
    }
    return 0;
}

/* --- motion laws ------------------------------------------------------------------------------ */
void cf_boom_telescope_law(double t, const CfBoom *b, CfTelescope *out)
{
    double dl = b->boom_length_end - b->boom_length_start;
    double v1 = b->telescope_speed;
    double v2 = b->telescope_speed * b->telescope_speed_ratio;
    double t2 = dl != 0.0 ? fabs(dl) / (v1 + v2) : 0.0;
    double sign = copysign(1.0, dl);
    double a[3], c[3];

    cf_trapezoid_motion(t, b->telescope_start, sign * v1 * t2, v1, b->t_acc, a);
    cf_trapezoid_motion(t, b->telescope_start, sign * v2 * t2, v2, b->t_acc, c);
    out->s[0] = a[0];
    out->s[1] = c[0];
    out->sd[0] = a[1];
    out->sd[1] = c[1];
    out->sdd[0] = a[2];
    out->sdd[1] = c[2];
}

void cf_boom_commanded_telescope(const double command[3], const CfBoom *b, CfTelescope *out)
{
    /* split as the law splits them: s1 = e / (1 + V20 / V10), s2 = e - s1 */
    double share = 1.0 / (1.0 + b->telescope_speed_ratio);
    double e = command[0], ed = command[1], edd = command[2];
    double s1 = e * share, sd1 = ed * share, sdd1 = edd * share;

    out->s[0] = s1;
    out->s[1] = e - s1;
    out->sd[0] = sd1;
    out->sd[1] = ed - sd1;
    out->sdd[0] = sdd1;
    out->sdd[1] = edd - sdd1;
}

void cf_boom_telescope_at(double t, const CfBoom *b, const double command[3], CfTelescope *out)
{
    if (b->telescope_input)
        cf_boom_commanded_telescope(command, b, out);
    else
        cf_boom_telescope_law(t, b, out);
}

void cf_boom_luff_at(double t, const CfBoom *b, const double command[3], double out[3])
{
    if (b->luff_input) {
        out[0] = b->luff_angle + command[0];
        out[1] = command[1];
        out[2] = command[2];
        return;
    }
    /* luff_law: the trapezoid of the telescoping law reused (seed 000: phi1 = 60 deg locked) */
    cf_trapezoid_motion(t, b->luff_start, b->luff_delta, b->luff_rate, b->luff_t_acc, out);
    out[0] = b->luff_angle + out[0];
}

/* --- geometry and mass -------------------------------------------------------------------------- */
void cf_boom_cylinder_geometry(double phi1, const CfBoom *b, double *s3, double *lever, double *phi2)
{
    /* eq. 1 in closed form: s3 e(phi2) = l_D e(phi1) - l6 e(alpha);
       s3^2 = l_D^2 + l6^2 - 2 l_D l6 cos(phi1 - alpha), s3 s3' = l_D l6 sin(phi1 - alpha) */
    double la = b->cyl_boom_arm, lb = b->cyl_base_distance, al = b->cyl_base_angle;
    double cx = la * cos(phi1) - lb * cos(al);
    double cy = la * sin(phi1) - lb * sin(al);

    *s3 = cf_py_hypot(cx, cy);
    *lever = la * lb * sin(phi1 - al) / *s3;
    *phi2 = atan2(cy, cx);
}

double cf_boom_constraint_residual(double phi1, double phi2, double s3, const CfBoom *b)
{
    double la = b->cyl_boom_arm, lb = b->cyl_base_distance, al = b->cyl_base_angle;
    double f1 = la * cos(phi1) - s3 * cos(phi2) - lb * cos(al);
    double f2 = la * sin(phi1) - s3 * sin(phi2) - lb * sin(al);

    return cf_py_hypot(f1, f2);
}

void cf_boom_mass_state_at(const CfTelescope *tele, const CfBoom *b, CfMassState *ms)
{
    /* per body: mass m, centre distance r from O2 (eq. 13), its rate rd and acceleration rdd, own
       inertia j about the centre; the sums in body order (segment 5, 4, 3, head) */
    double s1 = tele->s[0], s2 = tele->s[1], sd1 = tele->sd[0], sd2 = tele->sd[1];
    double sdd1 = tele->sdd[0], sdd2 = tele->sdd[1];
    double m5 = b->m_seg5, m4 = b->m_seg4, m3 = b->m_seg3, mh = b->m_head;
    double r5 = 0.5 * b->l_seg5, r4 = b->seg4_offset + s1 + 0.5 * b->l_seg4;
    double r3 = b->seg3_offset + s1 + s2 + 0.5 * b->l_seg3, rh = b->boom_length_start + s1 + s2;
    double rd4 = sd1, rd3 = sd1 + sd2; /* the head moves with segment 3; segment 5 does not move */
    double rdd4 = sdd1, rdd3 = sdd1 + sdd2;
    /* l ** 2 in Python is pow(l, 2.0), correctly rounded: l * l */
    double j5 = m5 * (b->l_seg5 * b->l_seg5) / 12.0, j4 = m4 * (b->l_seg4 * b->l_seg4) / 12.0;
    double j3 = m3 * (b->l_seg3 * b->l_seg3) / 12.0;

    ms->mass = m5 + m4 + m3 + mh;
    ms->S = m5 * r5 + m4 * r4 + m3 * r3 + mh * rh;
    ms->S_rate = m5 * 0.0 + m4 * rd4 + m3 * rd3 + mh * rd3;
    ms->S_acc = m5 * 0.0 + m4 * rdd4 + m3 * rdd3 + mh * rdd3;
    ms->J = (m5 * r5 * r5 + j5) + (m4 * r4 * r4 + j4) + (m3 * r3 * r3 + j3) + (mh * rh * rh + 0.0);
    ms->J_rate = 2.0 * m5 * r5 * 0.0 + 2.0 * m4 * r4 * rd4 + 2.0 * m3 * r3 * rd3 + 2.0 * mh * rh * rd3;
    ms->length = b->boom_length_start + s1 + s2;
    ms->length_rate = sd1 + sd2;
    ms->length_acc = sdd1 + sdd2;
}

void cf_boom_base_reactions(const CfMassState *ms, double psi, double psi_rate, double psi_acc, double fx,
                            double fy, double g, double out[3])
{
    /* Newton-Euler of the boom (derived): F = F_tip + m g - sum m_i a_i, M = r_B x F_tip + sum r_i x m_i g - dH/dt */
    double c = cos(psi), s = sin(psi);
    double ar = ms->S_acc - ms->S * psi_rate * psi_rate;       /* sum m a_i along e_r */
    double at = 2.0 * ms->S_rate * psi_rate + ms->S * psi_acc; /* sum m a_i along e_psi */

    out[0] = fx - (ar * c - at * s);
    out[1] = fy - ms->mass * g - (ar * s + at * c);
    out[2] = ms->length * (c * fy - s * fx) - g * ms->S * c - (ms->J * psi_acc + ms->J_rate * psi_rate);
}

void cf_boom_crane_motion_tip(double t, const CfBoom *b, double beta, double beta_rate, double length,
                              double length_rate, double tip[3], double vtip[3])
{
    /* seed 002's floor crane (derived): tip = (x_c + r cos psi, y, r sin psi) */
    double xc[3], steer[3], da[3];
    double ang, ang_rate, cb, sb, ca, sa, r, y, dr, dy, cp, sp;

    cf_trapezoid_motion(t, b->travel_start, b->travel_distance, b->travel_speed, b->travel_t_acc, xc);
    cf_trapezoid_motion(t, b->steer_start, b->steer_delta, b->steer_rate, b->steer_t_acc, steer);
    cf_trapezoid_motion(t, b->aux_start, b->aux_delta, b->aux_rate, b->aux_t_acc, da);
    ang = beta + b->aux_angle + da[0];
    ang_rate = beta_rate + da[1];
    cb = cos(beta);
    sb = sin(beta);
    ca = cos(ang);
    sa = sin(ang);
    r = b->x_foot + length * cb + b->aux_length * ca;
    y = b->y_foot + length * sb + b->aux_length * sa;
    dr = length_rate * cb - length * sb * beta_rate - b->aux_length * sa * ang_rate;
    dy = length_rate * sb + length * cb * beta_rate + b->aux_length * ca * ang_rate;
    cp = cos(steer[0]);
    sp = sin(steer[0]);
    tip[0] = xc[0] + r * cp;
    tip[1] = y;
    tip[2] = r * sp;
    vtip[0] = xc[1] + dr * cp - r * sp * steer[1];
    vtip[1] = dy;
    vtip[2] = dr * sp + r * cp * steer[1];
}
