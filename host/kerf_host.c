/*
 * kerf_host: a bare C host that measures the cost of kerf through FMI 2.0,
 * scene by scene.
 *
 * It dlopens the kerf shared library (target/release/libkerf.so or the
 * binary inside kerf.fmu), finds the value references by reading
 * modelDescription.xml with a tiny parser, and replays scene files as
 * Co-Simulation: for every row, fmi2SetReal of the 12 pose and velocity
 * inputs, one fmi2DoStep of 1 ms, fmi2GetReal of the forces. The rows are a
 * scene of `kerf::scenes` (a fresh cut, a tilted disc spinning about its own
 * axle, a pass beside a groove, a lap of a curved track, ...), written by
 * `examples/speed-vs-error.rs --host-scenes DIR`, so the host drives exactly
 * the passes the core's report measures.
 *
 * For each scene it prints one JSON line: median and quartiles of the wall
 * time of fmi2DoStep alone and of a whole step (fmi2SetReal + fmi2DoStep +
 * fmi2GetReal) over the rows marked timed, in microseconds, over `reps`
 * runs (each run replays every scene once, so load from other processes
 * falls on all scenes alike), and the mean forces over those rows.
 *
 * Build (scripts/speed-vs-error does this):
 *   cc -O2 -std=c11 -o target/speed-vs-error/kerf_host host/kerf_host.c -ldl
 * Run:
 *   kerf_host LIB.so modelDescription.xml REPS SCENE_FILE...
 *
 * Scene file, one item a line ('#' starts a comment line):
 *   name TEXT                      the scene's name
 *   param NAME VALUE               a Real or Integer parameter (type from the XML)
 *   step TIMED x y z yaw pitch roll vx vy vz wx wy wz
 *                                  one communication point: the inputs at t,
 *                                  then fmi2DoStep(t, 1 ms); TIMED 1 or 0
 *
 * The few fmi2 types and prototypes are declared here (they match
 * fmi2TypesPlatform.h / fmi2FunctionTypes.h of the FMI 2.0 standard), so no
 * header is needed.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;

typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*Instantiate_t)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                       const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment_t)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real,
                                        fmi2Boolean, fmi2Real);
typedef fmi2Status (*Component_t)(fmi2Component);
typedef void (*FreeInstance_t)(fmi2Component);
typedef fmi2Status (*SetReal_t)(fmi2Component, const fmi2ValueReference *, size_t,
                                const fmi2Real *);
typedef fmi2Status (*SetInteger_t)(fmi2Component, const fmi2ValueReference *, size_t,
                                   const fmi2Integer *);
typedef fmi2Status (*GetReal_t)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*DoStep_t)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env;
    if (status == fmi2OK) return;
    va_list ap;
    va_start(ap, message);
    fprintf(stderr, "[%s] %s (status %d): ", name ? name : "?", category ? category : "?",
            (int)status);
    vfprintf(stderr, message, ap);
    fputc('\n', stderr);
    va_end(ap);
}

static void die(const char *what, const char *detail) {
    fprintf(stderr, "kerf_host: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    exit(1);
}

static void *sym(void *lib, const char *name) {
    void *p = dlsym(lib, name);
    if (!p) die("missing symbol", name);
    return p;
}

static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) die("cannot read", path);
    buf[n] = 0;
    fclose(f);
    return buf;
}

/* Copies the value of attribute `attr` (e.g. `name`) found in [tag, end) into
 * out; returns 0 when it is absent. Matches ` name="` so that `modelName=` is
 * not taken for `name=`. */
static int attr_value(const char *tag, const char *end, const char *attr, char *out, size_t cap) {
    char key[64];
    snprintf(key, sizeof key, " %s=\"", attr);
    size_t klen = strlen(key);
    for (const char *p = tag; p + klen < end; p++) {
        /* attributes may also follow a newline or tab */
        if ((p[0] == ' ' || p[0] == '\n' || p[0] == '\t' || p[0] == '\r') &&
            strncmp(p + 1, key + 1, klen - 1) == 0) {
            const char *v = p + klen;
            const char *q = memchr(v, '"', (size_t)(end - v));
            if (!q || (size_t)(q - v) >= cap) return 0;
            memcpy(out, v, (size_t)(q - v));
            out[q - v] = 0;
            return 1;
        }
    }
    return 0;
}

/* Value reference of the ScalarVariable called `name`; *is_int tells whether
 * it is an Integer (else a Real, Boolean or Enumeration is not asked for). */
