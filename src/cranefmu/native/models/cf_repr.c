/* Python's repr() of a float (cf_repr.h). */
#include "cf_repr.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *cf_repr(double x, char *out)
{
    char buf[40], digits[24];
    int precision, exponent, n_digits = 0, i, pos = 0;
    const char *s;

    if (isnan(x)) {
        strcpy(out, "nan");
        return out;
    }
    if (isinf(x)) {
        strcpy(out, x > 0 ? "inf" : "-inf");
        return out;
    }
    /* the shortest %.{p}e that reads back to x: the digits of Python's repr (David Gay's mode 0) */
    for (precision = 0; precision < 17; precision++) {
        snprintf(buf, sizeof buf, "%.*e", precision, x);
        if (strtod(buf, NULL) == x)
            break;
    }
    if (precision == 17)
        snprintf(buf, sizeof buf, "%.16e", x);
    s = buf;
    if (*s == '-') {
        out[pos++] = '-';
        s++;
    }
    for (; *s && *s != 'e'; s++)
        if (*s != '.')
            digits[n_digits++] = *s;
    exponent = atoi(s + 1);
    while (n_digits > 1 && digits[n_digits - 1] == '0')
        n_digits--;
    digits[n_digits] = '\0';
    if (exponent >= -4 && exponent < 16) {
        if (exponent < 0) {
            out[pos++] = '0';
            out[pos++] = '.';
            for (i = 0; i < -exponent - 1; i++)
                out[pos++] = '0';
            for (i = 0; i < n_digits; i++)
                out[pos++] = digits[i];
        } else {
            for (i = 0; i <= exponent; i++)
                out[pos++] = i < n_digits ? digits[i] : '0';
            out[pos++] = '.';
            if (n_digits > exponent + 1)
                for (i = exponent + 1; i < n_digits; i++)
                    out[pos++] = digits[i];
            else
                out[pos++] = '0';
        }
        out[pos] = '\0';
    } else {
        out[pos++] = digits[0];
        if (n_digits > 1) {
            out[pos++] = '.';
            for (i = 1; i < n_digits; i++)
                out[pos++] = digits[i];
        }
        snprintf(out + pos, CF_REPR_SIZE - pos, "e%c%02d", exponent < 0 ? '-' : '+', abs(exponent));
    }
    return out;
}
