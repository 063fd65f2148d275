/* Integrator: an FMI 2.0 co-simulation FMU in C for the tests that can interpolate its input
 * (canInterpolateInputs): x' = u, with u over a step the polynomial u + s u' + s^2/2 u'' the master sets
 * with fmi2SetRealInputDerivatives (orders 1 and 2), integrated exactly.  Outputs y = x and ny = -x.
 * Value references (Real): 0 x0 (parameter), 1 u (input), 2 y, 3 ny (outputs).  integrator.py builds it.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

typedef struct {
    double x0, u, du, d2u, x, time;
    int init;
} Instance;

#include "fmi2_unsupported.h"

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging) {
    (void)name; (void)type; (void)guid; (void)resources; (void)cb; (void)visible; (void)logging;
    return calloc(1, sizeof(Instance));
}
void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real start, fmi2Boolean sd,
                               fmi2Real stop) {
    (void)td; (void)tol; (void)sd; (void)stop; ((Instance *)c)->time = start; return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { ((Instance *)c)->init = 1; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *x = c;
    x->init = 0;
    x->x = x->x0;
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { memset(c, 0, sizeof(Instance)); return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *x = c;
    double state = x->init ? x->x0 : x->x;
    for (size_t k = 0; k < n; k++) {
        switch (vr[k]) {
        case 0: value[k] = x->x0; break;
        case 1: value[k] = x->u; break;
        case 2: value[k] = state; break;
        case 3: value[k] = -state; break;
        default: return fmi2Error;
        }
    }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *x = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == 0) x->x0 = value[k];
        else if (vr[k] == 1) { x->u = value[k]; x->du = x->d2u = 0.0; }   /* a new value: held until told */
        else return fmi2Error;
    }
    return fmi2OK;
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    Instance *x = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] != 1 || order[k] < 1 || order[k] > 2) return fmi2Error;
        if (order[k] == 1) x->du = value[k]; else x->d2u = value[k];
    }
    return fmi2OK;
}
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    (void)no_prior;
    Instance *x = c;
    x->x += h * (x->u + h * (x->du / 2.0 + h * x->d2u / 6.0));
    x->u += h * (x->du + h * x->d2u / 2.0);
    x->du += h * x->d2u;
    x->time = t + h;
    return fmi2OK;
}
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    if (*s == NULL) *s = malloc(sizeof(Instance));
    if (*s == NULL) return fmi2Error;
    memcpy(*s, c, sizeof(Instance));
    return fmi2OK;
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { memcpy(c, s, sizeof(Instance)); return fmi2OK; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; free(*s); *s = NULL; return fmi2OK; }

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    (void)c; (void)vr; (void)value; return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    (void)c; (void)vr; (void)value; return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    (void)c; (void)vr; (void)value; return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    (void)c; (void)vr; (void)value; return n ? fmi2Error : fmi2OK;
}
