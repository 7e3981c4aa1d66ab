/* The bad plugins the suite loads (tests/CMakeLists.txt builds one library per BAD_*
 * case from this file; tests/plugin_test.sh and tests/test_plugins.cpp say what each must
 * cause). Each is a fixed-step Euler method but for the one thing it gets wrong. */
#include <math.h>
#include <signal.h>
#include <stdlib.h>

#include "stepbench/plugin.h"

typedef struct {
  int n;
  double* a;
} workspace;

static void* create(int n) {
  workspace* w = malloc(sizeof *w);
  if (w == NULL) return NULL;
  w->n = n;
  w->a = malloc((size_t)n * sizeof(double));
  return w;
}

static void destroy(void* p) {
  workspace* w = p;
  free(w->a);
  free(w);
}

static int step(void* p, double t, double dt, double* x, double* v, stepbench_force_fn force, void* ctx) {
  workspace* w = p;
#if defined(BAD_GREEDY)
  /* Evaluates far more than it declares, ignoring the host's stop. */
  for (int k = 0; k < 100000; ++k) force(ctx, t, x, v, w->a);
#endif
  const int status = force(ctx, t, x, v, w->a);
  if (status != STEPBENCH_OK) return status;
  for (int i = 0; i < w->n; ++i) x[i] += dt * v[i];
  for (int i = 0; i < w->n; ++i) v[i] += dt * w->a[i];
#if defined(BAD_STATUS)
  if (t > 0.5) return 7;
#elif defined(BAD_NAN)
  if (t > 0.5) x[0] = NAN;
#elif defined(BAD_CRASH)
  if (t > 0.5) {
    /* The default action, whatever handler the host has (AddressSanitizer's would turn
     * the signal into an exit status): the process ends by signal 11. */
    signal(SIGSEGV, SIG_DFL);
    raise(SIGSEGV);
  }
#endif
  return STEPBENCH_OK;
}

#if defined(BAD_RESERVED)
#define NAME "rk4" /* a built-in method's */
#elif defined(BAD_FIELDS)
#define NAME "bad_fields"
#elif defined(BAD_STATUS)
#define NAME "bad_status"
#elif defined(BAD_NAN)
#define NAME "bad_nan"
#elif defined(BAD_GREEDY)
#define NAME "bad_greedy"
#elif defined(BAD_CRASH)
#define NAME "bad_crash"
#else
#define NAME "bad_euler"
#endif

static const stepbench_method methods[] = {{
    .name = NAME,
    .description = "a bad plugin for the tests",
    .kind = STEPBENCH_FIXED_STEP,
#if defined(BAD_FIELDS)
    .order = 0, /* no order */
#else
    .order = 1,
#endif
    .force_evals_per_step = 1,
    .symplectic = 0,
    .create = create,
    .destroy = destroy,
    .step = step,
    .try_step = NULL,
}};

#if defined(BAD_ABI)
static const stepbench_plugin_table table = {STEPBENCH_PLUGIN_ABI_VERSION + 1, 1, methods};
#else
static const stepbench_plugin_table table = {STEPBENCH_PLUGIN_ABI_VERSION, 1, methods};
#endif

#if defined(BAD_NO_ENTRY)
/* A shared library, but not a stepbench plugin: its entry has another name. */
const stepbench_plugin_table* some_other_entry(void) { return &table; }
#else
const stepbench_plugin_table* stepbench_plugin(void) { return &table; }
#endif
