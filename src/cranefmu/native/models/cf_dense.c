/* Small dense linear algebra (cf_dense.h). */
#include "cf_dense.h"

#include <math.h>
#include <string.h>

int cf_inverse(int n, const double *a, double *inv)
{
    double lu[CF_DENSE_MAX * CF_DENSE_MAX];
    int piv[CF_DENSE_MAX], i, j, k;
    memcpy(lu, a, sizeof(double) * n * n);
    /* LU with partial pivoting (dgetrf) */
    for (k = 0; k < n; k++) {
        int p = k;
        double r;
        for (i = k + 1; i < n; i++)
            if (fabs(lu[i * n + k]) > fabs(lu[p * n + k]))
                p = i;
        piv[k] = p;
        if (lu[p * n + k] == 0.0)
            return 1;
        if (p != k)
            for (j = 0; j < n; j++) {
                double t = lu[k * n + j];
                lu[k * n + j] = lu[p * n + j];
                lu[p * n + j] = t;
            }
        r = 1.0 / lu[k * n + k];
        for (i = k + 1; i < n; i++)
            lu[i * n + k] *= r;
        for (i = k + 1; i < n; i++)
            for (j = k + 1; j < n; j++)
                lu[i * n + j] -= lu[i * n + k] * lu[k * n + j];
    }
    /* B = P I, then L y = B (unit lower) and U x = y (dgetrs) */
    memset(inv, 0, sizeof(double) * n * n);
    for (i = 0; i < n; i++)
        inv[i * n + i] = 1.0;
    for (k = 0; k < n; k++)
        if (piv[k] != k)
            for (j = 0; j < n; j++) {
                double t = inv[k * n + j];
                inv[k * n + j] = inv[piv[k] * n + j];
                inv[piv[k] * n + j] = t;
            }
    /* the solves as OpenBLAS does them (measured against numpy 2.4 / OpenBLAS: bitwise equal on 2x2
       mass matrices, 3 in 4 of 3x3 ones, else 1 ulp): fused multiply-adds, the reciprocal of each
       diagonal */
    for (j = 0; j < n; j++) {
        for (k = 0; k < n; k++)
            for (i = k + 1; i < n; i++)
                inv[i * n + j] = fma(-inv[k * n + j], lu[i * n + k], inv[i * n + j]);
        for (k = n - 1; k >= 0; k--) {
            inv[k * n + j] *= 1.0 / lu[k * n + k];
            for (i = 0; i < k; i++)
                inv[i * n + j] = fma(-inv[k * n + j], lu[i * n + k], inv[i * n + j]);
        }
    }
    return 0;
}
