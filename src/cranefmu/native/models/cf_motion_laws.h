/* Prescribed motion laws shared by the models: cranefmu.physics.motion_laws in C.
   (Helper P1, Drive: written by P3 for Boom and SlewingBoom; use it, do not write a second one.) */
#ifndef CF_MOTION_LAWS_H
#define CF_MOTION_LAWS_H

/* Position [m or rad], velocity and acceleration (out[0..2]) of the seed 000 trapezoid velocity law
   (motion_laws.trapezoid_motion): constant acceleration speed/t_acc over [0, T1 = t_acc], constant
   speed over [T1, T2], constant deceleration over [T2, T2 + T1] (times after t_start), with
   T2 = |distance| / speed so that the travel is `distance`.  Needs T2 >= t_acc. */
void cf_trapezoid_motion(double t, double t_start, double distance, double speed, double t_acc, double out[3]);

#endif
