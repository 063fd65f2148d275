/* Prescribed motion laws (cf_motion_laws.h), operation by operation as cranefmu.physics.motion_laws. */
#include "cf_motion_laws.h"

#include <math.h>

void cf_trapezoid_motion(double t, double t_start, double distance, double speed, double t_acc, double out[3])
{
    double sign, v, t1, t2, tau, a, s, sd, sdd, td;

    out[0] = out[1] = out[2] = 0.0;
    if (distance == 0.0 || speed <= 0.0)
        return;
    sign = distance > 0.0 ? 1.0 : -1.0;
    v = speed;
    t1 = t_acc;
    t2 = fabs(distance) / v;
    tau = t - t_start;
    if (tau <= 0.0)
        return;
    if (t1 == 0.0) { /* rectangular velocity: infinite acceleration at both ends, reported as 0 */
        if (tau < t2) {
            out[0] = sign * v * tau;
            out[1] = sign * v;
        } else {
            out[0] = distance;
        }
        return;
    }
    a = v / t1;
    if (tau < t1) {
        s = 0.5 * a * tau * tau;
        sd = a * tau;
        sdd = a;
    } else if (tau < t2) {
        s = v * (tau - 0.5 * t1);
        sd = v;
        sdd = 0.0;
    } else if (tau < t2 + t1) {
        td = tau - t2;
        s = v * (t2 - 0.5 * t1) + v * td - 0.5 * a * td * td;
        sd = v - a * td;
        sdd = -a;
    } else {
        out[0] = distance;
        return;
    }
    out[0] = sign * s;
    out[1] = sign * sd;
    out[2] = sign * sdd;
}