static fmi2ValueReference var_of(const char *xml, const char *name, int *is_int) {
    const char *p = xml;
    char buf[256];
    while ((p = strstr(p, "<ScalarVariable")) != NULL) {
        const char *end = strchr(p, '>');
        if (!end) break;
        if (attr_value(p, end, "name", buf, sizeof buf) && strcmp(buf, name) == 0) {
            if (!attr_value(p, end, "valueReference", buf, sizeof buf))
                die("no valueReference for", name);
            if (is_int) {
                const char *close = strstr(end, "</ScalarVariable>");
                const char *ip = strstr(end, "<Integer");
                *is_int = ip && (!close || ip < close);
            }
            return (fmi2ValueReference)strtoul(buf, NULL, 10);
        }
        p = end;
    }
    die("no ScalarVariable named", name);
    return 0;
}

static double now_us(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e6 + ts.tv_nsec * 1e-3;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double quantile(double *v, size_t n, double q) {
    if (n == 0) return 0.0;
    qsort(v, n, sizeof *v, cmp_double);
    double x = q * (double)(n - 1);
    size_t i = (size_t)x;
    double f = x - (double)i;
    return i + 1 < n ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

enum { NIN = 12, NOUT = 3, MAXPAR = 16 };
static const char *in_names[NIN] = {"x",  "y",  "z",  "yaw", "pitch", "roll",
                                    "vx", "vy", "vz", "wx",  "wy",    "wz"};
static const char *out_names[NOUT] = {"normalForce", "rollingForce", "sideForce"};

typedef struct {
    char name[128];
    int npar;
    fmi2ValueReference par_vr[MAXPAR];
    int par_int[MAXPAR];
    double par_val[MAXPAR];
    size_t nrows, ntimed;
    double *rows; /* nrows x NIN */
    int *timed;
    double *t_do, *t_all; /* ntimed x reps */
    size_t k;
    double sum[NOUT];
} Scene;

static void load_scene(Scene *sc, const char *path, const char *xml) {
    char *text = read_file(path);
    memset(sc, 0, sizeof *sc);
    snprintf(sc->name, sizeof sc->name, "%s", path);
    size_t cap = 1024;
    sc->rows = malloc(cap * NIN * sizeof *sc->rows);
    sc->timed = malloc(cap * sizeof *sc->timed);
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, "name ", 5) == 0) {
            snprintf(sc->name, sizeof sc->name, "%s", line + 5);
        } else if (strncmp(line, "param ", 6) == 0) {
            char pname[128];
            double v;
            if (sscanf(line + 6, "%127s %lf", pname, &v) != 2) die("bad param line in", path);
            if (sc->npar == MAXPAR) die("too many params in", path);
            sc->par_vr[sc->npar] = var_of(xml, pname, &sc->par_int[sc->npar]);
            sc->par_val[sc->npar++] = v;
        } else if (strncmp(line, "step ", 5) == 0) {
            if (sc->nrows == cap) {
                cap *= 2;
                sc->rows = realloc(sc->rows, cap * NIN * sizeof *sc->rows);
                sc->timed = realloc(sc->timed, cap * sizeof *sc->timed);
                if (!sc->rows || !sc->timed) die("out of memory", NULL);
            }
            char *p = line + 5, *q;
            sc->timed[sc->nrows] = (int)strtol(p, &q, 10);
            for (int j = 0; j < NIN; j++) {
                p = q;
                sc->rows[sc->nrows * NIN + j] = strtod(p, &q);
                if (q == p) die("bad step line in", path);
            }
            sc->ntimed += sc->timed[sc->nrows] != 0;
            sc->nrows++;
        } else if (line[0] != '#' && line[0] != 0) {
            die("unknown line in", path);
        }
    }
    if (sc->nrows == 0 || sc->ntimed == 0) die("no (timed) steps in", path);
    free(text);
}

