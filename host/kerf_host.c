/*
 * kerf_host: a bare C host that measures the cost of the FMI 2.0 layer.
 *
 * It dlopens the kerf shared library (target/release/libkerf.so or the
 * binary inside kerf.fmu), finds the value references by reading
 * modelDescription.xml with a tiny parser, and drives the reference cut of
 * thesis Table 2 as Co-Simulation: 1000 fmi2DoStep of 1 ms at vx = 1 m/s,
 * wy = 1/R, the pose inputs set for each communication point. It prints one
 * JSON object: median and quartiles of the wall time of fmi2DoStep alone and
 * of a whole step (fmi2SetReal of the pose, fmi2DoStep, fmi2GetReal of the
 * forces), in microseconds, over `reps` runs.
 *
 * Build (scripts/speed-vs-error does this):
 *   cc -O2 -std=c11 -o target/speed-vs-error/kerf_host host/kerf_host.c -ldl
 * Run:
 *   kerf_host [libkerf.so] [modelDescription.xml] [steps] [reps] [set|carry]
 *
 * Mode `set` (default) sets the pose inputs x = v t for every communication
 * point, as a host driving the cutter from a multibody model does; `carry`
 * sets them once and lets the FMU carry its own end pose into the next step.
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

/* Value reference of the ScalarVariable called `name`. */
static fmi2ValueReference vr_of(const char *xml, const char *name) {
    const char *p = xml;
    char buf[256];
    while ((p = strstr(p, "<ScalarVariable")) != NULL) {
        const char *end = strchr(p, '>');
        if (!end) break;
        if (attr_value(p, end, "name", buf, sizeof buf) && strcmp(buf, name) == 0) {
            if (!attr_value(p, end, "valueReference", buf, sizeof buf))
                die("no valueReference for", name);
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
    qsort(v, n, sizeof *v, cmp_double);
    double x = q * (double)(n - 1);
    size_t i = (size_t)x;
    double f = x - (double)i;
    return i + 1 < n ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

int main(int argc, char **argv) {
    const char *lib_path = argc > 1 ? argv[1] : "target/release/libkerf.so";
    const char *xml_path = argc > 2 ? argv[2] : "modelDescription/modelDescription.xml";
    int steps = argc > 3 ? atoi(argv[3]) : 1000;
    int reps = argc > 4 ? atoi(argv[4]) : 3;
    const char *mode = argc > 5 ? argv[5] : "set";
    int carry = strcmp(mode, "carry") == 0;
    if (!carry && strcmp(mode, "set") != 0) die("mode must be set or carry", mode);
    if (steps < 1 || reps < 1) die("steps and reps must be positive", NULL);

    char *xml = read_file(xml_path);
    char guid[128];
    const char *md = strstr(xml, "<fmiModelDescription");
    if (!md || !attr_value(md, strchr(md, '>'), "guid", guid, sizeof guid))
        die("no guid in", xml_path);
    enum { X, Y, Z, VX, WY, NIN };
    const char *in_names[NIN] = {"x", "y", "z", "vx", "wy"};
    fmi2ValueReference in_vr[NIN];
    for (int k = 0; k < NIN; k++) in_vr[k] = vr_of(xml, in_names[k]);
    enum { NOUT = 3 };
    const char *out_names[NOUT] = {"normalForce", "rollingForce", "sideForce"};
    fmi2ValueReference out_vr[NOUT];
    for (int k = 0; k < NOUT; k++) out_vr[k] = vr_of(xml, out_names[k]);

    void *lib = dlopen(lib_path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) die("dlopen failed", dlerror());
    Instantiate_t instantiate = (Instantiate_t)sym(lib, "fmi2Instantiate");
    SetupExperiment_t setup = (SetupExperiment_t)sym(lib, "fmi2SetupExperiment");
    Component_t enter_init = (Component_t)sym(lib, "fmi2EnterInitializationMode");
    Component_t exit_init = (Component_t)sym(lib, "fmi2ExitInitializationMode");
    SetReal_t set_real = (SetReal_t)sym(lib, "fmi2SetReal");
    GetReal_t get_real = (GetReal_t)sym(lib, "fmi2GetReal");
    DoStep_t do_step = (DoStep_t)sym(lib, "fmi2DoStep");
    FreeInstance_t free_instance = (FreeInstance_t)sym(lib, "fmi2FreeInstance");

    const double R = 0.2159, p = 3.8e-3, v = 1.0, h = 1e-3;
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    size_t n = (size_t)steps * (size_t)reps;
    double *t_do = malloc(n * sizeof *t_do), *t_all = malloc(n * sizeof *t_all);
    double out[NOUT] = {0, 0, 0}, sum[NOUT] = {0, 0, 0};
    size_t k = 0;
    for (int rep = 0; rep < reps; rep++) {
        fmi2Component c = instantiate("kerf_host", fmi2CoSimulation, guid, NULL, &cb, 0, 0);
        if (!c) die("fmi2Instantiate failed", NULL);
        if (setup(c, 0, 0.0, 0.0, 0, 0.0) > fmi2Warning) die("fmi2SetupExperiment failed", NULL);
        if (enter_init(c) > fmi2Warning) die("fmi2EnterInitializationMode failed", NULL);
        double in[NIN] = {0.0, 0.0, R - p, v, v / R};
        if (set_real(c, in_vr, NIN, in) > fmi2Warning) die("fmi2SetReal failed", NULL);
        if (exit_init(c) > fmi2Warning) die("fmi2ExitInitializationMode failed", NULL);
        for (int s = 0; s < steps; s++, k++) {
            double t = s * h;
            in[X] = v * t; /* the pose for the communication point t */
            double t0 = now_us();
            if (!carry && set_real(c, in_vr, NIN, in) > fmi2Warning)
                die("fmi2SetReal failed", NULL);
            double t1 = now_us();
            if (do_step(c, t, h, 1) > fmi2Warning) die("fmi2DoStep failed", NULL);
            double t2 = now_us();
            if (get_real(c, out_vr, NOUT, out) > fmi2Warning) die("fmi2GetReal failed", NULL);
            double t3 = now_us();
            t_do[k] = t2 - t1;
            t_all[k] = t3 - t0;
            if (s >= steps / 5)
                for (int j = 0; j < NOUT; j++) sum[j] += out[j] / (steps - steps / 5) / reps;
        }
        free_instance(c);
    }
    printf("{\"library\": \"%s\", \"mode\": \"%s\", \"steps\": %d, \"reps\": %d, \"step_s\": %g, "
           "\"dostep_us_median\": %.3f, \"dostep_us_p25\": %.3f, \"dostep_us_p75\": %.3f, "
           "\"dostep_us_min\": %.3f, \"step_us_median\": %.3f, \"step_us_p25\": %.3f, "
           "\"step_us_p75\": %.3f, \"mean_normal\": %.1f, \"mean_rolling\": %.1f, "
           "\"mean_side\": %.1f}\n",
           lib_path, mode, steps, reps, h, quantile(t_do, n, 0.5), quantile(t_do, n, 0.25),
           quantile(t_do, n, 0.75), quantile(t_do, n, 0.0), quantile(t_all, n, 0.5),
           quantile(t_all, n, 0.25), quantile(t_all, n, 0.75), sum[0], sum[1], sum[2]);
    free(t_do);
    free(t_all);
    free(xml);
    dlclose(lib);
    return 0;
}
