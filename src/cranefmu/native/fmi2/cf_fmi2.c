/* The generic FMI 2.0 co-simulation layer of a native crane FMU: what cranefmu.adapter.fmi_adapter.CraneSlave
   does for the pythonfmu FMU, in C99 + libm, over one model of include/cf_model.h.

   - Parameters solver, rtol, max_step, then the model's Params fields (cf_fmu_variables.h); each value
     is checked against its field's range or choices with the messages of
     cranefmu.physics.params.check_value, then cf_check_params and cf_prepare build the model.
     A refused parameter is reported through the logger by fmi2ExitInitializationMode with status
     error.  After initialization a fixed parameter cannot change; setting a tunable one rebuilds the
     model (the state is kept).
   - Inputs and, for every coupling input, <input>_dt and <input>_dt2: the inputs inside a step are
     u0 + s r1 + s^2/2 r2 (s: time into the step).
   - fmi2DoStep advances as fmi_adapter.advance: no integration when the model is frozen or has no
     state; "exact" takes cf_exact_step and falls back to rk4 at max_step; "auto" resolves to exact
     where cf_exact_applies, else rk4; then cf_after_step with the inputs at the end of the step and
     the finite-state check naming the state.
   - Outputs are computed lazily at the first get after a set or step; discrete outputs are Integers
     (rounded half to even, as Python's round).
   - fmi2Get/SetFMUstate copy the instance's values, state and model; serialization writes that copy.
   - Every failure is an error status with one logged line; nothing aborts the host. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#include "cf_fmi2.h"
#include "cf_model.h"
#include "cf_pyrepr.h"
#include "cf_solvers.h"
#include "cf_fmu_variables.h"

#define N_COUPLING CF_N_COUPLING
#define VR_INPUT0 CF_N_PARAM_VARS
#define VR_RATE0 (VR_INPUT0 + N_INPUTS)
#define VR_OUTPUT0 (VR_RATE0 + 2 * N_COUPLING)
#define N_VARS (VR_OUTPUT0 + N_OUTPUTS)
#define STATE_MAGIC 0x31534643u /* "CFS1" */

/* everything fmi2GetFMUstate saves: the variables' values, the model and its state */
typedef struct CfValues {
    unsigned mark;                       /* STATE_MAGIC ^ the GUID's hash: a state of this build */
    double pv[CF_N_PARAM_VARS];          /* parameter variables as set (codes for switches) */
    double fixed[CF_N_PARAM_VARS];       /* their values at initialization (the fixed ones must keep them) */
    double u[N_INPUTS + 1];
    double rates[2 * N_COUPLING + 1];    /* <input>_dt, <input>_dt2 per coupling input */
    double y[N_OUTPUTS + 1];             /* outputs (a discrete one holds its rounded value) */
    double x[CF_MAX_STATES];
    double p[N_PARAMS + 1];              /* the model's parameters (cf_model.h) */
    double t;
    int initialized, outputs_stale, init_error, model_built;
    int solver;                          /* CF_EULER ... CF_EXACT, resolved */
    CfModel model;
    char msg[CF_MSG_SIZE];
} CfValues;

typedef struct CfInstance {
    CfValues v;
    CfModel scratch;                     /* a model being built, kept only if it is valid */
    double scratch_p[N_PARAMS + 1];
    char instance_name[256];
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
    int logging_on;
} CfInstance;

int cf_fail(CfModel *m, const char *format, ...) {
    va_list ap;
    va_start(ap, format);
    vsnprintf(m->msg, CF_MSG_SIZE, format, ap);
    va_end(ap);
    return 1;
}

