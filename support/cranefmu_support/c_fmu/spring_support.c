/* SpringSupport: an FMI 2.0 co-simulation FMU written in C for the tests (not built by cranefmu).
 *
 * A sprung suspension point moving vertically: mass m on a spring k and damper d, pulled by the
 * force F the rope exerts on it (y up; the rope pulls down, F < 0):
 *
 *     m y'' = F - k y - d y'                                  (derived)
 *
 * y is measured from the unloaded spring.  start = 1 starts at rest for the input F given in
 * initialization mode (y = F / k, v = 0); start = 0 from y0, v0.  Between communication points
 * F is held (zero-order hold) and the state advanced by classical RK4 with substeps of at most
 * max_step.  State save/restore is supported (no serialization).
 *
 * Compiled against the FMI 2.0 headers fmpy ships (build.py beside it).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define GUID "{6a3a1d7e-0c1f-4c8e-9a51-cranefmu-c-fmu}"

enum { VR_M, VR_K, VR_D, VR_Y0, VR_V0, VR_MAX_STEP, VR_F, VR_Y, VR_V, VR_A, N_REAL };
enum { VR_START, N_INTEGER };

typedef enum { INSTANTIATED, INITIALIZATION, STEPPING, TERMINATED } Mode;

typedef struct {
    double r[N_REAL];
    int i[N_INTEGER];
    double time;
    Mode mode;
} State;

typedef struct {
    State s;
    char name[128];
    fmi2CallbackFunctions cb;
} Instance;

static const double START_REAL[N_REAL] = {10.0, 1.0e6, 0.0, 0.0, 0.0, 1.0e-4, 0.0, 0.0, 0.0, 0.0};

static void log_error(Instance *c, const char *message) {
    if (c->cb.logger) c->cb.logger(c->cb.componentEnvironment, c->name, fmi2Error, "error", message);
}

static double acceleration(const double *r, double y, double v) {
    return (r[VR_F] - r[VR_K] * y - r[VR_D] * v) / r[VR_M];
}

/* the outputs before the first step: the start state for the inputs and parameters now */
static void start_state(State *s) {
    double *r = s->r;
    if (s->i[VR_START] == 1) {
        r[VR_Y] = r[VR_F] / r[VR_K];
        r[VR_V] = 0.0;
    } else {
        r[VR_Y] = r[VR_Y0];
        r[VR_V] = r[VR_V0];
    }
    r[VR_A] = acceleration(r, r[VR_Y], r[VR_V]);
}

static int valid(Instance *c) {
    const double *r = c->s.r;
    if (!(r[VR_M] > 0.0) || !(r[VR_K] > 0.0) || !(r[VR_D] >= 0.0) || !(r[VR_MAX_STEP] > 0.0)) {
        log_error(c, "SpringSupport: m, k and max_step must be > 0 and d >= 0");
        return 0;
    }
    if (c->s.i[VR_START] != 0 && c->s.i[VR_START] != 1) {
        log_error(c, "SpringSupport: start must be 0 (given) or 1 (equilibrium)");
        return 0;
    }
    return 1;
}

static void reset(Instance *c) {
    memcpy(c->s.r, START_REAL, sizeof START_REAL);
    c->s.i[VR_START] = 1;
    c->s.time = 0.0;
    c->s.mode = INSTANTIATED;
}

