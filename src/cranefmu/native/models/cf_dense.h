/* Small dense linear algebra for the models' mass matrices (no allocation). */
#ifndef CF_DENSE_H
#define CF_DENSE_H

#define CF_DENSE_MAX 8

/* inv = a^-1 for the n x n row-major a (n <= CF_DENSE_MAX), as numpy.linalg.inv computes it (LAPACK
   dgesv on the identity: LU with partial pivoting, the column below a pivot scaled by its reciprocal,
   then the two triangular solves with fused multiply-adds as OpenBLAS does them; bitwise equal to
   numpy on 2x2 matrices, within 1 ulp on 3x3).  Returns 0, or 1 when a is singular (a zero pivot). */
int cf_inverse(int n, const double *a, double *inv);

/* x = a^-1 b for the n x n row-major a, as numpy.linalg.solve (the same factorisation and solves as
   cf_inverse).  Returns 0, or 1 when a is singular. */
int cf_solve(int n, const double *a, const double *b, double *x);

/* 3x3 on plain doubles in the fixed order of cranefmu.physics.small_linalg (issue 33: the Python model does
   the same operations in the same order, so the same bits; this file is compiled without FP contraction).
   Row-major a[3 i + j].  cofactors c_ij = a[r1 s1] a[r2 s2] - a[r1 s2] a[r2 s1], signed by swapping the
   difference; det = a0 c00 + a1 c01 + a2 c02; inv[3 i + j] = c_ji / det; matvec y_i = a[3i] v0 + a[3i+1] v1
   + a[3i+2] v2, left to right.  cf_inverse3 and cf_solve3 return 0, or 1 when det == 0. */
int cf_inverse3(const double *a, double *inv);
void cf_matvec3(const double *a, const double *v, double *y);
int cf_solve3(const double *a, const double *v, double *x);
/* x with a x = v on the directions where mask is not 0, 0 on the others (small_linalg.solve_free3: 3 free
   cf_solve3; 2 free i < j: det = a_ii a_jj - a_ij a_ji, inverse [a_jj, -a_ij; -a_ji, a_ii] / det, then
   x_i = inv00 v_i + inv01 v_j, x_j = inv10 v_i + inv11 v_j; 1 free: v_i / a_ii).  Returns 0, or 1 if singular. */
int cf_solve_free3(const double *mask, const double *a, const double *v, double *x);

#endif