/* --- logging ------------------------------------------------------------------------------------ */
static void log_line(const CfInstance *c, fmi2Status status, const char *format, ...) {
    char line[2 * CF_MSG_SIZE];
    va_list ap;
    if (!c->logger) return;
    va_start(ap, format);
    vsnprintf(line, sizeof line, format, ap);
    va_end(ap);
    const char *category = status == fmi2Error ? "logStatusError" : status == fmi2Warning ? "logStatusWarning"
                         : status == fmi2Fatal ? "logStatusFatal" : status == fmi2Discard ? "logStatusDiscard"
                         : "logAll";
    if (status == fmi2OK && !c->logging_on) return;
    c->logger(c->env, c->instance_name, status, category, line);
}

/* a failure of an FMI call: "<instance>: <what>: <Kind>: <message>", status error */
static fmi2Status fail(CfInstance *c, const char *what, const char *kind) {
    log_line(c, fmi2Error, "%s: %s: %s: %s", c->instance_name, what, kind, c->v.msg);
    return fmi2Error;
}

static fmi2Status usage_error(CfInstance *c, const char *format, ...) {
    char line[CF_MSG_SIZE];
    va_list ap;
    va_start(ap, format);
    vsnprintf(line, sizeof line, format, ap);
    va_end(ap);
    log_line(c, fmi2Error, "%s: %s", c->instance_name, line);
    return fmi2Error;
}

/* --- parameters (cranefmu.physics.params.check_value; CraneSlave._named and _build_model) ------- */
static void value_text(const CfParamSpec *s, double value, char *buf, size_t size) {
    if (s->kind == CF_REAL)
        cf_pyrepr(value, buf, size);
    else
        snprintf(buf, size, "%.0f", value);
}

static const char *owner(const CfInstance *c, const CfParamSpec *s) {
    return s->owner ? s->owner : c->instance_name;
}

/* a switch's code: an integer in [0, n_choices) (CraneSlave._named) */
static int check_code(CfInstance *c, const CfParamSpec *s, double value) {
    if (value >= 0 && value < s->n_choices && value == floor(value)) return 0;
    snprintf(c->v.msg, CF_MSG_SIZE, "%s.%s = %.0f is not allowed: %s", CF_COMPONENT, s->name, value, s->codes);
    return 1;
}

/* the range or choices of a field (check_value) */
static int check_range(CfInstance *c, const CfParamSpec *s, double value) {
    char text[64];
    value_text(s, value, text, sizeof text);
    if (s->kind == CF_SWITCH) return 0;  /* its name is one of its choices once its code is */
    if (s->kind == CF_INT_CHOICE) {
        for (int i = 0; i < s->n_choices; i++)
            if (s->choices[i] == value) return 0;
        snprintf(c->v.msg, CF_MSG_SIZE, "%s.%s = %s is not allowed: %s", owner(c, s), s->name, text, s->allowed);
        return 1;
    }
    if (!isfinite(value)) {
        snprintf(c->v.msg, CF_MSG_SIZE, "%s.%s = %s is not finite: allowed %s", owner(c, s), s->name, text,
                 s->allowed);
        return 1;
    }
    int bad_lo = s->has_min && (s->min_open ? value <= s->min : value < s->min);
    int bad_hi = s->has_max && (s->max_open ? value >= s->max : value > s->max);
    if (bad_lo || bad_hi) {
        snprintf(c->v.msg, CF_MSG_SIZE, "%s.%s = %s is out of range: allowed %s", owner(c, s), s->name, text,
                 s->allowed);
        return 1;
    }
    return 0;
}

/* the FMU's solver code -> CF_EULER ... CF_RK45, CF_UNSUPPORTED for radau and bdf */
static int solver_method(int code) {
    const char *name = cf_solver_names[code];
    static const char *const methods[] = {"euler", "rk2", "rk4", "trbdf2", "exact", "auto", "rk45"};
    for (int i = 0; i < 7; i++)
        if (!strcmp(name, methods[i])) return i;
    return CF_UNSUPPORTED;
}

/* Validated parameters -> model m (its p: p), and the resolved solver; 1 with a message in c->v.msg and
   *kind the error's kind on failure (CraneSlave._build_model, in its order of checks). */
