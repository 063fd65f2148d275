/* Hoist drive: asynchronous motor, torsional drivetrain and rope drum (seed 001 eq. 4-5, Tables 4-5),
   or a kinematic trapezoidal payout law (seed 000, the telescoping/payout velocity trapezoid):
   C twin of cranefmu.physics.drive, operation by operation.

   Sign conventions: every rotation angle and speed is positive in the hoisting sense (the drum winds
   rope in).  payout is the rope released by the drum since the start, summed over the n_drum_lines
   rope ends wound on it, positive when lowering:
       payout = -n_drum_lines R_3 phi_drum,   payout_rate = -n_drum_lines R_3 w_drum
   The drum feels the line force drum_force of every rope end: M_L = n_drum_lines drum_force R_3.

   Motor (mode "motor"), seed 001 eq. 4, the 3-state dynamic Kloss model (middle line re-derived so that
   its steady state is the static Kloss curve):
       dM_e/dt   = w_s Theta - M_e / T_e
       dTheta/dt = -w_s M_e + (2 M_k - Theta) / T_e       (the 2 M_k / T_e term only while powered)
       J_w dw_motor/dt = M_e + tau_1                     (eq. 4, line 3, with M_0 from eq. 5)
   with w_s = Omega_s(t) - p w_motor and T_e = 1 / (s_k Omega_s) (derived).

   Drivetrain, seed 001 eq. 5 (Lagrange equations; derived): motor (J_w), clutch (J_sp), gear input node
   (J_p1 + J_p2 / i_p^2) and drum (J_3) joined by torsional spring-dampers:
       tau_1 = c_1n (phi_2 - phi_1) + b_1n (w_2 - w_1)
       tau_2 = c_2n (phi_4 - phi_2) + b_2n (w_4 - w_2)
       tau_3 = c_3n (phi_3 - phi_4 / i_p) + b_3n (w_3 - w_4 / i_p)
       J_w w_1' = M_e + tau_1,  J_sp w_2' = tau_2 - tau_1,  J_g w_4' = tau_3 / i_p - tau_2,
       J_3 w_3' = -tau_3 - M_L
   Start: before start_time the supply is off; the brake holds the motor shaft until
   start_time + brake_delay; the springs are pre-twisted so that the drum holds M_L with phi_drum = 0.

   Kinematic mode: the payout follows the seed 000 trapezoid; the state is frozen and the outputs are
   closed-form functions of time (motor_torque: the torque a rigid drivetrain needs). */
#include <math.h>

#include "cf_model.h"
#include "cf_motion_laws.h"
#include "cf_repr.h"
#include "Drive_tables.h"

const int cf_has_exact_step = 0;

#define CF_PI 3.141592653589793   /* math.pi */

/* state layout (drive._STATES) */
enum { X_ME, X_TH, X_PHI_MOTOR, X_PHI_CLUTCH, X_PHI_GEAR, X_PHI_DRUM, X_W_MOTOR, X_W_CLUTCH, X_W_GEAR,
       X_W_DRUM, N_STATES };

/* DriveModel._constants: the parameters of eq. 4-5 as derivatives_list unpacks them */
typedef struct DriveData {
    double inv_t, forcing, poles, c1, b1, c2, b2, c3, b3, inv_i, inv_jw, inv_jsp, inv_jg, inv_j3, arm, start,
        release;
} DriveData;

typedef char drive_data_fits[sizeof(DriveData) <= sizeof(double) * CF_MODEL_DATA ? 1 : -1];

#define CDATA(m) ((const DriveData *)(m)->data)
#define KINEMATIC(p) ((int)(p)[P_mode] == SW_mode_kinematic)

/* Python's min(a, b) and max(a, b) on floats: the first argument unless the second compares smaller
   (larger) */
static double py_min(double a, double b) { return b < a ? b : a; }

/* Mechanical synchronous speed Omega_s / p [rad/s] at nominal supply frequency (Table 4: 104.72). */
static double synchronous_speed(const double *p) { return p[P_Omega_s] / p[P_pole_pairs]; }

/* Nominal rotor speed [rad/s] (Table 4: 98.96). */
static double nominal_speed(const double *p) { return p[P_n_n] * 2.0 * CF_PI / 60.0; }

/* Nominal slip 1 - w_n / w_sync [1] (derived; Table 4: 0.055). */
static double nominal_slip(const double *p) { return 1.0 - nominal_speed(p) / synchronous_speed(p); }

/* Nominal torque P_n / w_n [N m] (derived; Table 4: 101.05). */
static double nominal_torque(const double *p) { return p[P_P_n] / nominal_speed(p); }

