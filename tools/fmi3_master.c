/* A small FMI 3.0 co-simulation master for checking the FMU's binaries on Linux and, through
 * wine, Windows (the 3.0 twin of fmi_master.c, same scenario and output): no FMI library.
 *
 *   fmi3_master <library> <resource-path> <cache-dir> <value-references> <relative-tolerance>
 *               <gas-forces 0|1>
 *
 * (value references, comma separated: scene, rpm, chassis.cacheDir, solver.relTol,
 * effects.gasForces, then the arrays mount.F [4,3], steeringWheel.a [3], seat.a [3], whose 18
 * values are printed; the instantiation token, the GUID, comes from the environment variable
 * FMU_GUID.)
 *
 * Runs scene 1 for 1 s and scene 2 for 0.2 s at 2000 rpm with 1 ms communication steps, checks
 * fmi3DoStep's out-arguments, takes an FMU state half-way, serializes and deserializes it,
 * restores it and checks the continuation repeats, then frees everything. Prints one CSV line
 * per 10 ms: scene, time, the 18 output values. Exit status 0 on success. */
#include <stdbool.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#define LOAD(path) ((void *)LoadLibraryA(path))
#define SYM(lib, name) ((void *)GetProcAddress((HMODULE)(lib), name))
#else
#include <dlfcn.h>
#define LOAD(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYM(lib, name) dlsym(lib, name)
#endif

/* FMI 3.0 types (fmi3PlatformTypes.h, fmi3FunctionTypes.h). */
typedef void *fmi3Instance;
typedef void *fmi3InstanceEnvironment;
typedef void *fmi3FMUState;
typedef uint32_t fmi3ValueReference;
typedef double fmi3Float64;
typedef int32_t fmi3Int32;
typedef bool fmi3Boolean;
typedef const char *fmi3String;
typedef uint8_t fmi3Byte;
typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);

typedef fmi3Instance (*Instantiate)(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                    fmi3Boolean, fmi3Boolean, const fmi3ValueReference *, size_t,
                                    fmi3InstanceEnvironment, fmi3LogMessageCallback, void *);
typedef void (*FreeInstance)(fmi3Instance);
typedef fmi3Status (*EnterInit)(fmi3Instance, fmi3Boolean, fmi3Float64, fmi3Float64, fmi3Boolean,
                                fmi3Float64);
typedef fmi3Status (*Plain)(fmi3Instance);
typedef fmi3Status (*GetFloat64)(fmi3Instance, const fmi3ValueReference *, size_t, fmi3Float64 *,
                                 size_t);
typedef fmi3Status (*SetFloat64)(fmi3Instance, const fmi3ValueReference *, size_t,
                                 const fmi3Float64 *, size_t);
typedef fmi3Status (*SetInt32)(fmi3Instance, const fmi3ValueReference *, size_t, const fmi3Int32 *,
                               size_t);
typedef fmi3Status (*SetBoolean)(fmi3Instance, const fmi3ValueReference *, size_t,
                                 const fmi3Boolean *, size_t);
typedef fmi3Status (*SetString)(fmi3Instance, const fmi3ValueReference *, size_t,
                                const fmi3String *, size_t);
typedef fmi3Status (*DoStep)(fmi3Instance, fmi3Float64, fmi3Float64, fmi3Boolean, fmi3Boolean *,
                             fmi3Boolean *, fmi3Boolean *, fmi3Float64 *);