static int build_model(CfInstance *c, CfModel *m, double *p, int *solver, const char **kind) {
    const double *pv = c->v.pv;
    *kind = "ParameterError";
    if (check_code(c, &cf_param_specs[0], pv[0])) return 1;
    int method = solver_method((int)pv[0]);
    if (method == CF_UNSUPPORTED) {
        snprintf(c->v.msg, CF_MSG_SIZE, "%s.solver = %.0f (%s) is not offered by the native FMU: allowed %s "
                 "(radau and bdf: the pythonfmu FMU)", CF_COMPONENT, pv[0], cf_solver_names[(int)pv[0]],
                 CF_NATIVE_SOLVERS);
        return 1;
    }
    for (int i = 1; i < 3; i++)
        if (check_range(c, &cf_param_specs[i], pv[i])) return 1;
    for (int i = 3; i < CF_N_PARAM_VARS; i++)
        if (cf_param_specs[i].kind == CF_SWITCH && check_code(c, &cf_param_specs[i], pv[i])) return 1;
    for (int i = 3; i < CF_N_PARAM_VARS; i++)
        if (check_range(c, &cf_param_specs[i], pv[i])) return 1;
    for (int i = 3; i < CF_N_PARAM_VARS; i++) {
        const CfParamSpec *s = &cf_param_specs[i];
        double value = pv[i];
        if (s->kind == CF_INT_CHOICE)
            for (int k = 0; k < s->n_choices; k++)
                if (s->choices[k] == value) value = (double)k;
        p[i - 3] = value;
    }
    memset(m, 0, sizeof *m);
    m->p = p;
    m->msg = c->v.msg;
    if (cf_check_params(m)) return 1;
    *kind = "ValueError";
    if (cf_prepare(m)) return 1;
    if (m->n_states < 0 || m->n_states > CF_MAX_STATES) {
        snprintf(c->v.msg, CF_MSG_SIZE, "the model has %d states: allowed 0 to %d", m->n_states, CF_MAX_STATES);
        return 1;
    }
    if (method == CF_AUTO) method = cf_exact_applies(m) ? CF_EXACT : CF_RK4;
    *solver = method;
    return 0;
}

/* build into the scratch model and keep it only when it is valid */
static int rebuild(CfInstance *c, const char **kind) {
    int solver;
    if (build_model(c, &c->scratch, c->scratch_p, &solver, kind)) return 1;
    memcpy(c->v.p, c->scratch_p, sizeof c->v.p);
    c->v.model = c->scratch;
    c->v.model.p = c->v.p;
    c->v.model.msg = c->v.msg;
    c->v.solver = solver;
    c->v.model_built = 1;
    return 0;
}

/* x finite, else the message naming the states (Model.check_state) */
static int check_state(CfInstance *c, double t, const double *x) {
    int n = c->v.model.n_states, k = 0;
    for (int i = 0; i < n; i++) if (!isfinite(x[i])) k++;
    if (!k) return 0;
    char names[CF_MSG_SIZE / 2] = "";
    size_t used = 0;
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i])) {
            const char *name = cf_state_name(&c->v.model, i);
            char index[16];
            if (!name) { snprintf(index, sizeof index, "%d", i); name = index; }
            used += (size_t)snprintf(names + used, used < sizeof names ? sizeof names - used : 0, "%s%s",
                                     used ? ", " : "", name);
            if (used >= sizeof names) break;
        }
    snprintf(c->v.msg, CF_MSG_SIZE, "non-finite state %s at t = %.6g s", names, t);
    return 1;
}