/* Electromagnetic time constant T_e = 1 / (s_k Omega_s) [s] (derived from eq. 4 at steady state). */
static double time_constant(const double *p) { return 1.0 / (p[P_s_k] * p[P_Omega_s]); }

/* Inertia of the gear node reduced to the input shaft, J_p1 + J_p2 / i_p^2 [kg m^2] (eq. 5). */
static double gear_inertia(const double *p) { return p[P_J_p1] + p[P_J_p2] / pow(p[P_i_p], 2.0); }

/* Commanded supply angular frequency [rad/s]: 0 before start, then a linear ramp to Omega_s. */
static double supply_frequency(double t, const double *p)
{
    double frac;
    if (t < p[P_start_time])
        return 0.0;
    frac = p[P_ramp_time] == 0.0 ? 1.0 : py_min(1.0, (t - p[P_start_time]) / p[P_ramp_time]);
    return p[P_Omega_s] * (p[P_start_fraction] + (1.0 - p[P_start_fraction]) * frac);
}

/* Drum load torque M_L = n_drum_lines * drum_force * R_3 [N m], lowering sense. */
static double load_torque(const double *p, const double *u)
{
    return p[P_n_drum_lines] * u[IN_drum_force] * p[P_R_3];
}

int cf_check_params(CfModel *m)
{
    const double *p = m->p;
    char a[CF_REPR_SIZE], b[CF_REPR_SIZE];
    if (p[P_duration] < 2.0 * p[P_t_acc])
        return cf_fail(m, "drive.duration = %s is too short: allowed >= 2 * drive.t_acc = %s s (accelerate and "
                       "decelerate)", cf_repr(p[P_duration], a), cf_repr(2.0 * p[P_t_acc], b));
    if (p[P_M_k] <= nominal_torque(p))
        return cf_fail(m, "drive.M_k = %s is not allowed: the breakdown torque must exceed the nominal torque "
                       "P_n / w_n = %.6g N.m", cf_repr(p[P_M_k], a), nominal_torque(p));
    if (p[P_s_k] <= nominal_slip(p))
        return cf_fail(m, "drive.s_k = %s is not allowed: the critical slip must exceed the nominal slip "
                       "1 - n_n / n_sync = %.6g", cf_repr(p[P_s_k], a), nominal_slip(p));
    return 0;
}

int cf_prepare(CfModel *m)
{
    const double *p = m->p;
    DriveData *d = (DriveData *)m->data;
    d->inv_t = 1.0 / time_constant(p);
    d->forcing = 2.0 * p[P_M_k] * d->inv_t;
    d->poles = p[P_pole_pairs];
    d->c1 = p[P_c_1n];
    d->b1 = p[P_b_1n];
    d->c2 = p[P_c_2n];
    d->b2 = p[P_b_2n];
    d->c3 = p[P_c_3n];
    d->b3 = p[P_b_3n];
    d->inv_i = 1.0 / p[P_i_p];
    d->inv_jw = 1.0 / p[P_J_w];
    d->inv_jsp = 1.0 / p[P_J_sp];
    d->inv_jg = 1.0 / gear_inertia(p);
    d->inv_j3 = 1.0 / p[P_J_3];
    d->arm = p[P_n_drum_lines] * p[P_R_3];
    d->start = p[P_start_time];
    d->release = p[P_start_time] + p[P_brake_delay];
    m->n_states = N_STATES;
    return 0;
}

int cf_initial_state(CfModel *m, const double *u, double *x)
{
    const double *p = m->p;
    int i;
    for (i = 0; i < N_STATES; i++)
        x[i] = 0.0;
    if (!KINEMATIC(p)) {
        /* pretwisted_angles: static eq. 5, tau_3 = -M_L, tau_2 = tau_1 = tau_3 / i_p; the braked motor
           shaft takes the rest (derived) */
        double lt = load_torque(p, u);
        double phi3 = 0.0;
        double phi4 = p[P_i_p] * (phi3 + lt / p[P_c_3n]);
        double phi2 = phi4 + lt / (p[P_i_p] * p[P_c_2n]);
        double phi1 = phi2 + lt / (p[P_i_p] * p[P_c_1n]);
        x[X_PHI_MOTOR] = phi1;
        x[X_PHI_CLUTCH] = phi2;
        x[X_PHI_GEAR] = phi4;
        x[X_PHI_DRUM] = phi3;
    }
    return 0;
}

