/* Exact step of a linear model with polynomial inputs: Van Loan's augmented matrix, its matrix
   exponential and the maps per step size (cf_linear_step.h; C twin of physics/linear_step.py). */
#include "cf_linear_step.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define S CF_LS_MAX_SIZE

double cf_step_key(double h)
{
    /* float(f"{h:.12g}"): both sides round correctly, so the same double */
    char buf[40];
    snprintf(buf, sizeof buf, "%.12g", h);
    return strtod(buf, NULL);
}

/* --- small dense matrices, row-major n x n ------------------------------------------------------ */
static void mat_mul(int n, const double *a, const double *b, double *c)
{
    int i, j, l;
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++) {
            double s = 0.0;
            for (l = 0; l < n; l++)
                s += a[i * n + l] * b[l * n + j];
            c[i * n + j] = s;
        }
}

static double one_norm(int n, const double *a)
{
    double best = 0.0;
    int i, j;
    for (j = 0; j < n; j++) {
        double s = 0.0;
        for (i = 0; i < n; i++)
            s += fabs(a[i * n + j]);
        if (s > best)
            best = s;
    }
    return best;
}

/* ||A^p||_1 of the nonnegative |A|, exactly: max over e^T |A|^p (Al-Mohy and Higham 2009, sec. 5) */
static double abs_power_norm(int n, const double *a, int p)
{
    double w[S], v[S], best = 0.0;
    int i, j, r;
    for (j = 0; j < n; j++)
        w[j] = 1.0;
    for (r = 0; r < p; r++) {
        for (j = 0; j < n; j++) {
            double s = 0.0;
            for (i = 0; i < n; i++)
                s += w[i] * fabs(a[i * n + j]);
            v[j] = s;
        }
        memcpy(w, v, sizeof(double) * n);
    }
    for (j = 0; j < n; j++)
        if (w[j] > best)
            best = w[j];
    return best;
}

/* ell(A, m) of Al-Mohy and Higham 2009 eq. (5.2): extra squarings the backward error bound asks for */
static int ell(int n, const double *a, int m)
{
    /* 1 / |c_{2m+1}|, the coefficients of the Pade error series (Higham 2005, eq. 2.2, 2.6) */
    double c_recip = m == 3 ? 100800.0 : m == 5 ? 10059033600.0 : m == 7 ? 4487938430976000.0
                   : m == 9 ? 5914384781877411840000.0 : 113250775606021113483283660800000000.0;
    double norm_p = abs_power_norm(n, a, 2 * m + 1), alpha, value;
    if (norm_p == 0.0)
        return 0;
    alpha = norm_p / (one_norm(n, a) * c_recip);
    value = ceil(log2(alpha / ldexp(1.0, -53)) / (2 * m));
    return value > 0.0 ? (int)value : 0;
}

/* X = (V - U)^-1 (V + U) as I + 2 (V - U)^-1 U, with the LU factors of (V - U)^T (partial pivoting on
   the transpose: what scipy's expm gets by handing its row-major arrays to LAPACK's getrf/getrs "T"; on
   the badly scaled augmented generators it keeps small entries to round-off, where pivoting on V - U
   itself left them 1e-12 off) */
static void solve_pq(int n, const double *u, const double *v, double *x)
{
    double w[S * S], col[S];
    int piv[S], i, j, k;
    for (i = 0; i < n; i++)   /* w = (V - U)^T */
        for (j = 0; j < n; j++)
            w[j * n + i] = v[i * n + j] - u[i * n + j];
    for (k = 0; k < n; k++) {   /* w = P L R, row pivoting (getrf) */
        int p = k;
        for (i = k + 1; i < n; i++)
            if (fabs(w[i * n + k]) > fabs(w[p * n + k]))
                p = i;
        piv[k] = p;
        if (p != k)
            for (j = 0; j < n; j++) {
                double t = w[k * n + j];
                w[k * n + j] = w[p * n + j];
                w[p * n + j] = t;
            }
        if (w[k * n + k] != 0.0)
            for (i = k + 1; i < n; i++)
                w[i * n + k] /= w[k * n + k];
        for (i = k + 1; i < n; i++)
            for (j = k + 1; j < n; j++)
                w[i * n + j] -= w[i * n + k] * w[k * n + j];
    }
    for (j = 0; j < n; j++) {   /* (V - U) y = U[:, j] = w^T y (getrs "T"): R^T, L^T, then the swaps */
        for (i = 0; i < n; i++)
            col[i] = u[i * n + j];
        for (i = 0; i < n; i++) {
            double s = col[i];
            for (k = 0; k < i; k++)
                s -= w[k * n + i] * col[k];
            col[i] = s / w[i * n + i];
        }
        for (i = n - 1; i >= 0; i--) {
            double s = col[i];
            for (k = i + 1; k < n; k++)
                s -= w[k * n + i] * col[k];
            col[i] = s;
        }
        for (k = n - 1; k >= 0; k--)
            if (piv[k] != k) {
                double t = col[k];
                col[k] = col[piv[k]];
                col[piv[k]] = t;
            }
        for (i = 0; i < n; i++)
            x[i * n + j] = 2.0 * col[i] + (i == j ? 1.0 : 0.0);
    }
}

