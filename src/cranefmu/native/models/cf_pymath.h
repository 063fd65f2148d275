/* Python's own float functions where CPython does not call libm, so that a C model gives the same
   bits as its Python twin. */
#ifndef CF_PYMATH_H
#define CF_PYMATH_H

/* math.hypot(a, b) as CPython 3.10+ computes it (not libm's hypot: glibc 2.36's differs from it in
   the last bit for about 0.5 % of arguments): both scaled by a power of two so the larger is in
   [0.5, 1), their squares summed in double length (exact products by fma), the square root
   corrected by one Newton step on the double-length residual, and scaled back.  Measured equal to
   CPython 3.11's math.hypot on 300000 random pairs over ten decades and on zeros, subnormals,
   infinities and NaN (tests/native/test_boom_model.py). */
double cf_py_hypot(double a, double b);

#endif
