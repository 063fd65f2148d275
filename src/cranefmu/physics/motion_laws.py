"""Prescribed motion laws shared by the subsystems (seed 000: trapezoidal velocity)."""
from __future__ import annotations


def trapezoid_motion(t: float, t_start: float, distance: float, speed: float,
                     t_acc: float) -> tuple[float, float, float]:
    """Position [m or rad], velocity and acceleration of the seed 000 trapezoid velocity law.

    Constant acceleration speed/t_acc over [0, T1], constant speed over [T1, T2], constant
    deceleration over [T2, T3 = T2 + T1] (times after t_start); T2 = |distance| / speed so that the
    travel is ``distance`` (the area of the trapezoid is speed * T2).  Needs T2 >= t_acc.
    """
    if distance == 0.0 or speed <= 0.0:
        return 0.0, 0.0, 0.0
    sign = 1.0 if distance > 0.0 else -1.0
    v, t1 = speed, t_acc
    t2 = abs(distance) / v
    tau = t - t_start
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if t1 == 0.0:  # rectangular velocity: infinite acceleration at both ends, reported as 0
        return (sign * v * tau, sign * v, 0.0) if tau < t2 else (distance, 0.0, 0.0)
    a = v / t1
    if tau < t1:
        s, sd, sdd = 0.5 * a * tau * tau, a * tau, a
    elif tau < t2:
        s, sd, sdd = v * (tau - 0.5 * t1), v, 0.0
    elif tau < t2 + t1:
        td = tau - t2
        s, sd, sdd = v * (t2 - 0.5 * t1) + v * td - 0.5 * a * td * td, v - a * td, -a
    else:
        return distance, 0.0, 0.0
    return sign * s, sign * sd, sign * sdd