typedef fmi3Status (*GetState)(fmi3Instance, fmi3FMUState *);
typedef fmi3Status (*SetState)(fmi3Instance, fmi3FMUState);
typedef fmi3Status (*FreeState)(fmi3Instance, fmi3FMUState *);
typedef fmi3Status (*StateSize)(fmi3Instance, fmi3FMUState, size_t *);
typedef fmi3Status (*Serialize)(fmi3Instance, fmi3FMUState, fmi3Byte *, size_t);
typedef fmi3Status (*Deserialize)(fmi3Instance, const fmi3Byte *, size_t, fmi3FMUState *);

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                   fmi3String message) {
  (void)env;
  fprintf(stderr, "[%d %s] %s\n", (int)status, category, message);
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
    fmi3Status s_ = (call);                                                         \
    if (s_ != fmi3OK) {                                                             \
      fprintf(stderr, "%s failed with status %d (line %d)\n", #call, (int)s_, __LINE__); \
      exit(3);                                                                      \
    }                                                                               \
  } while (0)

/* One communication step; its out-arguments must say: no event, no termination, no early
 * return, the whole step done (up to the FMU's 1 ps grid of communication points). */
static void step(DoStep do_step, fmi3Instance c, double t, double h) {
  fmi3Boolean event = true, terminate = true, early = true;
  fmi3Float64 last = -1.0;
  CHECK(do_step(c, t, h, true, &event, &terminate, &early, &last));
  if (event || terminate || early || fabs(last - (t + h)) > 1e-12) {
    fprintf(stderr, "fmi3DoStep at %g: event %d terminate %d early %d lastSuccessfulTime %.17g\n",
            t, event, terminate, early, last);
    exit(5);
  }
}

int main(int argc, char **argv) {
  /* Rows unbuffered: a run that dies leaves what it wrote, so a test can tell how far it got. */
  setvbuf(stdout, NULL, _IONBF, 0);
  if (argc != 7) {
    fprintf(stderr, "usage: fmi3_master <library> <resource-path> <cache-dir> <value-references> "
                    "<relative-tolerance> <gas-forces 0|1>\n");
    return 1;
  }
  unsigned vr[8];
  int nvr = 0;
  for (char *tok = strtok(argv[4], ","); tok && nvr < 8; tok = strtok(NULL, ",")) {
    vr[nvr++] = (unsigned)strtoul(tok, NULL, 10);
  }
  if (nvr != 8) {
    fprintf(stderr, "need 8 value references, got %d\n", nvr);
    return 1;
  }
  const double rel_tol = strtod(argv[5], NULL);
  const fmi3Boolean gas = atoi(argv[6]) != 0;
  void *lib = LOAD(argv[1]);
  if (!lib) {
    fprintf(stderr, "cannot load %s\n", argv[1]);
    return 2;
  }
  Instantiate instantiate = (Instantiate)need(lib, "fmi3InstantiateCoSimulation");
  FreeInstance free_instance = (FreeInstance)need(lib, "fmi3FreeInstance");
  EnterInit enter = (EnterInit)need(lib, "fmi3EnterInitializationMode");
  Plain exit_init = (Plain)need(lib, "fmi3ExitInitializationMode");
  Plain terminate = (Plain)need(lib, "fmi3Terminate");
  GetFloat64 get_float64 = (GetFloat64)need(lib, "fmi3GetFloat64");
  SetFloat64 set_float64 = (SetFloat64)need(lib, "fmi3SetFloat64");
  SetInt32 set_int32 = (SetInt32)need(lib, "fmi3SetInt32");
  SetBoolean set_boolean = (SetBoolean)need(lib, "fmi3SetBoolean");
  SetString set_string = (SetString)need(lib, "fmi3SetString");
  DoStep do_step = (DoStep)need(lib, "fmi3DoStep");
  GetState get_state = (GetState)need(lib, "fmi3GetFMUState");
  SetState set_state = (SetState)need(lib, "fmi3SetFMUState");
  FreeState free_state = (FreeState)need(lib, "fmi3FreeFMUState");
  StateSize state_size = (StateSize)need(lib, "fmi3SerializedFMUStateSize");
  Serialize serialize = (Serialize)need(lib, "fmi3SerializeFMUState");
  Deserialize deserialize = (Deserialize)need(lib, "fmi3DeserializeFMUState");
  const char *token = getenv("FMU_GUID");
  const double h = 1e-3;
  for (int scene = 1; scene <= 2; scene++) {
    const double duration = scene == 1 ? 1.0 : 0.2;
    const int steps = (int)(duration / h + 0.5);
    fmi3Instance c = instantiate("master", token ? token : "", argv[2], false, false, false, false,
                                 NULL, 0, NULL, logger, NULL);
    if (!c) {
      fprintf(stderr, "fmi3InstantiateCoSimulation returned NULL\n");
      return 3;
    }
    fmi3Int32 scene_value = scene;
    fmi3Float64 rpm = 2000.0;
    fmi3String cache = argv[3];
    CHECK(set_int32(c, &vr[0], 1, &scene_value, 1));
    CHECK(set_float64(c, &vr[1], 1, &rpm, 1));
    CHECK(set_string(c, &vr[2], 1, &cache, 1));
    CHECK(set_float64(c, &vr[3], 1, &rel_tol, 1));
    CHECK(set_boolean(c, &vr[4], 1, &gas, 1));
    CHECK(enter(c, false, 0.0, 0.0, false, 0.0));
    CHECK(exit_init(c));
    fmi3FMUState saved = NULL;
    double reference[18];
    int half = steps / 2;
    for (int k = 0; k < steps; k++) {
      step(do_step, c, k * h, h);
      double out[18];
      CHECK(get_float64(c, &vr[5], 3, out, 18));
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
    fmi3Byte *bytes = malloc(size);
    CHECK(serialize(c, saved, bytes, size));
    fmi3FMUState copy = NULL;
    CHECK(deserialize(c, bytes, size, &copy));
    free(bytes);
    CHECK(set_state(c, copy));
    double out[18];
    for (int k = half; k < steps; k++) step(do_step, c, k * h, h);
    CHECK(get_float64(c, &vr[5], 3, out, 18));
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
