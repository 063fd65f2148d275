/* Python's repr() of a float (the algorithm of CPython's float_repr, mode 'r': shortest round-trip
   digits, fixed notation when -4 <= exponent < 16, else scientific with at least two exponent
   digits; a fixed number always has a fractional part, "1.0"). */
#include "cf_pyrepr.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cf_pyrepr(double x, char *buf, size_t size) {
    char sci[40], digits[24];
    int prec, exponent, n_digits, negative, i;
    size_t k = 0;

    if (isnan(x)) {
        snprintf(buf, size, "nan");
        return;
    }
    if (isinf(x)) {
        snprintf(buf, size, x < 0 ? "-inf" : "inf");
        return;
    }
    /* the shortest correctly rounded d.ddd that reads back as x */
    for (prec = 1; prec <= 17; prec++) {
        snprintf(sci, sizeof sci, "%.*e", prec - 1, x);
        if (strtod(sci, NULL) == x) break;
    }
    negative = sci[0] == '-';
    n_digits = 0;
    for (i = negative; sci[i] && sci[i] != 'e'; i++)
        if (sci[i] >= '0' && sci[i] <= '9') digits[n_digits++] = sci[i];
    digits[n_digits] = '\0';
    exponent = atoi(strchr(sci, 'e') + 1);
    while (n_digits > 1 && digits[n_digits - 1] == '0') digits[--n_digits] = '\0';

    char out[64];
    if (negative) out[k++] = '-';
    if (exponent < -4 || exponent >= 16) {  /* scientific: d[.ddd]e+XX */
        out[k++] = digits[0];
        if (n_digits > 1) {
            out[k++] = '.';
            for (i = 1; i < n_digits; i++) out[k++] = digits[i];
        }
        k += (size_t)snprintf(out + k, sizeof out - k, "e%c%02d", exponent < 0 ? '-' : '+', abs(exponent));
    } else if (exponent < 0) {  /* 0.000ddd */
        out[k++] = '0';
        out[k++] = '.';
        for (i = 0; i < -exponent - 1; i++) out[k++] = '0';
        for (i = 0; i < n_digits; i++) out[k++] = digits[i];
        out[k] = '\0';
    } else {  /* ddd.ddd, at least one digit after the point */
        for (i = 0; i <= exponent; i++) out[k++] = i < n_digits ? digits[i] : '0';
        out[k++] = '.';
        if (n_digits > exponent + 1)
            for (i = exponent + 1; i < n_digits; i++) out[k++] = digits[i];
        else
            out[k++] = '0';
        out[k] = '\0';
    }
    snprintf(buf, size, "%s", out);
}
