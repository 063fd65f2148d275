/* Exact step of a linear model with inputs polynomial in time over the step (C twin of
   cranefmu.physics.linear_step; derived).

   For x' = A x + b + B u(s) with u(s) = u0 + s r1 + s^2/2 r2 (s: time into the step), the vector
   z = (x, 1, u0, r1, r2) obeys z' = Z z with

       Z = [[A, b, B, 0, 0],      x' = A x + b + B u
            [0, 0, 0, 0, 0],      1' = 0
            [0, 0, 0, I, 0],      u' = r1 + s r2
            [0, 0, 0, 0, I],      (r1 + s r2)' = r2
            [0, 0, 0, 0, 0]]

   so x(s) = [expm(Z s) z(0)] restricted to x, exact to round-off (the augmented-matrix construction of
   Van Loan 1978 for integrals of matrix exponentials).  One expm per step size, then a matrix-vector
   product per step.

   No allocation: a CfLinearStep lives in the model's data (CfModel.data) and caches the maps of the
   last two step sizes (the Python propagator keeps up to 16; a master uses one or two). */
#ifndef CF_LINEAR_STEP_H
#define CF_LINEAR_STEP_H

#define CF_LS_MAX_N 6                                   /* states */
#define CF_LS_MAX_M 3                                   /* inputs */
#define CF_LS_MAX_SIZE (CF_LS_MAX_N + 1 + 3 * CF_LS_MAX_M)
#define CF_LS_CACHE 2

/* The maps of one step size h checked at k sub-points. */
typedef struct CfLinearMaps {
    double h_key;                                      /* cf_step_key(h) */
    int k;
    unsigned long used;                                /* when it was used last (LRU) */
    double sub[CF_LS_MAX_SIZE * CF_LS_MAX_SIZE];       /* expm(Z h_key / k), size x size */
    double end[CF_LS_MAX_N * CF_LS_MAX_SIZE];          /* rows 0..n-1 of sub^k: z -> x(h), n x size */
} CfLinearMaps;

typedef struct CfLinearStep {
    int n, m, size;
    double generator[CF_LS_MAX_SIZE * CF_LS_MAX_SIZE]; /* Z, row-major */
    double spectral_radius;                            /* max |eig(A)| [1/s] */
    double last_h;                                     /* h as given at the last call ... */
    int last_k;                                        /* ... its k ... */
    int last;                                          /* ... and its entry (-1: none) */
    unsigned long clock;
    int valid[CF_LS_CACHE];
    CfLinearMaps entry[CF_LS_CACHE];
} CfLinearStep;

/* The step size [s] to 12 significant digits (linear_step.step_key): a fixed-step master computes h
   as t_next - t, which differs from step to step in the last bits. */
double cf_step_key(double h);

/* Z from A (n x n), b (n), B (n x m), all row-major; the cache emptied.  Returns 0, or 1 when n or m
   exceed CF_LS_MAX_N / CF_LS_MAX_M.  with_radius: also compute max |eig(A)| (Chassis' margin). */
int cf_linear_init(CfLinearStep *ls, int n, int m, const double *a, const double *b, const double *big_b,
                   int with_radius);

/* The maps of step h with k sub-steps (computed on a miss: one expm, k matrix products). */
const CfLinearMaps *cf_linear_maps(CfLinearStep *ls, double h, int k);

/* z = (x, 1, u0[:m], r1[:m], r2[:m]) into z (size). */
void cf_linear_augment(const CfLinearStep *ls, const double *x, const double *u0, const double *r1,
                       const double *r2, double *z);

/* y = M z for the first `rows` rows of a row-major rows x size matrix (sums in column order). */
void cf_linear_apply(const CfLinearStep *ls, const double *map, int rows, const double *z, double *y);

/* exp(a) of an n x n row-major matrix (n <= CF_LS_MAX_SIZE): scaling and squaring with Pade
   approximants of degree 3, 5, 7, 9 or 13 chosen as in Al-Mohy and Higham 2009 (Algorithm 5.1, the
   choice scipy.linalg.expm makes; exact 1-norms of the powers, as scipy does for small n), and its
   final solve as scipy's, I + 2 (V - U)^-1 U with the LU factors of (V - U)^T.  Agrees with scipy to
   round-off, not to the bit (other summation orders in the products): a map applied to a state is
   within 2e-14 of the summed terms of an extended-precision exponential, as scipy's is
   (benchmarks/results/native_exact_step.md). */
void cf_expm(int n, const double *a, double *out);

/* max |lambda| over the eigenvalues of the n x n matrix a (n <= CF_LS_MAX_N): the characteristic
   polynomial (Faddeev-LeVerrier) and its roots (Durand-Kerner, polished by Newton); ~1e-12 relative. */
double cf_spectral_radius(int n, const double *a);

#endif
