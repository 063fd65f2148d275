/* Python's own float functions (cf_pymath.h). */
#include "cf_pymath.h"

#include <float.h>
#include <math.h>

/* the sum hi + lo of a >= |b| + b, exact (Dekker's fast two-sum) */
static double two_sum_lo(double a, double b, double *hi)
{
    *hi = a + b;
    return (a - *hi) + b;
}

static double norm_scaled(const double v[2], double largest)
{
    double csum = 1.0, frac1 = 0.0, frac2 = 0.0, scale, x, sq, sq_lo, h;
    int e, i;

    frexp(largest, &e);
    if (e < -1023) { /* 2^-e would overflow: lift the subnormals first */
        double w[2] = {v[0] / DBL_MIN, v[1] / DBL_MIN};
        return DBL_MIN * norm_scaled(w, largest / DBL_MIN);
    }
    scale = ldexp(1.0, -e);
    /* csum + frac1 + frac2 = 1 + sum of the scaled squares; the 1 keeps csum's exponent fixed */
    for (i = 0; i < 2; i++) {
        x = v[i] * scale;
        sq = x * x;
        sq_lo = fma(x, x, -sq);
        frac2 += two_sum_lo(csum, sq, &csum);
        frac1 += sq_lo;
    }
    h = sqrt(csum - 1.0 + (frac1 + frac2));
    /* one Newton step: h + (sum - h^2) / (2 h), the residual sum - h^2 in double length */
    sq = -h * h;
    sq_lo = fma(-h, h, -sq);
    frac2 += two_sum_lo(csum, sq, &csum);
    frac1 += sq_lo;
    x = csum - 1.0 + (frac1 + frac2);
    h += x / (2.0 * h);
    return h / scale;
}

double cf_py_hypot(double a, double b)
{
    double v[2] = {fabs(a), fabs(b)};
    double largest = v[0] > v[1] ? v[0] : v[1];

    if (isinf(a) || isinf(b))
        return INFINITY;
    if (isnan(a) || isnan(b))
        return NAN;
    if (largest == 0.0)
        return largest;
    return norm_scaled(v, largest);
}
