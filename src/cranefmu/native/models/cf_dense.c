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

/* --- 3x3 in the fixed order of cranefmu.physics.small_linalg (cf_dense.h) --------------------------- */
int cf_inverse3(const double *a, double *inv)
{
    double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8], c02 = a[3] * a[7] - a[4] * a[6];
    double c10 = a[2] * a[7] - a[1] * a[8], c11 = a[0] * a[8] - a[2] * a[6], c12 = a[1] * a[6] - a[0] * a[7];
    double c20 = a[1] * a[5] - a[2] * a[4], c21 = a[2] * a[3] - a[0] * a[5], c22 = a[0] * a[4] - a[1] * a[3];
    double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
    if (det == 0.0)
        return 1;
    inv[0] = c00 / det;
    inv[1] = c10 / det;
    inv[2] = c20 / det;
    inv[3] = c01 / det;
    inv[4] = c11 / det;
    inv[5] = c21 / det;
    inv[6] = c02 / det;
    inv[7] = c12 / det;
    inv[8] = c22 / det;
    return 0;
}

void cf_matvec3(const double *a, const double *v, double *y)
{
    double v0 = v[0], v1 = v[1], v2 = v[2];
    y[0] = a[0] * v0 + a[1] * v1 + a[2] * v2;
    y[1] = a[3] * v0 + a[4] * v1 + a[5] * v2;
    y[2] = a[6] * v0 + a[7] * v1 + a[8] * v2;
}

int cf_solve3(const double *a, const double *v, double *x)
{
    double inv[9];
    if (cf_inverse3(a, inv))
        return 1;
    cf_matvec3(inv, v, x);
    return 0;
}

int cf_solve_free3(const double *mask, const double *a, const double *v, double *x)
{
    int free[3], n = 0, i, j;
    for (i = 0; i < 3; i++)
        if (mask[i] != 0.0)
            free[n++] = i;
    if (n == 3)
        return cf_solve3(a, v, x);
    x[0] = x[1] = x[2] = 0.0;
    if (n == 2) {
        double aii, aij, aji, ajj, det, i00, i01, i10, i11;
        i = free[0];
        j = free[1];
        aii = a[3 * i + i];
        aij = a[3 * i + j];
        aji = a[3 * j + i];
        ajj = a[3 * j + j];
        det = aii * ajj - aij * aji;
        if (det == 0.0)
            return 1;
        i00 = ajj / det;
        i01 = -aij / det;
        i10 = -aji / det;
        i11 = aii / det;
        x[i] = i00 * v[i] + i01 * v[j];
        x[j] = i10 * v[i] + i11 * v[j];
    } else if (n == 1) {
        i = free[0];
        if (a[4 * i] == 0.0)
            return 1;
        x[i] = v[i] / a[4 * i];
    }
    return 0;
}
