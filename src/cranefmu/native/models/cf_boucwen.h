/* Modified Bouc-Wen hysteresis model of a steel wire rope (seed 001 eq. 1-3, Table 3): the C twin of
   cranefmu.physics.boucwen, operation by operation (same formulas, order and constants).

   Seed 001 eq. 2 (with eq. 1), as reconstructed in boucwen.py's module docstring:
       F   = F_2 (z + F_1)                                   total rope force              [N]
       F_1 = k1 x + k2 sign(x) x^2 + k3 x^3                  nonlinear elastic part        [N]
       F_2 = b^(c x)                                         loop shape modifier           [1]
       z'  = x' {alpha - [gamma + beta sign(x') sign(z)] |z|^n}                            [N/s]
   Tension only (our choice, boucwen.py): z rides the zero-force line z = -F_1(x) when an unloading rope
   reaches F = 0 while x > 0, and is frozen (z' = 0) while x < 0. */
#ifndef CF_BOUCWEN_H
#define CF_BOUCWEN_H

/* The nine parameters Y = {k1, k2, k3, b, c, alpha, beta, gamma, n} of seed 001 eq. 3 (BoucWenParams). */
typedef struct CfBoucWen {
    double k1, k2, k3, b, c, alpha, beta, gamma, n;
} CfBoucWen;

/* Ultimate hysteretic force z_u = (alpha / (beta + gamma))^(1/n) [N] (derived from eq. 1). */
double cf_bw_z_bound(const CfBoucWen *p);
/* dz/dt [N/s] of the Bouc-Wen state (seed 001 eq. 1); |z|^n through exp/log, exponent capped at 700. */
double cf_bw_z_rate(double x_dot, double z, const CfBoucWen *p);
/* F_1 = k1 x + k2 sign(x) x^2 + k3 x^3 [N] (seed 001 eq. 2). */
double cf_bw_elastic_force(double x, const CfBoucWen *p);
/* dF_1/dx [N/m] (derived). */
double cf_bw_elastic_slope(double x, const CfBoucWen *p);
/* F_2 = b^(c x) [1] (seed 001 eq. 2), exponent capped at 700. */
double cf_bw_shape_factor(double x, const CfBoucWen *p);
/* Total force F = F_2 (z + F_1) [N] (seed 001 eq. 2), signed. */
double cf_bw_force(double x, double z, const CfBoucWen *p);
/* Rope force [N]: max(0, F) while taut (x > 0), 0 when slack. */
double cf_bw_tension(double x, double z, const CfBoucWen *p);
/* dz/dt [N/s] of a tension-only rope (eq. 1 plus the slack rule). */
double cf_bw_rope_z_rate(double x, double x_dot, double z, const CfBoucWen *p);
/* z [N] moved into its admissible set: |z| <= z_u, z >= -F_1(x) when taut, 0 when slack. */
double cf_bw_project_state(double x, double z, const CfBoucWen *p);
/* dF/dx at (x, z) = (0, 0) [N/m]: alpha + k1 (derived from eq. 1-2, F_2(0) = 1). */
double cf_bw_small_amplitude_stiffness(const CfBoucWen *p);
/* Parameters of n_lines parallel lines of length `length` [m] from a set of one line of length_ref [m]
   (same strain, forces add; derived): k1 ~ m r, k2 ~ m r^2, k3 ~ m r^3, c ~ r, alpha ~ m r,
   beta, gamma ~ m^(1-n) r, with m = n_lines, r = length_ref / length.  The caller ensures length > 0. */
void cf_bw_for_length(const CfBoucWen *p, double length, double n_lines, double length_ref, CfBoucWen *out);
/* State z [N] of a rope loaded monotonically from slack (0, 0) to elongation x [m] (virgin curve):
   classical Runge-Kutta in x with step <= 0.05 z_u / (n alpha), projected after each step
   (boucwen.simulate_path with rope=True over [0, x]). */
double cf_bw_virgin_z(double x, const CfBoucWen *p);
/* Elongation [m] on the virgin curve where the tension is `load` [N] (bisection to rtol): returns 0 with
   *x written, or 1 when the curve does not reach the load below 1e6 m (boucwen.virgin_elongation). */
int cf_bw_virgin_elongation(double load, const CfBoucWen *p, double rtol, double *x);

#endif
