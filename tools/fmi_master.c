/* A small FMI 2.0 co-simulation master for checking the FMU's binaries on Linux and, through
 * wine, Windows: the same C source for both, no FMI library.
 *
 *   fmi_master <library> <resources-uri> <cache-dir> <value-references> <relative-tolerance>
 *              <gas-forces 0|1>
 *
 * (value references, comma separated: scene, rpm, chassis.cacheDir, solver.relTol,
 * effects.gasForces, then the 18 outputs printed; the GUID comes from the environment variable
 * FMU_GUID.)
 *
 * Runs scene 1 for 1 s and scene 2 for 0.2 s at 2000 rpm with 1 ms communication steps, takes
 * an FMU state half-way, serializes and deserializes it, restores it and checks the continuation
 * repeats, then frees everything. Prints one CSV line per 10 ms: scene, time, the twelve mount
 * forces, steering-wheel and seat accelerations. Exit status 0 on success. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdarg.h>
#ifdef _WIN32
#include <windows.h>
#define LOAD(path) ((void *)LoadLibraryA(path))
#define SYM(lib, name) ((void *)GetProcAddress((HMODULE)(lib), name))
#else
#include <dlfcn.h>
#define LOAD(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYM(lib, name) dlsym(lib, name)
#endif

/* FMI 2.0 types (fmi2TypesPlatform.h, fmi2FunctionTypes.h). */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef struct {
  fmi2CallbackLogger logger;
  void *(*allocateMemory)(size_t, size_t);
  void (*freeMemory)(void *);
  void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
  fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef void (*FreeInstance)(fmi2Component);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean,
                                      fmi2Real);
typedef fmi2Status (*Plain)(fmi2Component);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*SetInteger)(fmi2Component, const fmi2ValueReference *, size_t,
                                 const fmi2Integer *);
typedef fmi2Status (*SetBoolean)(fmi2Component, const fmi2ValueReference *, size_t,
                                 const fmi2Boolean *);
typedef fmi2Status (*SetString)(fmi2Component, const fmi2ValueReference *, size_t,
                                const fmi2String *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status (*GetState)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*SetState)(fmi2Component, fmi2FMUstate);
typedef fmi2Status (*FreeState)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*StateSize)(fmi2Component, fmi2FMUstate, size_t *);
typedef fmi2Status (*Serialize)(fmi2Component, fmi2FMUstate, fmi2Byte *, size_t);
typedef fmi2Status (*Deserialize)(fmi2Component, const fmi2Byte *, size_t, fmi2FMUstate *);

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
  va_list args;
  (void)env;
  fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
  va_start(args, message);
  vfprintf(stderr, message, args);
  va_end(args);
  fprintf(stderr, "\n");
}

static void *need(void *lib, const char *name) {
  void *f = SYM(lib, name);
  if (!f) {
    fprintf(stderr, "missing export %s\n", name);
    exit(2);
  }
  return f;
}

