/* Small dense linear algebra (cf_dense.h). */
#include "cf_dense.h"

#include <math.h>
#include <string.h>

/* LU with partial pivoting in place (dgetrf), the column below a pivot scaled by its reciprocal */
static int factor(int n, double *lu, int *piv)
{
    int i, j, k;
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
    return 0;
}

/* column j of the n x cols row-major b overwritten by the solution of LU x = P b (dgetrs; pivots
   already applied to b): the solves as OpenBLAS does them (measured against numpy 2.4 / OpenBLAS:
   bitwise equal on 2x2 mass matrices, 3 in 4 of 3x3 ones, else 1 ulp): fused multiply-adds, the
   reciprocal of each diagonal */
static void solve_column(int n, const double *lu, double *b, int cols, int j)
{
    int i, k;
    for (k = 0; k < n; k++)
        for (i = k + 1; i < n; i++)
            b[i * cols + j] = fma(-b[k * cols + j], lu[i * n + k], b[i * cols + j]);
    for (k = n - 1; k >= 0; k--) {
        b[k * cols + j] *= 1.0 / lu[k * n + k];
        for (i = 0; i < k; i++)
            b[i * cols + j] = fma(-b[k * cols + j], lu[i * n + k], b[i * cols + j]);
    }
}

int cf_solve(int n, const double *a, const double *b, double *x)
{
    double lu[CF_DENSE_MAX * CF_DENSE_MAX];
    int piv[CF_DENSE_MAX], k;
    memcpy(lu, a, sizeof(double) * n * n);
    if (factor(n, lu, piv))
        return 1;
    memcpy(x, b, sizeof(double) * n);
    for (k = 0; k < n; k++)
        if (piv[k] != k) {
            double t = x[k];
            x[k] = x[piv[k]];
            x[piv[k]] = t;
        }
    solve_column(n, lu, x, 1, 0);
    return 0;
}

int cf_inverse(int n, const double *a, double *inv)
{
    double lu[CF_DENSE_MAX * CF_DENSE_MAX];
    int piv[CF_DENSE_MAX], i, j, k;
    memcpy(lu, a, sizeof(double) * n * n);
    if (factor(n, lu, piv))
        return 1;
    /* B = P I, then L y = B (unit lower) and U x = y */
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
    for (j = 0; j < n; j++)
        solve_column(n, lu, inv, n, j);
    return 0;
}
