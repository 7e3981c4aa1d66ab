/* Ruth's third-order symplectic method as a stepbench plugin (include/stepbench/plugin.h):
 * R. D. Ruth, "A canonical integration technique", IEEE Trans. Nucl. Sci. 30 (1983)
 * 2669-2671. Three kick-drift stages; stage i kicks the velocity by c_i dt a(x) and then
 * drifts the position by d_i dt v, with (the coefficients as "Symplectic integrator" on
 * Wikipedia lists them for Ruth's method)
 *   c = (1, -2/3, 2/3),  d = (-1/24, 3/4, 7/24).
 * Both sum to 1; halving dt on the pendulum divides the error by 8 (order 3, checked in
 * floating point before it was written here, and by the study's order fit). None of
 * stepbench's own methods is a third-order symplectic one. For a force that depends on v
 * it kicks with the velocity of the moment (no longer symplectic there; the study shows
 * what it costs). Build it by itself with
 *   cc -shared -fPIC -O2 -I include -o libruth3.so examples/plugins/ruth3.c
 */
#include <stdlib.h>

#include "stepbench/plugin.h"

typedef struct {
  int n;
  double* a;
} ruth3_workspace;

static void* ruth3_create(int n) {
  ruth3_workspace* w = malloc(sizeof *w);
  if (w == NULL) return NULL;
  w->n = n;
  w->a = malloc((size_t)n * sizeof(double));
  if (w->a == NULL) {
    free(w);
    return NULL;
  }
  return w;
}

static void ruth3_destroy(void* p) {
  ruth3_workspace* w = p;
  free(w->a);
  free(w);
}

static int ruth3_step(void* p, double t, double dt, double* x, double* v, stepbench_force_fn force, void* ctx) {
  static const double c[3] = {1.0, -2.0 / 3.0, 2.0 / 3.0};
  static const double d[3] = {-1.0 / 24.0, 3.0 / 4.0, 7.0 / 24.0};
  ruth3_workspace* w = p;
  double tau = t; /* the time the positions have reached */
  for (int s = 0; s < 3; ++s) {
    const int status = force(ctx, tau, x, v, w->a);
    if (status != STEPBENCH_OK) return status;
    const double kick = c[s] * dt, drift = d[s] * dt;
    for (int i = 0; i < w->n; ++i) v[i] += kick * w->a[i];
    for (int i = 0; i < w->n; ++i) x[i] += drift * v[i];
    tau += drift;
  }
  return STEPBENCH_OK;
}

static const stepbench_method methods[] = {{
    .name = "ruth3",
    .description = "Ruth's third-order symplectic method (1983), from examples/plugins/ruth3.c",
    .kind = STEPBENCH_FIXED_STEP,
    .order = 3,
    .force_evals_per_step = 3,
    .symplectic = 1,
    .create = ruth3_create,
    .destroy = ruth3_destroy,
    .step = ruth3_step,
    .try_step = NULL,
}};

static const stepbench_plugin_table table = {STEPBENCH_PLUGIN_ABI_VERSION, 1, methods};

const stepbench_plugin_table* stepbench_plugin(void) { return &table; }