#define CHECK(call)                                                                 \
  do {                                                                              \
    fmi2Status s_ = (call);                                                         \
    if (s_ != fmi2OK) {                                                             \
      fprintf(stderr, "%s failed with status %d (line %d)\n", #call, (int)s_, __LINE__); \
      exit(3);                                                                      \
    }                                                                               \
  } while (0)

int main(int argc, char **argv) {
  /* Rows unbuffered: a run that dies leaves what it wrote, so a test can tell how far it got. */
  setvbuf(stdout, NULL, _IONBF, 0);
  if (argc != 7) {
    fprintf(stderr, "usage: fmi_master <library> <resources-uri> <cache-dir> <value-references> "
                    "<relative-tolerance> <gas-forces 0|1>\n");
    return 1;
  }
  unsigned vr[23];
  int nvr = 0;
  for (char *tok = strtok(argv[4], ","); tok && nvr < 23; tok = strtok(NULL, ",")) {
    vr[nvr++] = (unsigned)strtoul(tok, NULL, 10);
  }
  if (nvr != 23) {
    fprintf(stderr, "need 23 value references, got %d\n", nvr);
    return 1;
  }
  const double rel_tol = strtod(argv[5], NULL);
  const fmi2Boolean gas = atoi(argv[6]) != 0;
  void *lib = LOAD(argv[1]);
  if (!lib) {
    fprintf(stderr, "cannot load %s\n", argv[1]);
    return 2;
  }
  Instantiate instantiate = (Instantiate)need(lib, "fmi2Instantiate");
  FreeInstance free_instance = (FreeInstance)need(lib, "fmi2FreeInstance");
  SetupExperiment setup = (SetupExperiment)need(lib, "fmi2SetupExperiment");
  Plain enter = (Plain)need(lib, "fmi2EnterInitializationMode");
  Plain exit_init = (Plain)need(lib, "fmi2ExitInitializationMode");
  Plain terminate = (Plain)need(lib, "fmi2Terminate");
  GetReal get_real = (GetReal)need(lib, "fmi2GetReal");
  SetReal set_real = (SetReal)need(lib, "fmi2SetReal");
  SetInteger set_integer = (SetInteger)need(lib, "fmi2SetInteger");
  SetBoolean set_boolean = (SetBoolean)need(lib, "fmi2SetBoolean");
  SetString set_string = (SetString)need(lib, "fmi2SetString");
  DoStep do_step = (DoStep)need(lib, "fmi2DoStep");
  GetState get_state = (GetState)need(lib, "fmi2GetFMUstate");
  SetState set_state = (SetState)need(lib, "fmi2SetFMUstate");
  FreeState free_state = (FreeState)need(lib, "fmi2FreeFMUstate");
  StateSize state_size = (StateSize)need(lib, "fmi2SerializedFMUstateSize");
  Serialize serialize = (Serialize)need(lib, "fmi2SerializeFMUstate");
  Deserialize deserialize = (Deserialize)need(lib, "fmi2DeSerializeFMUstate");
  const char *guid = getenv("FMU_GUID");
  fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
  const double h = 1e-3;
  for (int scene = 1; scene <= 2; scene++) {
    const double duration = scene == 1 ? 1.0 : 0.2;
    const int steps = (int)(duration / h + 0.5);
    fmi2Component c = instantiate("master", fmi2CoSimulation, guid ? guid : "", argv[2],
                                  &callbacks, 0, 0);
    if (!c) {
      fprintf(stderr, "fmi2Instantiate returned NULL\n");
      return 3;
    }
    fmi2Integer scene_value = scene;
    fmi2Real rpm = 2000.0;
    fmi2String cache = argv[3];
    CHECK(set_integer(c, &vr[0], 1, &scene_value));
    CHECK(set_real(c, &vr[1], 1, &rpm));
    CHECK(set_string(c, &vr[2], 1, &cache));
    CHECK(set_real(c, &vr[3], 1, &rel_tol));
    CHECK(set_boolean(c, &vr[4], 1, &gas));
    CHECK(setup(c, 0, 0.0, 0.0, 0, 0.0));
    CHECK(enter(c));
    CHECK(exit_init(c));
    fmi2FMUstate saved = NULL;
    double reference[18];
    int half = steps / 2;
    for (int k = 0; k < steps; k++) {
      CHECK(do_step(c, k * h, h, 1));
      double out[18];
      CHECK(get_real(c, &vr[5], 18, out));
      if (k + 1 == half) {
        CHECK(get_state(c, &saved));
      }
      if ((k + 1) % 10 == 0) {
        printf("%d,%.3f", scene, (k + 1) * h);
        for (int i = 0; i < 18; i++) printf(",%.17g", out[i]);
        printf("\n");
      }
      if (k + 1 == steps) memcpy(reference, out, sizeof reference);
    }
    /* Back to the saved state through a serialized copy: the continuation must repeat. */
    size_t size = 0;
    CHECK(state_size(c, saved, &size));
    fmi2Byte *bytes = malloc(size);
    CHECK(serialize(c, saved, bytes, size));
    fmi2FMUstate copy = NULL;
    CHECK(deserialize(c, bytes, size, &copy));
    free(bytes);
    CHECK(set_state(c, copy));
    double out[18];
    for (int k = half; k < steps; k++) CHECK(do_step(c, k * h, h, 1));
    CHECK(get_real(c, &vr[5], 18, out));
    for (int i = 0; i < 18; i++) {
      if (out[i] != reference[i]) {
        fprintf(stderr, "scene %d: output %d after restoring the state: %.17g vs %.17g\n", scene,
                i, out[i], reference[i]);
        return 4;
      }
    }
    CHECK(free_state(c, &saved));
    CHECK(free_state(c, &copy));
    CHECK(terminate(c));
    free_instance(c);
  }
  return 0;
}
