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

#endif
