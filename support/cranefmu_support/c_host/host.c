/* A minimal FMI 2.0 co-simulation host in C: loads FMUs with dlopen, couples them with Jacobi and
 * zero-order hold in the order the connections are listed, writes a CSV.  It exists to prove that
 * the cranefmu FMUs run outside Python hosts (tests/test_native_hosts.py) and to measure the cost
 * of a step there (benchmarks/native_host_cost.py).
 *
 * Usage: host CONFIG OUT.csv
 * CONFIG, one item a line (whitespace separated, '#' starts a comment):
 *   fmu NAME UNZIPDIR MODEL_IDENTIFIER GUID      an FMU, index 0, 1, ... in this order
 *   real FMU VR VALUE | int FMU VR VALUE         start values (parameters), set before initialization
 *   conn SRC_FMU SRC_VR DST_FMU DST_VR           a Real connection; exchanged in the listed order, so
 *                                                list feedthrough sources before their readers
 *   out FMU VR COLUMN                            a Real column of the CSV
 *   run START STOP STEP                          the experiment
 *   hold_gil 1                                   keep one Python thread state for the whole run
 *                                                (see README "Using an FMU in another tool")
 * Prints "steps N seconds_per_step S" and "freed K instances" on stdout; exit 0 on success.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2Functions.h"

#define MAX_FMUS 8
#define MAX_ITEMS 256

typedef struct {
    char name[64];
    void *lib;
    fmi2Component c;
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *freeInstance;
    fmi2SetupExperimentTYPE *setupExperiment;
    fmi2EnterInitializationModeTYPE *enterInitializationMode;
    fmi2ExitInitializationModeTYPE *exitInitializationMode;
    fmi2TerminateTYPE *terminate;
    fmi2GetRealTYPE *getReal;
    fmi2SetRealTYPE *setReal;
    fmi2SetIntegerTYPE *setInteger;
    fmi2DoStepTYPE *doStep;
} Fmu;

typedef struct { int fmu; unsigned vr; double value; int is_int; } Start;
typedef struct { int src; unsigned src_vr; int dst; unsigned dst_vr; } Conn;
typedef struct { int fmu; unsigned vr; char column[96]; } Out;

static Fmu fmus[MAX_FMUS];
static int n_fmus;

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    fprintf(stderr, "[%s] status %d %s: %s\n", instance ? instance : "?", (int)status, category ? category : "",
            message ? message : "");
}

static void *sym(Fmu *f, const char *name) {
    void *p = dlsym(f->lib, name);
    if (!p) {
        fprintf(stderr, "host: %s has no symbol %s\n", f->name, name);
        exit(3);
    }
    return p;
}

static void check(fmi2Status s, const char *what, const char *who) {
    if (s > fmi2Warning) {
        fprintf(stderr, "host: %s failed for %s with status %d\n", what, who, (int)s);
        exit(4);
    }
}

int main(int argc, char **argv) {
    static Start starts[MAX_ITEMS];
    static Conn conns[MAX_ITEMS];
    static Out outs[MAX_ITEMS];
    int n_starts = 0, n_conns = 0, n_outs = 0, hold_gil = 0;
    double t0 = 0.0, t1 = 1.0, h = 1e-3;
    char line[4096];
    static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

    if (argc != 3) {
        fprintf(stderr, "usage: host CONFIG OUT.csv\n");
        return 2;
    }
    FILE *cfg = fopen(argv[1], "r");
    if (!cfg) {
        fprintf(stderr, "host: cannot read %s\n", argv[1]);
        return 2;
    }
    while (fgets(line, sizeof line, cfg)) {
        char key[16], a[1024], b[1024], d[256];
        if (line[0] == '#' || sscanf(line, "%15s", key) != 1) continue;
        if (!strcmp(key, "fmu") && n_fmus < MAX_FMUS &&
            sscanf(line, "%*s %63s %1023s %1023s %255s", fmus[n_fmus].name, a, b, d) == 4) {
            Fmu *f = &fmus[n_fmus];
            char path[2200], uri[1100];
            snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", a, b);
            /* RTLD_GLOBAL is not needed: the FMU resolves libpython from the process (LD_PRELOAD) */
            f->lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
            if (!f->lib) {
                fprintf(stderr, "host: dlopen %s: %s\n", path, dlerror());
                return 3;
            }
            f->instantiate = sym(f, "fmi2Instantiate");
            f->freeInstance = sym(f, "fmi2FreeInstance");
            f->setupExperiment = sym(f, "fmi2SetupExperiment");
            f->enterInitializationMode = sym(f, "fmi2EnterInitializationMode");
            f->exitInitializationMode = sym(f, "fmi2ExitInitializationMode");
            f->terminate = sym(f, "fmi2Terminate");
            f->getReal = sym(f, "fmi2GetReal");
            f->setReal = sym(f, "fmi2SetReal");
            f->setInteger = sym(f, "fmi2SetInteger");
            f->doStep = sym(f, "fmi2DoStep");
            snprintf(uri, sizeof uri, "file://%s/resources", a);
            f->c = f->instantiate(f->name, fmi2CoSimulation, d, uri, &callbacks, fmi2False, fmi2False);
            if (!f->c) {
                fprintf(stderr, "host: fmi2Instantiate failed for %s (is libpython preloaded and numpy on "
                                "PYTHONPATH?)\n", f->name);
                return 3;
            }
            n_fmus++;
        } else if ((!strcmp(key, "real") || !strcmp(key, "int")) && n_starts < MAX_ITEMS) {
            Start *s = &starts[n_starts++];
            s->is_int = key[0] == 'i';
            sscanf(line, "%*s %d %u %lf", &s->fmu, &s->vr, &s->value);
        } else if (!strcmp(key, "conn") && n_conns < MAX_ITEMS) {
            Conn *k = &conns[n_conns++];
            sscanf(line, "%*s %d %u %d %u", &k->src, &k->src_vr, &k->dst, &k->dst_vr);
        } else if (!strcmp(key, "out") && n_outs < MAX_ITEMS) {
            Out *o = &outs[n_outs++];
            sscanf(line, "%*s %d %u %95s", &o->fmu, &o->vr, o->column);
        } else if (!strcmp(key, "run")) {
            sscanf(line, "%*s %lf %lf %lf", &t0, &t1, &h);
        } else if (!strcmp(key, "hold_gil")) {
            sscanf(line, "%*s %d", &hold_gil);
        } else {
            fprintf(stderr, "host: cannot read config line: %s", line);
            return 2;
        }
    }
    fclose(cfg);

    /* Python 3.11+: a thread without a Python thread state gets a new one in every FMI call and loses
     * it on return.  Holding one here (from the preloaded libpython) makes every call reuse it. */
    int (*gil_ensure)(void) = NULL;
    void (*gil_release)(int) = NULL;
    int gil_state = 0;
    if (hold_gil) {
        gil_ensure = (int (*)(void))dlsym(RTLD_DEFAULT, "PyGILState_Ensure");
        gil_release = (void (*)(int))dlsym(RTLD_DEFAULT, "PyGILState_Release");
        if (!gil_ensure || !gil_release) {
            fprintf(stderr, "host: hold_gil needs libpython in the process (LD_PRELOAD)\n");
            return 3;
        }
        gil_state = gil_ensure();
    }

    for (int i = 0; i < n_fmus; i++)
        check(fmus[i].setupExperiment(fmus[i].c, fmi2False, 0.0, t0, fmi2False, 0.0), "setupExperiment", fmus[i].name);
    for (int i = 0; i < n_starts; i++) {
        Fmu *f = &fmus[starts[i].fmu];
        if (starts[i].is_int) {
            fmi2Integer v = (fmi2Integer)starts[i].value;
            check(f->setInteger(f->c, &starts[i].vr, 1, &v), "setInteger", f->name);
        } else {
            check(f->setReal(f->c, &starts[i].vr, 1, &starts[i].value), "setReal", f->name);
        }
    }
    for (int i = 0; i < n_fmus; i++)
        check(fmus[i].enterInitializationMode(fmus[i].c), "enterInitializationMode", fmus[i].name);

    double value;
    /* exchange: every connection in the listed order, get then set */
