/* Modified Bouc-Wen rope (cf_boucwen.h): cranefmu.physics.boucwen in C, operation by operation. */
#include "cf_boucwen.h"

#include <math.h>

/* exponent cap for F_2 = b^(c x) and |z|^n: exp(700) is near the float limit; a rope never gets there */
#define MAX_EXP 700.0

/* Python's min(a, b) / max(a, b) on floats: the first argument unless the second compares smaller / larger */
static double py_min(double a, double b) { return b < a ? b : a; }
static double py_max(double a, double b) { return b > a ? b : a; }

double cf_bw_z_bound(const CfBoucWen *p)
{
    return pow(p->alpha / (p->beta + p->gamma), 1.0 / p->n);
}

double cf_bw_z_rate(double x_dot, double z, const CfBoucWen *p)
{
    double az = fabs(z), s, zn;
    if (az == 0.0)
        return x_dot * p->alpha;
    s = x_dot != 0.0 ? copysign(1.0, x_dot) * copysign(1.0, z) : 0.0;
    /* |z|^n through exp/log with a cap: a solver's trial step far outside |z| <= z_u must give a large
       finite rate (the step is rejected), not an overflow */
    zn = exp(py_min(p->n * log(az), MAX_EXP));
    return x_dot * (p->alpha - (p->gamma + p->beta * s) * zn);
}

double cf_bw_elastic_force(double x, const CfBoucWen *p)
{
    return x * (p->k1 + p->k2 * fabs(x) + p->k3 * x * x);
}

double cf_bw_elastic_slope(double x, const CfBoucWen *p)
{
    return p->k1 + 2.0 * p->k2 * fabs(x) + 3.0 * p->k3 * x * x;
}

double cf_bw_shape_factor(double x, const CfBoucWen *p)
{
    double e = p->c * log(p->b) * x;
    return exp(py_min(e, MAX_EXP));
}

double cf_bw_force(double x, double z, const CfBoucWen *p)
{
    return cf_bw_shape_factor(x, p) * (z + cf_bw_elastic_force(x, p));
}

double cf_bw_tension(double x, double z, const CfBoucWen *p)
{
    if (x <= 0.0)
        return 0.0;
    return py_max(0.0, cf_bw_force(x, z, p));
}

double cf_bw_rope_z_rate(double x, double x_dot, double z, const CfBoucWen *p)
{
    double rate;
    if (x < 0.0)
        return 0.0;   /* slack: z is frozen (it reached 0 on the zero-force line as x -> 0+) */
    rate = cf_bw_z_rate(x_dot, z, p);
    if (z + cf_bw_elastic_force(x, p) <= 0.0)   /* on the zero-force line (F_2 > 0 so this is F <= 0): */
        rate = py_max(rate, -cf_bw_elastic_slope(x, p) * x_dot);   /* follow it, no compression */
    return rate;
}

double cf_bw_project_state(double x, double z, const CfBoucWen *p)
{
    double zu;
    if (x <= 0.0)
        return 0.0;
    zu = cf_bw_z_bound(p);
    return py_min(py_max(py_max(z, -zu), -cf_bw_elastic_force(x, p)), zu);
}

double cf_bw_small_amplitude_stiffness(const CfBoucWen *p)
{
    return p->alpha + p->k1;
}

void cf_bw_for_length(const CfBoucWen *p, double length, double n_lines, double length_ref, CfBoucWen *out)
{
    double r = length_ref / length, m = n_lines;
    CfBoucWen s;
    s.k1 = m * p->k1 * r;
    s.k2 = m * p->k2 * r * r;
    s.k3 = m * p->k3 * pow(r, 3.0);
    s.b = p->b;
    s.c = p->c * r;
    s.alpha = m * p->alpha * r;
    s.beta = pow(m, 1.0 - p->n) * p->beta * r;
    s.gamma = pow(m, 1.0 - p->n) * p->gamma * r;
    s.n = p->n;
    *out = s;
}

/* boucwen._substeps: the decay rate of eq. 1 near saturation is about n alpha / z_u per metre of travel */
static double substeps(double dx, const CfBoucWen *p, double zu)
{
    double k = ceil(fabs(dx) * p->n * p->alpha / zu / 0.05);
    return k > 1.0 ? k : 1.0;
}

double cf_bw_virgin_z(double x, const CfBoucWen *p)
{
    /* simulate_path(np.array([0.0, x]), p) with rope=True; eq. 1 is rate independent, so z depends only on
       the path: integrated in x with x' = sign(dx) as a unit speed (dz/dx = rate / sign) */
    double xa = 0.0, xb = x, dx, zu, k, h, s, x0, k1, k2, k3, k4, z = 0.0, j;
    if (x <= 0.0)
        return 0.0;
    zu = cf_bw_z_bound(p);
    dx = xb - xa;
    if (dx != 0.0) {
        k = substeps(dx, p, zu);
        h = dx / k;
        s = copysign(1.0, dx);
        for (j = 0.0; j < k; j += 1.0) {
            x0 = xa + j * h;
            k1 = cf_bw_rope_z_rate(x0, s, z, p) * s;
            k2 = cf_bw_rope_z_rate(x0 + 0.5 * h, s, z + 0.5 * h * k1, p) * s;
            k3 = cf_bw_rope_z_rate(x0 + 0.5 * h, s, z + 0.5 * h * k2, p) * s;
            k4 = cf_bw_rope_z_rate(x0 + h, s, z + h * k3, p) * s;
            z += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
            /* the zero-force line is a sliding mode that RK4 would cut across: project onto it */
            z = cf_bw_project_state(x0 + h, z, p);
        }
    }
    return z;
}

int cf_bw_virgin_elongation(double load, const CfBoucWen *p, double rtol, double *x)
{
    double hi, lo, mid;
    if (load <= 0.0) {
        *x = 0.0;
        return 0;
    }
    hi = load / cf_bw_small_amplitude_stiffness(p);
    while (cf_bw_tension(hi, cf_bw_virgin_z(hi, p), p) < load) {
        hi *= 2.0;
        if (hi > 1e6)
            return 1;
    }
    lo = 0.0;
    while (hi - lo > rtol * hi) {
        mid = 0.5 * (lo + hi);
        if (cf_bw_tension(mid, cf_bw_virgin_z(mid, p), p) < load)
            lo = mid;
        else
            hi = mid;
    }
    *x = 0.5 * (lo + hi);
    return 0;
}
