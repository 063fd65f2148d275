/* Python's repr() of a float in C, for error messages in the same words as the Python models'. */
#ifndef CF_REPR_H
#define CF_REPR_H

#define CF_REPR_SIZE 32

/* Writes repr(x) as CPython prints it (the shortest digits that read back to x; fixed notation for
   decimal exponents -4..15 with ".0" on whole numbers, else d.ddde+XX) into out (CF_REPR_SIZE
   bytes) and returns out, so that it can stand in a printf argument list. */
const char *cf_repr(double x, char *out);

#endif