void cf_expm(int n, const double *a_in, double *out)
{
    /* Pade coefficients b_0..b_m (Higham 2005, Table 2.3 / Al-Mohy and Higham 2009) */
    static const double b3[] = {120.0, 60.0, 12.0, 1.0};
    static const double b5[] = {30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0};
    static const double b7[] = {17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0};
    static const double b9[] = {17643225600.0, 8821612800.0, 2075673600.0, 302702400.0, 30270240.0,
                                2162160.0, 110880.0, 3960.0, 90.0, 1.0};
    static const double b13[] = {64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
                                 1187353796428800.0, 129060195264000.0, 10559470521600.0, 670442572800.0,
                                 33522128640.0, 1323241920.0, 40840800.0, 960960.0, 16380.0, 182.0, 1.0};
    double a[S * S], a2[S * S], a4[S * S], a6[S * S], a8[S * S], t1[S * S], t2[S * S], u[S * S], v[S * S];
    double d4, d6, d8, d10, eta1, eta3, eta4, eta5;
    const double *b = NULL;
    int nn = n * n, i, m = 0, s = 0, r;

    memcpy(a, a_in, sizeof(double) * nn);
    mat_mul(n, a, a, a2);
    mat_mul(n, a2, a2, a4);
    mat_mul(n, a4, a2, a6);
    d4 = pow(one_norm(n, a4), 0.25);
    d6 = pow(one_norm(n, a6), 1.0 / 6.0);
    eta1 = d4 > d6 ? d4 : d6;
    if (eta1 <= 1.495585217958292e-002 && ell(n, a, 3) == 0) {
        m = 3;
        b = b3;
    } else if (eta1 <= 2.539398330063230e-001 && ell(n, a, 5) == 0) {
        m = 5;
        b = b5;
    } else {
        mat_mul(n, a4, a4, a8);
        d8 = pow(one_norm(n, a8), 0.125);
        eta3 = d6 > d8 ? d6 : d8;
        if (eta3 <= 9.504178996162932e-001 && ell(n, a, 7) == 0) {
            m = 7;
            b = b7;
        } else if (eta3 <= 2.097847961257068e+000 && ell(n, a, 9) == 0) {
            m = 9;
            b = b9;
        } else {
            mat_mul(n, a4, a6, t1);
            d10 = pow(one_norm(n, t1), 0.1);
            eta4 = d8 > d10 ? d8 : d10;
            eta5 = eta3 < eta4 ? eta3 : eta4;
            s = (int)ceil(log2(eta5 / 4.25));
            if (s < 0)
                s = 0;
            for (i = 0; i < nn; i++)
                t1[i] = ldexp(a[i], -s);
            s += ell(n, t1, 13);
            for (i = 0; i < nn; i++) {
                a[i] = ldexp(a[i], -s);
                a2[i] = ldexp(a2[i], -2 * s);
                a4[i] = ldexp(a4[i], -4 * s);
                a6[i] = ldexp(a6[i], -6 * s);
            }
            m = 13;
            b = b13;
        }
    }
    if (m == 13) {
        /* U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I],
           V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I */
        for (i = 0; i < nn; i++)
            t1[i] = b[13] * a6[i] + b[11] * a4[i] + b[9] * a2[i];
        mat_mul(n, a6, t1, t2);
        for (i = 0; i < nn; i++)
            t2[i] += b[7] * a6[i] + b[5] * a4[i] + b[3] * a2[i] + (i % (n + 1) == 0 ? b[1] : 0.0);
        mat_mul(n, a, t2, u);
        for (i = 0; i < nn; i++)
            t1[i] = b[12] * a6[i] + b[10] * a4[i] + b[8] * a2[i];
        mat_mul(n, a6, t1, v);
        for (i = 0; i < nn; i++)
            v[i] += b[6] * a6[i] + b[4] * a4[i] + b[2] * a2[i] + (i % (n + 1) == 0 ? b[0] : 0.0);
    } else {
        /* U = A sum_j b_{2j+1} A^{2j}, V = sum_j b_{2j} A^{2j}, j = 0..(m-1)/2 */
        const double *pw[5];
        pw[0] = NULL;
        pw[1] = a2;
        pw[2] = a4;
        pw[3] = a6;
        pw[4] = a8;
        memset(t1, 0, sizeof t1);   /* (filled below; tells the compiler so) */
        for (i = 0; i < nn; i++) {
            double odd = i % (n + 1) == 0 ? b[1] : 0.0, even = i % (n + 1) == 0 ? b[0] : 0.0;
            int j;
            for (j = 1; 2 * j <= m - 1; j++) {
                odd += b[2 * j + 1] * pw[j][i];
                even += b[2 * j] * pw[j][i];
            }
            t1[i] = odd;
            v[i] = even;
        }
        mat_mul(n, a, t1, u);
    }
    solve_pq(n, u, v, out);
    for (r = 0; r < s; r++) {
        mat_mul(n, out, out, t1);
        memcpy(out, t1, sizeof(double) * nn);
    }
}