/* --- outputs (CraneSlave._refresh_outputs) ------------------------------------------------------ */
static fmi2Status refresh_outputs(CfInstance *c) {
    CfValues *v = &c->v;
    const char *kind;
    if (v->init_error) return fmi2OK;  /* reported by fmi2ExitInitializationMode */
    if (!v->model_built || !v->initialized) {
        if (rebuild(c, &kind)) return fail(c, "cannot compute the outputs", kind);
        if (cf_initial_state(&v->model, v->u, v->x)) return fail(c, "cannot compute the outputs", "ValueError");
    }
    double y[N_OUTPUTS + 1];
    v->msg[0] = '\0';   /* a model that cannot compute its outputs says why there (cf_model.h) */
    cf_outputs(&v->model, v->t, v->x, v->u, y);
    if (v->msg[0] != '\0') return fail(c, "cannot compute the outputs", "FloatingPointError");
    for (int i = 0; i < N_OUTPUTS; i++)
        if (cf_output_discrete[i]) {
            if (!isfinite(y[i]) || fabs(y[i]) > 2147483647.0) {
                snprintf(v->msg, CF_MSG_SIZE, "discrete output %s = %.17g is not an integer", cf_output_names[i],
                         y[i]);
                return fail(c, "cannot compute the outputs", "ValueError");
            }
            y[i] = nearbyint(y[i]);  /* half to even, as Python's round */
        }
    memcpy(v->y, y, sizeof(double) * N_OUTPUTS);
    v->outputs_stale = 0;
    return fmi2OK;
}

/* --- advance (cranefmu.adapter.fmi_adapter.advance) ---------------------------------------------------- */
static int advance(CfInstance *c, double t, double h, double *x1, const char **kind) {
    CfValues *v = &c->v;
    CfModel *m = &v->model;
    int n = m->n_states, solver = v->solver, moving = 0;
    double r1[N_INPUTS + 1], r2[N_INPUTS + 1], u[N_INPUTS + 1];
    for (int i = 0; i < 2 * N_COUPLING; i++)
        if (v->rates[i] != 0.0) moving = 1;  /* NaN counts as set, as in Python */
    for (int i = 0; i < N_INPUTS; i++) r1[i] = r2[i] = 0.0;
    if (moving)
        for (int k = 0; k < N_COUPLING; k++) {
            r1[cf_coupling[k]] = v->rates[2 * k];
            r2[cf_coupling[k]] = v->rates[2 * k + 1];
        }
    memcpy(x1, v->x, sizeof(double) * (size_t)n);
    *kind = "FloatingPointError";
    if (!(n == 0 && solver != CF_EXACT) && !cf_frozen(m)) {
        int done = 0;
        if (solver == CF_EXACT) {
            int rc = cf_exact_step(m, t, v->x, h, v->u, r1, r2, v->pv[2], x1);
            if (rc < 0) return 1;
            done = rc == 1;
            solver = CF_RK4;
        }
        if (!done) {
            CfRhs f;
            f.m = m;
            f.t0 = t;
            f.u0 = v->u;
            f.r1 = r1;
            f.r2 = r2;
            f.moving = moving;
            f.n_inputs = N_INPUTS;
            f.u = u;
            if (cf_integrate(&f, solver, t, v->x, n, h, v->pv[2], v->pv[1], x1, v->msg, CF_MSG_SIZE)) return 1;
        }
    }
    double t1 = t + h;
    if (moving) {
        for (int i = 0; i < N_INPUTS; i++) u[i] = v->u[i] + h * (r1[i] + 0.5 * h * r2[i]);
        cf_after_step(m, t1, x1, u);
    } else {
        cf_after_step(m, t1, x1, v->u);
    }
    return check_state(c, t1, x1);
}

/* --- value references ------------------------------------------------------------------------- */
static int is_integer_vr(fmi2ValueReference vr) {
    if (vr < CF_N_PARAM_VARS) return cf_param_specs[vr].kind != CF_REAL;
    if (vr >= VR_OUTPUT0 && vr < N_VARS) return cf_output_discrete[vr - VR_OUTPUT0];
    return 0;
}

