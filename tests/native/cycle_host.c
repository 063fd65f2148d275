/* A plain FMI 2.0 C host for the native FMUs' drop-in test (tests/native/test_drop_in.py): no Python in
   the process.  It loads one FMU binary with dlopen and runs instantiate/free cycles, each: instantiate,
   setup, initialize, steps with an FMU state saved, serialized, deserialized and restored (the replayed
   step must give the same bits), terminate, free.  Then the failure paths: a wrong GUID (NULL), a
   refused parameter (fmi2ExitInitializationMode returns an error, the instance is freed).
   Usage: cycle_host UNZIPDIR IDENTIFIER GUID CYCLES OUTPUT_VR BAD_REAL_VR BAD_VALUE
   Exit 0 when every call did what it should; prints "cycles N ok". */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static int n_errors_logged;

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    (void)category;
    if (status >= fmi2Error) n_errors_logged++;
    fprintf(stderr, "[%s] %d %s\n", instance ? instance : "?", (int)status, message ? message : "");
}

#define LOAD(name) fmi2##name##TYPE *name = (fmi2##name##TYPE *)dlsym(lib, "fmi2" #name); \
    if (!name) { fprintf(stderr, "no fmi2" #name "\n"); return 3; }
#define EXPECT(cond, what) if (!(cond)) { fprintf(stderr, "cycle %d: %s\n", cycle, what); return 4; }

int main(int argc, char **argv) {
    if (argc != 8) {
        fprintf(stderr, "usage: cycle_host UNZIPDIR IDENTIFIER GUID CYCLES OUTPUT_VR BAD_REAL_VR BAD_VALUE\n");
        return 2;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", argv[1], argv[2]);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen %s: %s\n", path, dlerror());
        return 3;
    }
    LOAD(Instantiate) LOAD(FreeInstance) LOAD(SetupExperiment) LOAD(EnterInitializationMode)
    LOAD(ExitInitializationMode) LOAD(Terminate) LOAD(GetReal) LOAD(SetReal) LOAD(DoStep) LOAD(GetFMUstate)
    LOAD(SetFMUstate) LOAD(FreeFMUstate) LOAD(SerializedFMUstateSize) LOAD(SerializeFMUstate)
    LOAD(DeSerializeFMUstate)
    const char *guid = argv[3];
    int cycles = atoi(argv[4]), cycle = 0;
    fmi2ValueReference out = (fmi2ValueReference)atoi(argv[5]), bad_vr = (fmi2ValueReference)atoi(argv[6]);
    double bad_value = atof(argv[7]), h = 1e-3;
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

    for (cycle = 0; cycle < cycles; cycle++) {
        fmi2Component c = Instantiate("cycle", fmi2CoSimulation, guid, "file:///tmp", &callbacks, fmi2False, fmi2False);
        EXPECT(c, "fmi2Instantiate returned NULL");
        EXPECT(SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK, "setup");
        EXPECT(EnterInitializationMode(c) == fmi2OK, "enter initialization");
        EXPECT(ExitInitializationMode(c) == fmi2OK, "exit initialization");
        fmi2FMUstate saved = NULL, restored = NULL;
        double y1 = 0.0, y2 = 1.0;
        for (int k = 0; k < 20; k++) {
            if (k == 10) {
                size_t size = 0;
                EXPECT(GetFMUstate(c, &saved) == fmi2OK, "get state");
                EXPECT(SerializedFMUstateSize(c, saved, &size) == fmi2OK && size > 0, "state size");
                fmi2Byte *bytes = (fmi2Byte *)malloc(size);
                EXPECT(bytes && SerializeFMUstate(c, saved, bytes, size) == fmi2OK, "serialize");
                EXPECT(DeSerializeFMUstate(c, bytes, size, &restored) == fmi2OK, "deserialize");
                free(bytes);
            }
            EXPECT(DoStep(c, k * h, h, fmi2True) == fmi2OK, "doStep");
            if (k == 10) EXPECT(GetReal(c, &out, 1, &y1) == fmi2OK, "getReal");
        }
        EXPECT(SetFMUstate(c, restored) == fmi2OK, "set state");
        EXPECT(DoStep(c, 10 * h, h, fmi2True) == fmi2OK && GetReal(c, &out, 1, &y2) == fmi2OK, "replay");
        EXPECT(memcmp(&y1, &y2, sizeof y1) == 0, "the replayed step differs from the first");
        EXPECT(FreeFMUstate(c, &saved) == fmi2OK && FreeFMUstate(c, &restored) == fmi2OK && !saved, "free states");
        EXPECT(Terminate(c) == fmi2OK, "terminate");
        FreeInstance(c);
    }
    /* failure paths */
    n_errors_logged = 0;
    EXPECT(Instantiate("wrong", fmi2CoSimulation, "{not-this-guid}", "", &callbacks, fmi2False, fmi2False) == NULL,
           "a wrong GUID was accepted");
    EXPECT(Instantiate("me", fmi2ModelExchange, guid, "", &callbacks, fmi2False, fmi2False) == NULL,
           "model exchange was accepted");
    fmi2Component c = Instantiate("refused", fmi2CoSimulation, guid, "", &callbacks, fmi2False, fmi2False);
    EXPECT(c, "instantiate for the refused parameter");
    EXPECT(SetReal(c, &bad_vr, 1, &bad_value) == fmi2OK, "set the bad value before initialization");
    EXPECT(EnterInitializationMode(c) == fmi2OK, "enter initialization with a bad value (reported at exit)");
    EXPECT(ExitInitializationMode(c) == fmi2Error, "the bad value was not refused");
    EXPECT(DoStep(c, 0.0, h, fmi2True) == fmi2Error, "a step after a refused initialization");
    FreeInstance(c);
    EXPECT(n_errors_logged == 4, "not one logged line per failure");
    dlclose(lib);
    printf("cycles %d ok\n", cycles);
    return 0;
}