/* --- spectral radius ---------------------------------------------------------------------------- */
double cf_spectral_radius(int n, const double *a)
{
    /* characteristic polynomial sum_k c_k lambda^k, c_n = 1 (Faddeev-LeVerrier) */
    double c[CF_LS_MAX_N + 1], mk[CF_LS_MAX_N * CF_LS_MAX_N], amk[CF_LS_MAX_N * CF_LS_MAX_N];
    double bound = 0.0, best = 0.0;
    double complex roots[CF_LS_MAX_N];
    int i, j, k, it;

    if (n <= 0)
        return 0.0;
    memset(mk, 0, sizeof mk);
    c[n] = 1.0;
    for (k = 1; k <= n; k++) {
        double trace = 0.0;
        /* M_k = A M_{k-1} + c_{n-k+1} I */
        if (k == 1) {
            for (i = 0; i < n * n; i++)
                mk[i] = 0.0;
        } else {
            mat_mul(n, a, mk, amk);
            memcpy(mk, amk, sizeof(double) * n * n);
        }
        for (i = 0; i < n; i++)
            mk[i * n + i] += c[n - k + 1];
        mat_mul(n, a, mk, amk);
        for (i = 0; i < n; i++)
            trace += amk[i * n + i];
        c[n - k] = -trace / k;
    }
    /* Fujiwara's bound on the roots */
    for (k = 1; k <= n; k++) {
        double r = pow(fabs(c[n - k]) / (k == n ? 2.0 : 1.0), 1.0 / k);
        if (r > bound)
            bound = r;
    }
    bound *= 2.0;
    if (bound == 0.0)
        return 0.0;
    for (i = 0; i < n; i++)
        roots[i] = bound * cpow(0.4 + 0.9 * I, i);
    /* Durand-Kerner: all roots at once */
    for (it = 0; it < 2000; it++) {
        double change = 0.0, size = 0.0;
        for (i = 0; i < n; i++) {
            double complex p = 1.0, q = 1.0, z = roots[i], step;
            for (k = n - 1; k >= 0; k--)
                p = p * z + c[k];
            for (j = 0; j < n; j++)
                if (j != i)
                    q *= z - roots[j];
            if (q == 0.0)
                q = 1e-300;
            step = p / q;
            roots[i] = z - step;
            if (cabs(step) > change)
                change = cabs(step);
            if (cabs(roots[i]) > size)
                size = cabs(roots[i]);
        }
        if (change <= 1e-15 * size)
            break;
    }
    for (i = 0; i < n; i++)
        if (cabs(roots[i]) > best)
            best = cabs(roots[i]);
    return best;
}