static const char *var_name(fmi2ValueReference vr) {
    if (vr < CF_N_PARAM_VARS) return cf_param_specs[vr].name;
    if (vr < VR_RATE0) return cf_input_names[vr - VR_INPUT0];
    if (vr < VR_OUTPUT0) return cf_rate_names[vr - VR_RATE0];
    if (vr < N_VARS) return cf_output_names[vr - VR_OUTPUT0];
    return "?";
}

static double *value_slot(CfValues *v, fmi2ValueReference vr) {
    if (vr < CF_N_PARAM_VARS) return &v->pv[vr];
    if (vr < VR_RATE0) return &v->u[vr - VR_INPUT0];
    if (vr < VR_OUTPUT0) return &v->rates[vr - VR_RATE0];
    return &v->y[vr - VR_OUTPUT0];
}

/* after a set that touched a parameter (CraneSlave._after_set) */
static fmi2Status after_parameter_set(CfInstance *c) {
    CfValues *v = &c->v;
    const char *kind;
    if (!v->initialized) return fmi2OK;
    for (int i = 0; i < CF_N_PARAM_VARS; i++) {
        const CfParamSpec *s = &cf_param_specs[i];
        double now = v->pv[i], old = v->fixed[i];
        if (s->tunable || now == old || (now != now && old != old)) continue;
        char a[64], b[64];
        value_text(s, now, a, sizeof a);
        value_text(s, old, b, sizeof b);
        snprintf(v->msg, CF_MSG_SIZE, "%s.%s = %s is refused: a fixed parameter cannot change after "
                 "initialization (it is %s)", CF_COMPONENT, s->name, a, b);
        return fail(c, "parameter refused", "ParameterError");
    }
    if (rebuild(c, &kind)) return fail(c, "parameter refused", kind);
    return fmi2OK;
}

/* --- FMI 2.0: common functions ----------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    (void)n;
    (void)categories;
    if (!comp) return fmi2Error;
    ((CfInstance *)comp)->logging_on = on ? 1 : 0;
    return fmi2OK;
}

static unsigned guid_hash(void);

static void reset_values(CfInstance *c) {
    CfValues *v = &c->v;
    memset(v, 0, sizeof *v);
    v->mark = STATE_MAGIC ^ guid_hash();
    for (int i = 0; i < CF_N_PARAM_VARS; i++) v->pv[i] = v->fixed[i] = cf_param_specs[i].start;
    for (int i = 0; i < N_INPUTS; i++) v->u[i] = cf_input_start[i];
    v->outputs_stale = 1;
    v->model.p = v->p;
    v->model.msg = v->msg;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean logging_on) {
    (void)resources;
    (void)visible;
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    void *env = functions ? functions->componentEnvironment : NULL;
    const char *who = name ? name : CF_MODEL_IDENTIFIER;
    if (type != fmi2CoSimulation) {
        if (logger) logger(env, who, fmi2Error, "logStatusError",
                           "fmi2Instantiate: this FMU offers co-simulation only");
        return NULL;
    }
    if (guid && strcmp(guid, CF_GUID) != 0) {
        if (logger) logger(env, who, fmi2Error, "logStatusError",
                           "fmi2Instantiate: the GUID does not match this FMU's modelDescription.xml");
        return NULL;
    }
    CfInstance *c = (CfInstance *)calloc(1, sizeof(CfInstance));
    if (!c) {
        if (logger) logger(env, who, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        return NULL;
    }
    snprintf(c->instance_name, sizeof c->instance_name, "%s", who);
    c->logger = logger;
    c->env = env;
    c->logging_on = logging_on ? 1 : 0;
    reset_values(c);
    return c;
}

void fmi2FreeInstance(fmi2Component comp) { free(comp); }

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                               fmi2Real start_time, fmi2Boolean stop_time_defined, fmi2Real stop_time) {
    (void)tolerance_defined;
    (void)tolerance;
    (void)stop_time_defined;
    (void)stop_time;
    if (!comp) return fmi2Error;
    ((CfInstance *)comp)->v.t = start_time;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    CfInstance *c = (CfInstance *)comp;
    const char *kind;
    if (!c) return fmi2Error;
    /* a refused parameter is reported at fmi2ExitInitializationMode (as the pythonfmu FMU) */
    c->v.init_error = rebuild(c, &kind);
    c->v.outputs_stale = 1;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    CfInstance *c = (CfInstance *)comp;
    CfValues *v;
    const char *kind;
    if (!c) return fmi2Error;
    v = &c->v;
    if (rebuild(c, &kind)) return fail(c, "initialization refused", kind);
    if (cf_initial_state(&v->model, v->u, v->x)) return fail(c, "initialization refused", "ValueError");
    if (check_state(c, v->t, v->x)) return fail(c, "initialization refused", "FloatingPointError");
