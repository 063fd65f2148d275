/* The telescopic boom with luffing cylinder of cranefmu.physics.boom (seed 000 eq. 1, 11-18), shared by
   the Boom and SlewingBoom models: its parameters, motion laws, cylinder geometry, mass properties
   and base reactions, each operation by operation as the Python functions of the same names. */
#ifndef CF_BOOM_H
#define CF_BOOM_H

#include "cf_model.h"

/* The boom's parameters (BoomParams) as plain doubles, kept at the start of CfModel.data; a switch is
   1.0 for the choice named by the field, else 0.0. */
typedef struct CfBoom {
    double tip_kinematic, cylinder_spring_damper, telescope_input, luff_input;
    double luff_angle, luff_delta, luff_rate, luff_t_acc, luff_start;
    double boom_length_start, boom_length_end, telescope_speed, telescope_speed_ratio, t_acc, telescope_start;
    double m_head, m_seg3, m_seg4, m_seg5, l_seg3, l_seg4, l_seg5, seg3_offset, seg4_offset;
    double cyl_boom_arm, cyl_base_distance, cyl_base_angle, cylinder_stiffness, cylinder_damping;
    double travel_distance, travel_speed, travel_t_acc, travel_start;
    double steer_delta, steer_rate, steer_t_acc, steer_start;
    double aux_length, aux_angle, aux_delta, aux_rate, aux_t_acc, aux_start;
    double x_foot, y_foot, g;
} CfBoom;

/* CfBoom from a model's parameter vector p, expanded where the model's <Name>_tables.h defines P_... */
#define CF_BOOM_FROM_PARAMS(b, p) do { \
    (b)->tip_kinematic = (p)[P_tip] == SW_tip_kinematic; \
    (b)->cylinder_spring_damper = (p)[P_cylinder] == SW_cylinder_spring_damper; \
    (b)->telescope_input = (p)[P_telescope_source] == SW_telescope_source_input; \
    (b)->luff_input = (p)[P_luff_source] == SW_luff_source_input; \
    (b)->luff_angle = (p)[P_luff_angle]; (b)->luff_delta = (p)[P_luff_delta]; \
    (b)->luff_rate = (p)[P_luff_rate]; (b)->luff_t_acc = (p)[P_luff_t_acc]; (b)->luff_start = (p)[P_luff_start]; \
    (b)->boom_length_start = (p)[P_boom_length_start]; (b)->boom_length_end = (p)[P_boom_length_end]; \
    (b)->telescope_speed = (p)[P_telescope_speed]; (b)->telescope_speed_ratio = (p)[P_telescope_speed_ratio]; \
    (b)->t_acc = (p)[P_t_acc]; (b)->telescope_start = (p)[P_telescope_start]; \
    (b)->m_head = (p)[P_m_head]; (b)->m_seg3 = (p)[P_m_seg3]; (b)->m_seg4 = (p)[P_m_seg4]; \
    (b)->m_seg5 = (p)[P_m_seg5]; (b)->l_seg3 = (p)[P_l_seg3]; (b)->l_seg4 = (p)[P_l_seg4]; \
    (b)->l_seg5 = (p)[P_l_seg5]; (b)->seg3_offset = (p)[P_seg3_offset]; (b)->seg4_offset = (p)[P_seg4_offset]; \
    (b)->cyl_boom_arm = (p)[P_cyl_boom_arm]; (b)->cyl_base_distance = (p)[P_cyl_base_distance]; \
    (b)->cyl_base_angle = (p)[P_cyl_base_angle]; (b)->cylinder_stiffness = (p)[P_cylinder_stiffness]; \
    (b)->cylinder_damping = (p)[P_cylinder_damping]; \
    (b)->travel_distance = (p)[P_travel_distance]; (b)->travel_speed = (p)[P_travel_speed]; \
    (b)->travel_t_acc = (p)[P_travel_t_acc]; (b)->travel_start = (p)[P_travel_start]; \
    (b)->steer_delta = (p)[P_steer_delta]; (b)->steer_rate = (p)[P_steer_rate]; \
    (b)->steer_t_acc = (p)[P_steer_t_acc]; (b)->steer_start = (p)[P_steer_start]; \
    (b)->aux_length = (p)[P_aux_length]; (b)->aux_angle = (p)[P_aux_angle]; (b)->aux_delta = (p)[P_aux_delta]; \
    (b)->aux_rate = (p)[P_aux_rate]; (b)->aux_t_acc = (p)[P_aux_t_acc]; (b)->aux_start = (p)[P_aux_start]; \
    (b)->x_foot = (p)[P_x_foot]; (b)->y_foot = (p)[P_y_foot]; (b)->g = (p)[P_g]; \
} while (0)

/* Extensions (s1, s2) [m], their rates and accelerations (boom._telescope_floats and friends). */
typedef struct CfTelescope {
    double s[2], sd[2], sdd[2];
} CfTelescope;

/* Mass properties of the boom at one instant (boom.MassState, eq. 13-18). */
typedef struct CfMassState {
    double length, length_rate, length_acc; /* L, foot - tip [m] */
    double mass;                            /* sum of masses [kg] */
    double S, S_rate, S_acc;                /* first moment sum m_i r_i about O2 [kg m] */
    double J, J_rate;                       /* moment of inertia about O2 [kg m2] */
} CfMassState;

/* BoomParams.check in the same words; the Python check's order. */
int cf_boom_check(CfModel *m, const CfBoom *b);
/* The telescoping law (seed 000): both segments share T1 = t_acc, T2 = |L_end - L_start| / (V10 + V20). */
void cf_boom_telescope_law(double t, const CfBoom *b, CfTelescope *out);
/* The telescoping from a commanded e = s1 + s2 with its rate and acceleration (command[0..2]). */
void cf_boom_commanded_telescope(const double command[3], const CfBoom *b, CfTelescope *out);
/* The law or the command, as telescope_source names. */
void cf_boom_telescope_at(double t, const CfBoom *b, const double command[3], CfTelescope *out);
/* Commanded luffing angle phi1 [rad], rate, acceleration from the law or luff_angle + command. */
void cf_boom_luff_at(double t, const CfBoom *b, const double command[3], double out[3]);
/* Cylinder length s3 [m], lever ds3/dphi1 [m], direction phi2 [rad] at phi1 (closed form of eq. 1). */
void cf_boom_cylinder_geometry(double phi1, const CfBoom *b, double *s3, double *lever, double *phi2);
/* |f| of eq. 1 [m]. */
double cf_boom_constraint_residual(double phi1, double phi2, double s3, const CfBoom *b);
/* Mass properties for the extensions, rates and accelerations of one instant. */
void cf_boom_mass_state_at(const CfTelescope *tele, const CfBoom *b, CfMassState *ms);
/* Force (Fx, Fy) [N] and moment M [N m] about O2 the boom exerts on the chassis. */
void cf_boom_base_reactions(const CfMassState *ms, double psi, double psi_rate, double psi_acc, double fx,
                            double fy, double g, double out[3]);
/* ((x, y), z) and ((vx, vy), vz) of a kinematic tip carried by seed 002's crane motions:
   tip[0..2] = x, y, z; vtip[0..2] = vx, vy, vz. */
void cf_boom_crane_motion_tip(double t, const CfBoom *b, double beta, double beta_rate, double length,
                              double length_rate, double tip[3], double vtip[3]);

#endif