/* --- FMI 2.0 ---------------------------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    (void)c; (void)on; (void)n; (void)cats;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean logging) {
    (void)resources; (void)visible; (void)logging;
    if (type != fmi2CoSimulation || !guid || strcmp(guid, GUID) != 0) return NULL;
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    strncpy(c->name, name ? name : "", sizeof c->name - 1);
    if (functions) c->cb = *functions;
    reset(c);
    return c;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stop_defined, fmi2Real stop) {
    (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
    ((Instance *)c)->s.time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    ((Instance *)c)->s.mode = INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *inst = c;
    if (!valid(inst)) return fmi2Error;
    start_state(&inst->s);
    inst->s.mode = STEPPING;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    ((Instance *)c)->s.mode = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    reset(c);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *inst = c;
    if (inst->s.mode == INITIALIZATION) start_state(&inst->s);   /* outputs calculated from inputs now */
    for (size_t j = 0; j < n; j++) {
        if (vr[j] >= N_REAL) return fmi2Error;
        value[j] = inst->s.r[vr[j]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *inst = c;
    for (size_t j = 0; j < n; j++) {
        if (vr[j] > VR_F) return fmi2Error;   /* parameters and the input only */
        if (vr[j] < VR_F && inst->s.mode == STEPPING) return fmi2Error;   /* parameters are fixed */
        inst->s.r[vr[j]] = value[j];
    }
    if (inst->s.mode == STEPPING) inst->s.r[VR_A] = acceleration(inst->s.r, inst->s.r[VR_Y], inst->s.r[VR_V]);
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    for (size_t j = 0; j < n; j++) {
        if (vr[j] >= N_INTEGER) return fmi2Error;
        value[j] = ((Instance *)c)->s.i[vr[j]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    Instance *inst = c;
    for (size_t j = 0; j < n; j++) {
        if (vr[j] >= N_INTEGER || inst->s.mode == STEPPING) return fmi2Error;
        inst->s.i[vr[j]] = value[j];
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    (void)c; (void)vr; (void)value;
    return n == 0 ? fmi2OK : fmi2Error;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    (void)c; (void)vr; (void)value;
    return n == 0 ? fmi2OK : fmi2Error;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    (void)c; (void)vr; (void)value;
    return n == 0 ? fmi2OK : fmi2Error;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    (void)c; (void)vr; (void)value;
    return n == 0 ? fmi2OK : fmi2Error;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    State *copy = *state ? (State *)*state : malloc(sizeof(State));
    if (!copy) return fmi2Error;
    *copy = ((Instance *)c)->s;
    *state = copy;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    if (!state) return fmi2Error;
    ((Instance *)c)->s = *(State *)state;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)c;
    free(*state);
    *state = NULL;
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    (void)c; (void)state; (void)size;
    return fmi2Error;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    (void)c; (void)state; (void)bytes; (void)size;
    return fmi2Error;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    (void)c; (void)bytes; (void)size; (void)state;
    return fmi2Error;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference unknown[], size_t n_unknown,
                                        const fmi2ValueReference known[], size_t n_known, const fmi2Real dv_known[],
                                        fmi2Real dv_unknown[]) {
    (void)c; (void)unknown; (void)n_unknown; (void)known; (void)n_known; (void)dv_known; (void)dv_unknown;
    return fmi2Error;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)value;
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)value;
    return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    (void)no_prior;
    Instance *inst = c;
    double *r = inst->s.r;
    if (inst->s.mode != STEPPING || !(h > 0.0)) return fmi2Error;
    int n = (int)ceil(h / r[VR_MAX_STEP] - 1e-9);
    if (n < 1) n = 1;
    double dt = h / n, y = r[VR_Y], v = r[VR_V];
    for (int j = 0; j < n; j++) {   /* classical RK4 on (y, v) */
        double k1y = v, k1v = acceleration(r, y, v);
        double k2y = v + 0.5 * dt * k1v, k2v = acceleration(r, y + 0.5 * dt * k1y, v + 0.5 * dt * k1v);
        double k3y = v + 0.5 * dt * k2v, k3v = acceleration(r, y + 0.5 * dt * k2y, v + 0.5 * dt * k2v);
        double k4y = v + dt * k3v, k4v = acceleration(r, y + dt * k3y, v + dt * k3v);
        y += dt / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
        v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    if (!isfinite(y) || !isfinite(v)) {
        log_error(inst, "SpringSupport: the state is not finite");
        return fmi2Discard;
    }
    r[VR_Y] = y;
    r[VR_V] = v;
    r[VR_A] = acceleration(r, y, v);
    inst->s.time = t + h;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    (void)c;
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = ((Instance *)c)->s.time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
