"""Matrix exponential (scaling and squaring with Pade approximants) in one fixed order of operations.

The algorithm is scipy.linalg.expm's: Al-Mohy and Higham, "A new scaling and squaring algorithm for the
matrix exponential", SIAM J. Matrix Anal. Appl. 31 (2009) 970-989 (Algorithm 6.1: degrees 3, 5, 7, 9, 13
chosen by the theta bounds and the extra squarings ell(A, m) of eq. 5.2 with the exact norms of |A|^p),
with Higham's Pade coefficients (SIAM J. Matrix Anal. Appl. 26 (2005), Table 2.3).  scipy hands the
products to BLAS (dgemm) and the final solve to LAPACK, whose kernels order their sums and fuse
multiply-adds as the machine's OpenBLAS chooses; here every product and sum is in the order of the C
twin ``native/models/cf_linear_step.c`` (``cf_expm``, compiled without FP contraction), so the Python and
the native FMUs take the same bits (issue 33):

- a product C = A B: C_ij = sum over l = 0..n-1 of A_il B_lj, summed from 0.0 in increasing l;
- a norm: column sums of |.| from 0.0 in increasing row, the largest kept if strictly larger;
- linear combinations left to right as written in :func:`expm`;
- the Pade solve X = (V - U)^-1 (V + U) = I + 2 (V - U)^-1 U with the LU factors of (V - U)^T (partial
  pivoting, the first largest pivot, the column divided by the pivot), then for each column of U the
  transposed triangular solves and the row swaps undone (as LAPACK's getrs "T" on scipy's row-major data);
- libm's pow, log2 and ceil (the same calls as C).

Each step is one IEEE operation on each element, so numpy's element-wise arithmetic on whole rows gives
the same bits as the C loops.
"""
from __future__ import annotations

import math

import numpy as np

_B = {3: (120.0, 60.0, 12.0, 1.0),
      5: (30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0),
      7: (17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0),
      9: (17643225600.0, 8821612800.0, 2075673600.0, 302702400.0, 30270240.0, 2162160.0, 110880.0, 3960.0,
          90.0, 1.0),
      13: (64764752532480000.0, 32382376266240000.0, 7771770303897600.0, 1187353796428800.0,
           129060195264000.0, 10559470521600.0, 670442572800.0, 33522128640.0, 1323241920.0, 40840800.0,
           960960.0, 16380.0, 182.0, 1.0)}
# 1 / |c_{2m+1}|, the coefficients of the Pade error series (Higham 2005, eq. 2.2, 2.6)
_C_RECIP = {3: 100800.0, 5: 10059033600.0, 7: 4487938430976000.0, 9: 5914384781877411840000.0,
            13: 113250775606021113483283660800000000.0}


def _seq_sum(terms: np.ndarray) -> np.ndarray:
    """0.0 + terms[0] + terms[1] + ... along axis 0, one addition after the other (np.add.accumulate is
    sequential; np.sum is pairwise and would not be C's loop)."""
    first = terms[0] + 0.0          # C's s = 0.0; s += t0 (turns -0.0 into 0.0 as C does)
    if len(terms) == 1:
        return first
    return np.add.accumulate(np.concatenate((first[None], terms[1:])), axis=0)[-1]


def matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A B with each entry summed from 0.0 in increasing inner index (module docstring)."""
    return _seq_sum(a.T[:, :, None] * b[:, None, :])


def matvec(a, z) -> list[float]:
    """A z on plain floats, each row summed from 0.0 left to right (C's cf_linear_apply)."""
    z = z.tolist() if hasattr(z, "tolist") else list(z)
    out = []
    for row in (a.tolist() if hasattr(a, "tolist") else a):
        s = 0.0
        for aij, zj in zip(row, z):
            s += aij * zj
        out.append(s)
    return out


def _largest(values: np.ndarray) -> float:
    best = 0.0
    for v in values.tolist():
        if v > best:
            best = v
    return best


def _one_norm(a: np.ndarray) -> float:
    return _largest(_seq_sum(np.abs(a)))


def _abs_power_norm(a: np.ndarray, p: int) -> float:
    """||A^p||_1 of the nonnegative |A| exactly: the largest entry of e^T |A|^p (Al-Mohy, Higham 2009, sec. 5)."""
    w = np.ones(a.shape[0])
    aa = np.abs(a)
    for _ in range(p):
        w = _seq_sum(w[:, None] * aa)
    return _largest(w)


def _ell(a: np.ndarray, m: int) -> int:
    """ell(A, m), Al-Mohy and Higham 2009 eq. (5.2): the extra squarings the backward error bound asks for."""
    norm_p = _abs_power_norm(a, 2 * m + 1)
    if norm_p == 0.0:
        return 0
    alpha = norm_p / (_one_norm(a) * _C_RECIP[m])
    value = math.ceil(math.log2(alpha / math.ldexp(1.0, -53)) / (2 * m))
    return value if value > 0 else 0


def _solve_pq(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """I + 2 (V - U)^-1 U through the LU factors of (V - U)^T (module docstring)."""
    n = u.shape[0]
    w = (v - u).T.copy()
    piv = []
    for k in range(n):
        p = k + int(np.argmax(np.abs(w[k:, k])))   # the first largest magnitude
        piv.append(p)
        if p != k:
            w[[k, p]] = w[[p, k]]
        if w[k, k] != 0.0:
            w[k + 1:, k] = w[k + 1:, k] / w[k, k]
        w[k + 1:, k + 1:] = w[k + 1:, k + 1:] - np.multiply.outer(w[k + 1:, k], w[k, k + 1:])
    col = u.copy()          # row i of col: entry i of every column's solution
    # each s = col_i - w_0i col_0 - w_1i col_1 - ... one subtraction after the other (x - y is x + (-y))
    for i in range(n):      # R^T (the upper factor transposed), dividing by the diagonal
        s = col[i] if i == 0 else np.add.accumulate(
            np.concatenate((col[i][None], -(w[:i, i, None] * col[:i]))), axis=0)[-1]
        col[i] = s / w[i, i]
    for i in range(n - 2, -1, -1):   # L^T (unit diagonal)
        col[i] = np.add.accumulate(np.concatenate((col[i][None], -(w[i + 1:, i, None] * col[i + 1:]))), axis=0)[-1]
    for k in range(n - 1, -1, -1):
        if piv[k] != k:
            col[[k, piv[k]]] = col[[piv[k], k]]
    return 2.0 * col + np.eye(n)


def expm(a_in: np.ndarray) -> np.ndarray:
    """exp(A) of the square ``a_in`` (module docstring: scipy's algorithm, C's order)."""
    a = np.array(a_in, dtype=float)
    n = a.shape[0]
    eye = np.eye(n)
    a2 = matmul(a, a)
    a4 = matmul(a2, a2)
    a6 = matmul(a4, a2)
    a8 = None
    d4, d6 = math.pow(_one_norm(a4), 0.25), math.pow(_one_norm(a6), 1.0 / 6.0)
    eta1 = d4 if d4 > d6 else d6
    s = 0
    if eta1 <= 1.495585217958292e-002 and _ell(a, 3) == 0:
        m = 3
    elif eta1 <= 2.539398330063230e-001 and _ell(a, 5) == 0:
        m = 5
    else:
        a8 = matmul(a4, a4)
        d8 = math.pow(_one_norm(a8), 0.125)
        eta3 = d6 if d6 > d8 else d8
        if eta3 <= 9.504178996162932e-001 and _ell(a, 7) == 0:
            m = 7
        elif eta3 <= 2.097847961257068e+000 and _ell(a, 9) == 0:
            m = 9
        else:
            d10 = math.pow(_one_norm(matmul(a4, a6)), 0.1)
            eta4 = d8 if d8 > d10 else d10
            eta5 = eta3 if eta3 < eta4 else eta4
            s = max(math.ceil(math.log2(eta5 / 4.25)), 0)
            s += _ell(np.ldexp(a, -s), 13)
            a, a2, a4, a6 = np.ldexp(a, -s), np.ldexp(a2, -2 * s), np.ldexp(a4, -4 * s), np.ldexp(a6, -6 * s)
            m = 13
    b = _B[m]
    if m == 13:
        # U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I],
        # V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I
        t2 = matmul(a6, b[13] * a6 + b[11] * a4 + b[9] * a2)
        t2 = t2 + (b[7] * a6 + b[5] * a4 + b[3] * a2 + b[1] * eye)
        u = matmul(a, t2)
        v = matmul(a6, b[12] * a6 + b[10] * a4 + b[8] * a2)
        v = v + (b[6] * a6 + b[4] * a4 + b[2] * a2 + b[0] * eye)
    else:
        # U = A sum_j b_{2j+1} A^{2j}, V = sum_j b_{2j} A^{2j}, j = 0..(m-1)/2
        powers = (None, a2, a4, a6, a8)
        odd, v = b[1] * eye, b[0] * eye
        for j in range(1, (m - 1) // 2 + 1):
            odd = odd + b[2 * j + 1] * powers[j]
            v = v + b[2 * j] * powers[j]
        u = matmul(a, odd)
    out = _solve_pq(u, v)
    for _ in range(s):
        out = matmul(out, out)
    return out
