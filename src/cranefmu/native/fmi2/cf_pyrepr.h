/* Python's repr() of a float, so that the native FMU's messages read as the pythonfmu FMU's
   (cranefmu.physics.params.check_value writes values with {value!r}). */
#ifndef CF_PYREPR_H
#define CF_PYREPR_H

#include <stddef.h>

/* repr(x) of a Python float into buf (at least 32 bytes): the shortest digits that read back as x,
   fixed notation for a decimal exponent in [-4, 16), else d.ddde+XX; "inf", "-inf", "nan". */
void cf_pyrepr(double x, char *buf, size_t size);

#endif