#if CF_HAS_PREPARE_EXACT_STEP
    if (v->solver == CF_EXACT && cf_prepare_exact_step(&v->model))
        return fail(c, "initialization refused", "ParameterError");
#endif
    v->initialized = 1;
    v->init_error = 0;
    memcpy(v->fixed, v->pv, sizeof v->fixed);
    v->outputs_stale = 1;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp) { return comp ? fmi2OK : fmi2Error; }

fmi2Status fmi2Reset(fmi2Component comp) {
    if (!comp) return fmi2Error;
    reset_values((CfInstance *)comp);
    return fmi2OK;
}

/* --- get and set ------------------------------------------------------------------------------- */
fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    CfInstance *c = (CfInstance *)comp;
    if (!c) return fmi2Error;
    if (nvr && (!vr || !value)) return usage_error(c, "fmi2GetReal: no value references or values");
    if (nvr && c->v.outputs_stale && refresh_outputs(c) != fmi2OK) return fmi2Error;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARS || is_integer_vr(vr[i]))
            return usage_error(c, "fmi2GetReal: value reference %u is not a Real variable of %s", vr[i],
                               CF_MODEL_IDENTIFIER);
        value[i] = *value_slot(&c->v, vr[i]);
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    CfInstance *c = (CfInstance *)comp;
    if (!c) return fmi2Error;
    if (nvr && (!vr || !value)) return usage_error(c, "fmi2GetInteger: no value references or values");
    if (nvr && c->v.outputs_stale && refresh_outputs(c) != fmi2OK) return fmi2Error;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARS || !is_integer_vr(vr[i]))
            return usage_error(c, "fmi2GetInteger: value reference %u is not an Integer variable of %s", vr[i],
                               CF_MODEL_IDENTIFIER);
        value[i] = (fmi2Integer)*value_slot(&c->v, vr[i]);
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    (void)vr;
    (void)value;
    if (!comp) return fmi2Error;
    return nvr ? usage_error((CfInstance *)comp, "fmi2GetBoolean: %s has no Boolean variables",
                             CF_MODEL_IDENTIFIER) : fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr;
    (void)value;
    if (!comp) return fmi2Error;
    return nvr ? usage_error((CfInstance *)comp, "fmi2GetString: %s has no String variables",
                             CF_MODEL_IDENTIFIER) : fmi2OK;
}

/* one set of Real or Integer values; a set parameter then goes through after_parameter_set */
static fmi2Status set_values(CfInstance *c, const char *fn, int integer, const fmi2ValueReference vr[],
                             size_t nvr, const double *reals, const fmi2Integer *ints) {
    int parameter = 0;
    if (nvr && (!vr || (!reals && !ints))) return usage_error(c, "%s: no value references or values", fn);
    for (size_t i = 0; i < nvr; i++)
        if (vr[i] >= N_VARS || is_integer_vr(vr[i]) != integer)
            return usage_error(c, "%s: value reference %u is not %s variable of %s", fn, vr[i],
                               integer ? "an Integer" : "a Real", CF_MODEL_IDENTIFIER);
        else if (vr[i] >= VR_OUTPUT0)
            return usage_error(c, "%s: %s is an output: it cannot be set", fn, var_name(vr[i]));
    for (size_t i = 0; i < nvr; i++) {
        *value_slot(&c->v, vr[i]) = integer ? (double)ints[i] : reals[i];
        if (vr[i] < CF_N_PARAM_VARS) parameter = 1;
    }
    c->v.outputs_stale = 1;
    return parameter ? after_parameter_set(c) : fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    if (!comp) return fmi2Error;
    return set_values((CfInstance *)comp, "fmi2SetReal", 0, vr, nvr, value, NULL);
}

fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    if (!comp) return fmi2Error;
    return set_values((CfInstance *)comp, "fmi2SetInteger", 1, vr, nvr, NULL, value);
}

fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    (void)vr;
    (void)value;
    if (!comp) return fmi2Error;
    return nvr ? usage_error((CfInstance *)comp, "fmi2SetBoolean: %s has no Boolean variables",
                             CF_MODEL_IDENTIFIER) : fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr;
    (void)value;
    if (!comp) return fmi2Error;
    return nvr ? usage_error((CfInstance *)comp, "fmi2SetString: %s has no String variables",
                             CF_MODEL_IDENTIFIER) : fmi2OK;
}

/* --- FMU state ---------------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    CfInstance *c = (CfInstance *)comp;
    if (!c) return fmi2Error;
    if (!state) return usage_error(c, "fmi2GetFMUstate: no place for the state");
    CfValues *copy = (CfValues *)*state;
    if (!copy) copy = (CfValues *)malloc(sizeof(CfValues));
    if (!copy) return usage_error(c, "fmi2GetFMUstate: out of memory");
    memcpy(copy, &c->v, sizeof(CfValues));
    *state = copy;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state) {
    CfInstance *c = (CfInstance *)comp;
    if (!c) return fmi2Error;
    if (!state) return usage_error(c, "fmi2SetFMUstate: no state");
    if (((const CfValues *)state)->mark != (STATE_MAGIC ^ guid_hash()))
        return usage_error(c, "fmi2SetFMUstate: the state is not one of %s (this build)", CF_MODEL_IDENTIFIER);
    memcpy(&c->v, state, sizeof(CfValues));
    c->v.model.p = c->v.p;
    c->v.model.msg = c->v.msg;
    c->v.outputs_stale = 1;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    if (!comp) return fmi2Error;
    if (state) {
        free(*state);
        *state = NULL;
    }
    return fmi2OK;
}

/* serialized: magic, the size of the copy, the GUID's hash, the copy */
typedef struct { unsigned magic, size, guid_hash, pad; } StateHeader;

