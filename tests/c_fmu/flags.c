/* Flags: an FMI 2.0 co-simulation FMU in C for the tests (issue 35), after the Modelica Association's
 * Reference FMU Feedthrough: each output is its input, of the same type (Real, Boolean, Integer,
 * Enumeration), held over a step.  Compiled against the FMI 2.0 headers fmpy ships (flags.py beside it).
 * Value references per type: Real 0 in, 1 out; Boolean 0 in, 1 out; Integer 0 in, 1 out, Enumeration
 * (an Integer to FMI) 2 in, 3 out.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

typedef struct {
    double r[2];
    int b[2];
    int i[4];
    double time;
} Instance;

#include "fmi2_unsupported.h"

static void through(Instance *c) {
    c->r[1] = c->r[0];
    c->b[1] = c->b[0];
    c->i[1] = c->i[0];
    c->i[3] = c->i[2];
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging) {
    (void)name; (void)type; (void)guid; (void)resources; (void)cb; (void)visible; (void)logging;
    Instance *c = calloc(1, sizeof(Instance));
    if (c) { c->i[2] = 1; through(c); }
    return c;
}
void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real start, fmi2Boolean sd,
                               fmi2Real stop) {
    (void)td; (void)tol; (void)sd; (void)stop; ((Instance *)c)->time = start; return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { through(c); return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { memset(c, 0, sizeof(Instance)); ((Instance *)c)->i[2] = 1; return fmi2OK; }

#define ACCESS(NAME, T, FIELD, N, CONST, DIR)                                                          \
    fmi2Status NAME(fmi2Component c, const fmi2ValueReference vr[], size_t n, CONST T value[]) {        \
        Instance *x = c;                                                                               \
        for (size_t k = 0; k < n; k++) {                                                               \
            if (vr[k] >= N) return fmi2Error;                                                          \
            DIR;                                                                                       \
        }                                                                                              \
        through(x);                                                                                    \
        return fmi2OK;                                                                                 \
    }
ACCESS(fmi2GetReal, fmi2Real, r, 2, , value[k] = x->r[vr[k]])
ACCESS(fmi2SetReal, fmi2Real, r, 2, const, x->r[vr[k]] = value[k])
ACCESS(fmi2GetInteger, fmi2Integer, i, 4, , value[k] = x->i[vr[k]])
ACCESS(fmi2SetInteger, fmi2Integer, i, 4, const, x->i[vr[k]] = value[k])
ACCESS(fmi2GetBoolean, fmi2Boolean, b, 2, , value[k] = x->b[vr[k]])
ACCESS(fmi2SetBoolean, fmi2Boolean, b, 2, const, x->b[vr[k]] = value[k] ? 1 : 0)

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)value; return fmi2Error;
}
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    (void)no_prior;
    Instance *x = c;
    x->time = t + h;
    through(x);
    return fmi2OK;
}