int main(int argc, char **argv) {
    if (argc < 5) {
        fprintf(stderr, "usage: kerf_host LIB.so modelDescription.xml REPS SCENE_FILE...\n");
        return 2;
    }
    const char *lib_path = argv[1];
    const char *xml_path = argv[2];
    int reps = atoi(argv[3]);
    if (reps < 1) die("reps must be positive", argv[3]);
    int nsc = argc - 4;

    char *xml = read_file(xml_path);
    char guid[128];
    const char *md = strstr(xml, "<fmiModelDescription");
    if (!md || !attr_value(md, strchr(md, '>'), "guid", guid, sizeof guid))
        die("no guid in", xml_path);
    fmi2ValueReference in_vr[NIN], out_vr[NOUT];
    for (int k = 0; k < NIN; k++) in_vr[k] = var_of(xml, in_names[k], NULL);
    for (int k = 0; k < NOUT; k++) out_vr[k] = var_of(xml, out_names[k], NULL);
    Scene *scenes = calloc((size_t)nsc, sizeof *scenes);
    for (int i = 0; i < nsc; i++) {
        load_scene(&scenes[i], argv[4 + i], xml);
        scenes[i].t_do = malloc(scenes[i].ntimed * (size_t)reps * sizeof(double));
        scenes[i].t_all = malloc(scenes[i].ntimed * (size_t)reps * sizeof(double));
    }

    void *lib = dlopen(lib_path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) die("dlopen failed", dlerror());
    Instantiate_t instantiate = (Instantiate_t)sym(lib, "fmi2Instantiate");
    SetupExperiment_t setup = (SetupExperiment_t)sym(lib, "fmi2SetupExperiment");
    Component_t enter_init = (Component_t)sym(lib, "fmi2EnterInitializationMode");
    Component_t exit_init = (Component_t)sym(lib, "fmi2ExitInitializationMode");
    SetReal_t set_real = (SetReal_t)sym(lib, "fmi2SetReal");
    SetInteger_t set_int = (SetInteger_t)sym(lib, "fmi2SetInteger");
    GetReal_t get_real = (GetReal_t)sym(lib, "fmi2GetReal");
    DoStep_t do_step = (DoStep_t)sym(lib, "fmi2DoStep");
    FreeInstance_t free_instance = (FreeInstance_t)sym(lib, "fmi2FreeInstance");

    const double h = 1e-3;
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    /* rep -1 is a warm-up of the first scene, not recorded: the first run in
     * a process pays for page faults and cold caches, and the first scene is
     * the straight cut every ratio divides by */
    for (int rep = -1; rep < reps; rep++) {
        for (int i = 0; i < (rep < 0 ? 1 : nsc); i++) {
            Scene *sc = &scenes[i];
            fmi2Component c = instantiate("kerf_host", fmi2CoSimulation, guid, NULL, &cb, 0, 0);
            if (!c) die("fmi2Instantiate failed", sc->name);
            for (int j = 0; j < sc->npar; j++) {
                fmi2Status st;
                if (sc->par_int[j]) {
                    fmi2Integer v = (fmi2Integer)sc->par_val[j];
                    st = set_int(c, &sc->par_vr[j], 1, &v);
                } else {
                    st = set_real(c, &sc->par_vr[j], 1, &sc->par_val[j]);
                }
                if (st > fmi2Warning) die("setting a parameter failed", sc->name);
            }
            if (setup(c, 0, 0.0, 0.0, 0, 0.0) > fmi2Warning) die("fmi2SetupExperiment failed", NULL);
            if (enter_init(c) > fmi2Warning) die("fmi2EnterInitializationMode failed", NULL);
            if (set_real(c, in_vr, NIN, sc->rows) > fmi2Warning) die("fmi2SetReal failed", NULL);
            if (exit_init(c) > fmi2Warning) die("fmi2ExitInitializationMode failed", sc->name);
            double out[NOUT];
            for (size_t s = 0; s < sc->nrows; s++) {
                double t = (double)s * h;
                const double *in = sc->rows + s * NIN;
                double t0 = now_us();
                if (set_real(c, in_vr, NIN, in) > fmi2Warning) die("fmi2SetReal failed", sc->name);
                double t1 = now_us();
                if (do_step(c, t, h, 1) > fmi2Warning) die("fmi2DoStep failed", sc->name);
                double t2 = now_us();
                if (get_real(c, out_vr, NOUT, out) > fmi2Warning) die("fmi2GetReal failed", sc->name);
                double t3 = now_us();
                if (rep >= 0 && sc->timed[s]) {
                    sc->t_do[sc->k] = t2 - t1;
                    sc->t_all[sc->k] = t3 - t0;
                    sc->k++;
                    for (int j = 0; j < NOUT; j++) sc->sum[j] += out[j];
                }
            }
            free_instance(c);
        }
    }
    for (int i = 0; i < nsc; i++) {
        Scene *sc = &scenes[i];
        size_t n = sc->k;
        printf("{\"kind\": \"host\", \"scene\": \"%s\", \"library\": \"%s\", \"reps\": %d, "
               "\"timed_steps\": %zu, \"steps\": %zu, \"step_s\": %g, "
               "\"dostep_us_median\": %.3f, \"dostep_us_p25\": %.3f, \"dostep_us_p75\": %.3f, "
               "\"dostep_us_min\": %.3f, \"step_us_median\": %.3f, \"step_us_p25\": %.3f, "
               "\"step_us_p75\": %.3f, \"mean_normal\": %.1f, \"mean_rolling\": %.1f, "
               "\"mean_side\": %.1f}\n",
               sc->name, lib_path, reps, sc->ntimed, sc->nrows, h, quantile(sc->t_do, n, 0.5),
               quantile(sc->t_do, n, 0.25), quantile(sc->t_do, n, 0.75),
               quantile(sc->t_do, n, 0.0), quantile(sc->t_all, n, 0.5),
               quantile(sc->t_all, n, 0.25), quantile(sc->t_all, n, 0.75), sc->sum[0] / (double)n,
               sc->sum[1] / (double)n, sc->sum[2] / (double)n);
        free(sc->rows);
        free(sc->timed);
        free(sc->t_do);
        free(sc->t_all);
    }
    free(scenes);
    free(xml);
    dlclose(lib);
    return 0;
}
