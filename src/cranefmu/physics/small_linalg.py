"""3x3 linear algebra on plain floats in one fixed, documented order of operations.

numpy hands a 3x3 inverse, solve or matrix-vector product to LAPACK/OpenBLAS, whose kernels choose their
own order and fused multiply-adds (they differ from machine to machine and version to version); the C
models (``native/models/cf_dense.c``: ``cf_inverse3``, ``cf_solve3``, ``cf_matvec3``) do exactly the
operations below in the same order, compiled without floating-point contraction, so the two give the
same bits (issue 33).  On plain floats they are also several times cheaper than numpy on 3x3 arrays.

Matrices are row-major sequences of 9 floats a0..a8 (a[3 i + j] = row i, column j).

Order (each line is evaluated left to right, no fused multiply-add):

- cofactors  c_ij = a[r1 s1] a[r2 s2] - a[r1 s2] a[r2 s1] with (r1, r2), (s1, s2) the rows and columns
  other than i, j in increasing order, signed: c01 and c10, c12 and c21 negated (-(x - y) as y - x);
- det        = a0 c00 + a1 c01 + a2 c02 (expansion along the first row);
- inverse    inv[3 i + j] = c_ji / det (the adjugate divided, not multiplied by 1 / det);
- matvec     y_i = a[3 i] v0 + a[3 i + 1] v1 + a[3 i + 2] v2;
- solve      x = inverse(a) v, then matvec (Cramer's rule in the same cofactors);
- solve on the free directions (a mask of 3 with zeros for the frozen ones, as the Pendulum's dimension):
  3 free: solve; 2 free (i < j): det = a_ii a_jj - a_ij a_ji, the inverse [a_jj, -a_ij; -a_ji, a_ii] / det
  (each entry divided), then x_i = inv_00 v_i + inv_01 v_j, x_j = inv_10 v_i + inv_11 v_j; 1 free:
  x_i = v_i / a_ii; 0 elsewhere.

Source: the adjugate formula of the inverse (any linear algebra text, e.g. Strang, Introduction to Linear
Algebra, sec. 5.3); derived here: the order of operations is the project's choice, stated so that C and
Python follow it.
"""
from __future__ import annotations

from typing import Sequence


class SingularMatrix(ArithmeticError):
    """The 3x3 matrix has a zero determinant."""


def cofactors3(a: Sequence[float]) -> tuple[float, ...]:
    """The signed cofactors c00, c01, ..., c22 of the row-major 3x3 ``a`` (module docstring's order)."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    return (a4 * a8 - a5 * a7, a5 * a6 - a3 * a8, a3 * a7 - a4 * a6,
            a2 * a7 - a1 * a8, a0 * a8 - a2 * a6, a1 * a6 - a0 * a7,
            a1 * a5 - a2 * a4, a2 * a3 - a0 * a5, a0 * a4 - a1 * a3)


def inverse3(a: Sequence[float]) -> list[float]:
    """Row-major inverse of the row-major 3x3 ``a`` by the adjugate (module docstring); raises
    :class:`SingularMatrix` when the determinant is 0."""
    c00, c01, c02, c10, c11, c12, c20, c21, c22 = cofactors3(a)
    det = a[0] * c00 + a[1] * c01 + a[2] * c02
    if det == 0.0:
        raise SingularMatrix(f"3x3 matrix {list(a)!r} is singular (determinant 0)")
    return [c00 / det, c10 / det, c20 / det, c01 / det, c11 / det, c21 / det, c02 / det, c12 / det, c22 / det]


def matvec3(a: Sequence[float], v: Sequence[float]) -> list[float]:
    """a v for the row-major 3x3 ``a`` and a 3-vector ``v``, each row summed left to right."""
    v0, v1, v2 = v
    return [a[0] * v0 + a[1] * v1 + a[2] * v2, a[3] * v0 + a[4] * v1 + a[5] * v2,
            a[6] * v0 + a[7] * v1 + a[8] * v2]


def solve3(a: Sequence[float], v: Sequence[float]) -> list[float]:
    """x with a x = v: :func:`inverse3` then :func:`matvec3` (raises :class:`SingularMatrix`)."""
    return matvec3(inverse3(a), v)


def solve_free3(a: Sequence[float], v: Sequence[float], mask: Sequence[float]) -> list[float]:
    """x with a x = v on the directions where ``mask`` is not 0 (the rows and columns of the others
    dropped), 0 on the others (module docstring's order); raises :class:`SingularMatrix`."""
    free = [i for i in range(3) if mask[i] != 0.0]
    x = [0.0, 0.0, 0.0]
    if len(free) == 3:
        return solve3(a, v)
    if len(free) == 2:
        i, j = free
        aii, aij, aji, ajj = a[3 * i + i], a[3 * i + j], a[3 * j + i], a[3 * j + j]
        det = aii * ajj - aij * aji
        if det == 0.0:
            raise SingularMatrix(f"2x2 block {[aii, aij, aji, ajj]!r} is singular (determinant 0)")
        i00, i01, i10, i11 = ajj / det, -aij / det, -aji / det, aii / det
        x[i], x[j] = i00 * v[i] + i01 * v[j], i10 * v[i] + i11 * v[j]
    elif len(free) == 1:
        i = free[0]
        if a[4 * i] == 0.0:
            raise SingularMatrix(f"1x1 block {a[4 * i]!r} is singular")
        x[i] = v[i] / a[4 * i]
    return x