void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx)
{
    /* DriveModel.derivatives_list: eq. 4 (motor_rhs) and eq. 5 (drivetrain_accelerations) on plain floats */
    const DriveData *d = CDATA(m);
    double slip_freq, tau1, tau2, tau3, d_motor, a_motor;
    int i;
    if (KINEMATIC(m->p)) {
        for (i = 0; i < N_STATES; i++)
            dx[i] = 0.0;
        return;
    }
    slip_freq = supply_frequency(t, m->p) - d->poles * x[X_W_MOTOR];
    dx[X_ME] = slip_freq * x[X_TH] - x[X_ME] * d->inv_t;
    dx[X_TH] = -slip_freq * x[X_ME] + (t >= d->start ? d->forcing : 0.0) - x[X_TH] * d->inv_t;
    tau1 = d->c1 * (x[X_PHI_CLUTCH] - x[X_PHI_MOTOR]) + d->b1 * (x[X_W_CLUTCH] - x[X_W_MOTOR]);
    tau2 = d->c2 * (x[X_PHI_GEAR] - x[X_PHI_CLUTCH]) + d->b2 * (x[X_W_GEAR] - x[X_W_CLUTCH]);
    tau3 = d->c3 * (x[X_PHI_DRUM] - x[X_PHI_GEAR] * d->inv_i) + d->b3 * (x[X_W_DRUM] - x[X_W_GEAR] * d->inv_i);
    if (t < d->release) {   /* brake holds the motor shaft: its reaction takes whatever reaches the rotor */
        d_motor = a_motor = 0.0;
    } else {
        d_motor = x[X_W_MOTOR];
        a_motor = (x[X_ME] + tau1) * d->inv_jw;
    }
    dx[X_PHI_MOTOR] = d_motor;
    dx[X_PHI_CLUTCH] = x[X_W_CLUTCH];
    dx[X_PHI_GEAR] = x[X_W_GEAR];
    dx[X_PHI_DRUM] = x[X_W_DRUM];
    dx[X_W_MOTOR] = a_motor;
    dx[X_W_CLUTCH] = (tau2 - tau1) * d->inv_jsp;
    dx[X_W_GEAR] = (tau3 * d->inv_i - tau2) * d->inv_jg;
    dx[X_W_DRUM] = (-tau3 - d->arm * u[IN_drum_force]) * d->inv_j3;
}

void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y)
{
    const double *p = m->p;
    double k = p[P_n_drum_lines] * p[P_R_3];
    if (KINEMATIC(p)) {
        /* trapezoid: the seed 000 law, payout_speed reached after t_acc, held, back to 0 at duration */
        double law[3], s, v, a, w3, alpha3, j_fast, torque;
        cf_trapezoid_motion(t, p[P_start_time], p[P_payout_speed] * (p[P_duration] - p[P_t_acc]),
                            p[P_payout_speed], p[P_t_acc], law);
        s = law[0];
        v = law[1];
        a = law[2];
        w3 = -v / k;
        alpha3 = -a / k;
        /* rigid drivetrain: inertia on the motor side turns at i_p * w3 */
        j_fast = p[P_J_w] + p[P_J_sp] + gear_inertia(p);
        torque = j_fast * p[P_i_p] * alpha3 + (p[P_J_3] * alpha3 + load_torque(p, u)) / p[P_i_p];
        y[OUT_payout] = s;
        y[OUT_payout_rate] = v;
        y[OUT_motor_torque] = torque;
        y[OUT_motor_speed] = p[P_i_p] * w3;
        y[OUT_drum_angle] = -s / k;
        y[OUT_drum_speed] = w3;
        y[OUT_slip] = 0.0;
        return;
    }
    {
        double omega_s = supply_frequency(t, p);
        double w1 = x[X_W_MOTOR];
        double slip = omega_s > 0.0 ? 1.0 - p[P_pole_pairs] * w1 / omega_s : 0.0;
        y[OUT_payout] = -k * x[X_PHI_DRUM];
        y[OUT_payout_rate] = -k * x[X_W_DRUM];
        y[OUT_motor_torque] = x[X_ME];
        y[OUT_motor_speed] = w1;
        y[OUT_drum_angle] = x[X_PHI_DRUM];
        y[OUT_drum_speed] = x[X_W_DRUM];
        y[OUT_slip] = slip;
    }
}

int cf_frozen(const CfModel *m)
{
    return KINEMATIC(m->p);
}

CF_NO_EXACT_STEP

CF_NOTHING_AFTER_STEP

const char *cf_state_name(const CfModel *m, int i)
{
    static const char *names[N_STATES] = {"M_e", "Theta", "phi_motor", "phi_clutch", "phi_gear", "phi_drum",
                                          "w_motor", "w_clutch", "w_gear", "w_drum"};
    (void)m;
    return i >= 0 && i < N_STATES ? names[i] : "?";
}