/* --- the propagator ------------------------------------------------------------------------------ */
int cf_linear_init(CfLinearStep *ls, int n, int m, const double *a, const double *b, const double *big_b,
                   int with_radius)
{
    int size = n + 1 + 3 * m, i, j;
    double *z = ls->generator;
    if (n > CF_LS_MAX_N || m > CF_LS_MAX_M)
        return 1;
    ls->n = n;
    ls->m = m;
    ls->size = size;
    memset(z, 0, sizeof ls->generator);
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++)
            z[i * size + j] = a[i * n + j];
        z[i * size + n] = b[i];
        for (j = 0; j < m; j++)
            z[i * size + n + 1 + j] = big_b[i * m + j];
    }
    for (j = 0; j < m; j++) {
        z[(n + 1 + j) * size + n + 1 + m + j] = 1.0;
        z[(n + 1 + m + j) * size + n + 1 + 2 * m + j] = 1.0;
    }
    ls->spectral_radius = with_radius ? cf_spectral_radius(n, a) : 0.0;
    ls->last = -1;
    ls->last_h = 0.0;
    ls->last_k = 0;
    ls->clock = 0;
    for (i = 0; i < CF_LS_CACHE; i++)
        ls->valid[i] = 0;
    return 0;
}

static void fill_maps(CfLinearStep *ls, CfLinearMaps *e, double h_key, int k)
{
    int size = ls->size, nn = size * size, i, it;
    double scaled[S * S], phi[S * S], next[S * S];
    double factor = h_key / k;
    for (i = 0; i < nn; i++)
        scaled[i] = ls->generator[i] * factor;
    cf_expm(size, scaled, e->sub);
    /* phi = sub^k, as sub @ phi from the identity (linear_step.maps) */
    memset(phi, 0, sizeof(double) * nn);
    for (i = 0; i < size; i++)
        phi[i * size + i] = 1.0;
    for (it = 0; it < k; it++) {
        mat_mul(size, e->sub, phi, next);
        memcpy(phi, next, sizeof(double) * nn);
    }
    memcpy(e->end, phi, sizeof(double) * ls->n * size);
    e->h_key = h_key;
    e->k = k;
}

const CfLinearMaps *cf_linear_maps(CfLinearStep *ls, double h, int k)
{
    double h_key;
    int i, slot = -1;
    ls->clock++;
    if (ls->last >= 0 && ls->last_h == h && ls->last_k == k) {   /* a fixed-step master: the same h */
        ls->entry[ls->last].used = ls->clock;
        return &ls->entry[ls->last];
    }
    h_key = cf_step_key(h);
    for (i = 0; i < CF_LS_CACHE; i++)
        if (ls->valid[i] && ls->entry[i].h_key == h_key && ls->entry[i].k == k)
            slot = i;
    if (slot < 0) {   /* a free entry, else the least recently used */
        for (i = 0; i < CF_LS_CACHE && slot < 0; i++)
            if (!ls->valid[i])
                slot = i;
        if (slot < 0) {
            slot = 0;
            for (i = 1; i < CF_LS_CACHE; i++)
                if (ls->entry[i].used < ls->entry[slot].used)
                    slot = i;
        }
        fill_maps(ls, &ls->entry[slot], h_key, k);
        ls->valid[slot] = 1;
    }
    ls->entry[slot].used = ls->clock;
    ls->last = slot;
    ls->last_h = h;
    ls->last_k = k;
    return &ls->entry[slot];
}

void cf_linear_augment(const CfLinearStep *ls, const double *x, const double *u0, const double *r1,
                       const double *r2, double *z)
{
    int n = ls->n, m = ls->m, j;
    for (j = 0; j < n; j++)
        z[j] = x[j];
    z[n] = 1.0;
    for (j = 0; j < m; j++) {
        z[n + 1 + j] = u0[j];
        z[n + 1 + m + j] = r1[j];
        z[n + 1 + 2 * m + j] = r2[j];
    }
}

void cf_linear_apply(const CfLinearStep *ls, const double *map, int rows, const double *z, double *y)
{
    int size = ls->size, i, j;
    for (i = 0; i < rows; i++) {
        double s = 0.0;
        for (j = 0; j < size; j++)
            s += map[i * size + j] * z[j];
        y[i] = s;
    }
}