static unsigned guid_hash(void) {
    unsigned h = 2166136261u;  /* FNV-1a */
    for (const char *s = CF_GUID; *s; s++) h = (h ^ (unsigned char)*s) * 16777619u;
    return h;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size) {
    (void)state;
    if (!comp) return fmi2Error;
    if (!size) return usage_error((CfInstance *)comp, "fmi2SerializedFMUstateSize: no place for the size");
    *size = sizeof(StateHeader) + sizeof(CfValues);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    CfInstance *c = (CfInstance *)comp;
    StateHeader head = {STATE_MAGIC, (unsigned)sizeof(CfValues), 0, 0};
    if (!c) return fmi2Error;
    if (!state || !bytes) return usage_error(c, "fmi2SerializeFMUstate: no state or no bytes");
    if (size < sizeof head + sizeof(CfValues))
        return usage_error(c, "fmi2SerializeFMUstate: %lu bytes given, the state needs %lu", (unsigned long)size,
                           (unsigned long)(sizeof head + sizeof(CfValues)));
    head.guid_hash = guid_hash();
    memcpy(bytes, &head, sizeof head);
    memcpy(bytes + sizeof head, state, sizeof(CfValues));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    CfInstance *c = (CfInstance *)comp;
    StateHeader head;
    if (!c) return fmi2Error;
    if (!bytes || !state) return usage_error(c, "fmi2DeSerializeFMUstate: no bytes or no place for the state");
    if (size != sizeof head + sizeof(CfValues))
        return usage_error(c, "fmi2DeSerializeFMUstate: %lu bytes are not a state of %s (%lu bytes)",
                           (unsigned long)size, CF_MODEL_IDENTIFIER, (unsigned long)(sizeof head + sizeof(CfValues)));
    memcpy(&head, bytes, sizeof head);
    unsigned mark;
    memcpy(&mark, bytes + sizeof head, sizeof mark);
    if (head.magic != STATE_MAGIC || head.size != sizeof(CfValues) || head.guid_hash != guid_hash() ||
        mark != (STATE_MAGIC ^ guid_hash()))
        return usage_error(c, "fmi2DeSerializeFMUstate: the bytes are not a state of this build of %s",
                           CF_MODEL_IDENTIFIER);
    CfValues *copy = (CfValues *)*state;
    if (!copy) copy = (CfValues *)malloc(sizeof(CfValues));
    if (!copy) return usage_error(c, "fmi2DeSerializeFMUstate: out of memory");
    memcpy(copy, bytes + sizeof head, sizeof(CfValues));
    *state = copy;
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component comp, const fmi2ValueReference unknown[], size_t n_unknown,
                                        const fmi2ValueReference known[], size_t n_known, const fmi2Real dv_known[],
                                        fmi2Real dv_unknown[]) {
    (void)unknown; (void)n_unknown; (void)known; (void)n_known; (void)dv_known; (void)dv_unknown;
    if (!comp) return fmi2Error;
    return usage_error((CfInstance *)comp, "fmi2GetDirectionalDerivative: not provided by this FMU");
}

/* --- FMI 2.0: co-simulation --------------------------------------------------------------------- */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    if (!comp) return fmi2Error;
    return usage_error((CfInstance *)comp, "fmi2SetRealInputDerivatives: not provided: set <input>_dt and "
                       "<input>_dt2 instead");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    if (!comp) return fmi2Error;
    return usage_error((CfInstance *)comp, "fmi2GetRealOutputDerivatives: not provided by this FMU");
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real current_time, fmi2Real step_size, fmi2Boolean no_set_prior) {
    CfInstance *c = (CfInstance *)comp;
    double x1[CF_MAX_STATES];
    const char *kind;
    char what[96];
    (void)no_set_prior;
    if (!c) return fmi2Error;
    snprintf(what, sizeof what, "step at t = %.9g s failed", current_time);
    if (!c->v.initialized) {
        snprintf(c->v.msg, CF_MSG_SIZE, "the FMU is not initialized (call fmi2ExitInitializationMode first)");
        return fail(c, what, "RuntimeError");
    }
    if (advance(c, current_time, step_size, x1, &kind)) return fail(c, what, kind);
    memcpy(c->v.x, x1, sizeof(double) * (size_t)c->v.model.n_states);
    c->v.t = current_time + step_size;
    c->v.outputs_stale = 1;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component comp) {
    if (!comp) return fmi2Error;
    return usage_error((CfInstance *)comp, "fmi2CancelStep: fmi2DoStep never runs asynchronously here");
}

fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Status *value) {
    (void)s;
    if (!comp || !value) return fmi2Error;
    *value = fmi2OK;
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value) {
    if (!comp || !value) return fmi2Error;
    if (s == fmi2LastSuccessfulTime) {
        *value = ((CfInstance *)comp)->v.t;
        return fmi2OK;
    }
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s;
    (void)value;
    return comp ? fmi2Discard : fmi2Error;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Boolean *value) {
    if (!comp || !value) return fmi2Error;
    if (s == fmi2Terminated) {
        *value = fmi2False;
        return fmi2OK;
    }
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind s, fmi2String *value) {
    (void)s;
    (void)value;
    return comp ? fmi2Discard : fmi2Error;
}