#define EXCHANGE()                                                                                   \
    for (int k = 0; k < n_conns; k++) {                                                              \
        Fmu *s = &fmus[conns[k].src], *d = &fmus[conns[k].dst];                                      \
        check(s->getReal(s->c, &conns[k].src_vr, 1, &value), "getReal", s->name);                   \
        check(d->setReal(d->c, &conns[k].dst_vr, 1, &value), "setReal", d->name);                    \
    }
    for (int pass = 0; pass < 3; pass++) { EXCHANGE() }  /* settle feedthrough chains at start */
    for (int i = 0; i < n_fmus; i++)
        check(fmus[i].exitInitializationMode(fmus[i].c), "exitInitializationMode", fmus[i].name);
    EXCHANGE()

    FILE *csv = fopen(argv[2], "w");
    if (!csv) {
        fprintf(stderr, "host: cannot write %s\n", argv[2]);
        return 2;
    }
    fprintf(csv, "time");
    for (int j = 0; j < n_outs; j++) fprintf(csv, ",%s", outs[j].column);
    fprintf(csv, "\n");
#define RECORD(T)                                                                                    \
    fprintf(csv, "%.17g", (T));                                                                      \
    for (int j = 0; j < n_outs; j++) {                                                               \
        Fmu *f = &fmus[outs[j].fmu];                                                                 \
        check(f->getReal(f->c, &outs[j].vr, 1, &value), "getReal", f->name);                         \
        fprintf(csv, ",%.17g", value);                                                               \
    }                                                                                                \
    fprintf(csv, "\n");
    RECORD(t0)

    long n_steps = (long)((t1 - t0) / h + 0.5);
    struct timespec w0, w1;
    clock_gettime(CLOCK_MONOTONIC, &w0);
    for (long n = 0; n < n_steps; n++) {
        double t = t0 + n * h;  /* the same communication points as cranefmu's master */
        for (int i = 0; i < n_fmus; i++)
            check(fmus[i].doStep(fmus[i].c, t, h, fmi2True), "doStep", fmus[i].name);
        EXCHANGE()
        RECORD(t0 + (n + 1) * h)
    }
    clock_gettime(CLOCK_MONOTONIC, &w1);
    fclose(csv);
    double seconds = (double)(w1.tv_sec - w0.tv_sec) + 1e-9 * (double)(w1.tv_nsec - w0.tv_nsec);
    printf("steps %ld seconds_per_step %.9g\n", n_steps, n_steps ? seconds / (double)n_steps : 0.0);

    if (hold_gil) gil_release(gil_state);
    /* every instance is terminated and freed before exit: pythonfmu corrupts the heap at exit otherwise */
    int freed = 0;
    for (int i = 0; i < n_fmus; i++) {
        check(fmus[i].terminate(fmus[i].c), "terminate", fmus[i].name);
        fmus[i].freeInstance(fmus[i].c);
        freed++;
    }
    printf("freed %d instances\n", freed);
    fflush(stdout);
    return 0;
}
