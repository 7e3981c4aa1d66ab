/* Classic fourth-order Runge-Kutta as a stepbench plugin (include/stepbench/plugin.h).
 *
 * The arithmetic is integrators/rk4.hpp's, term for term and in the same order (Eigen
 * evaluates its expressions element by element, so a loop over i in this order rounds
 * alike): with the accelerations a = F / m the host gives, this plugin's results equal the
 * built-in rk4's wherever 1/m is a power of two, which covers every default problem
 * (tests/test_plugins.cpp checks it). Build it by itself with
 *   cc -shared -fPIC -O2 -I include -o librk4.so examples/plugins/rk4.c
 */
#include <stdlib.h>

#include "stepbench/plugin.h"

typedef struct {
  int n;
  double *a1, *x2, *v2, *a2, *x3, *v3, *a3, *x4, *v4, *a4, *x123, *v123;
} rk4_workspace;

static void* rk4_create(int n) {
  rk4_workspace* w = malloc(sizeof *w);
  double* block = malloc(12 * (size_t)n * sizeof(double));
  if (w == NULL || block == NULL) {
    free(w);
    free(block);
    return NULL;
  }
  w->n = n;
  double** arrays[] = {&w->a1, &w->x2, &w->v2, &w->a2, &w->x3,   &w->v3,
                       &w->a3, &w->x4, &w->v4, &w->a4, &w->x123, &w->v123};
  for (int k = 0; k < 12; ++k) *arrays[k] = block + (size_t)k * (size_t)n;
  return w;
}

static void rk4_destroy(void* p) {
  rk4_workspace* w = p;
  free(w->a1); /* the block */
  free(w);
}

/* k1 = f(t, y), k2 = f(t + dt/2, y + dt/2 k1), k3 = f(t + dt/2, y + dt/2 k2),
 * k4 = f(t + dt, y + dt k3), y += dt (k1 + 2 (k2 + k3) + k4) / 6, for y = (x, v). */
static int rk4_step(void* p, double t, double dt, double* x, double* v, stepbench_force_fn force, void* ctx) {
  rk4_workspace* w = p;
  const int n = w->n;
  const double h = 0.5 * dt;
  int status;
  if ((status = force(ctx, t, x, v, w->a1)) != STEPBENCH_OK) return status;
  for (int i = 0; i < n; ++i) w->x2[i] = x[i] + h * v[i];
  for (int i = 0; i < n; ++i) w->v2[i] = v[i] + h * w->a1[i];
  if ((status = force(ctx, t + h, w->x2, w->v2, w->a2)) != STEPBENCH_OK) return status;
  for (int i = 0; i < n; ++i) w->x3[i] = x[i] + h * w->v2[i];
  for (int i = 0; i < n; ++i) w->v3[i] = v[i] + h * w->a2[i];
  if ((status = force(ctx, t + h, w->x3, w->v3, w->a3)) != STEPBENCH_OK) return status;
  for (int i = 0; i < n; ++i) w->x4[i] = x[i] + dt * w->v3[i];
  for (int i = 0; i < n; ++i) w->v4[i] = v[i] + dt * w->a3[i];
  /* The sums of the first three samples before the fourth force, as rk4.hpp orders them. */
  const double wt = dt / 6.0;
  for (int i = 0; i < n; ++i) w->x123[i] = x[i] + wt * (v[i] + 2.0 * (w->v2[i] + w->v3[i]));
  for (int i = 0; i < n; ++i) w->v123[i] = v[i] + wt * (w->a1[i] + 2.0 * (w->a2[i] + w->a3[i]));
  if ((status = force(ctx, t + dt, w->x4, w->v4, w->a4)) != STEPBENCH_OK) return status;
  for (int i = 0; i < n; ++i) x[i] = w->x123[i] + wt * w->v4[i];
  for (int i = 0; i < n; ++i) v[i] = w->v123[i] + wt * w->a4[i];
  return STEPBENCH_OK;
}

static const stepbench_method methods[] = {{
    .name = "plugin_rk4",
    .description = "classic fourth-order Runge-Kutta, from examples/plugins/rk4.c",
    .kind = STEPBENCH_FIXED_STEP,
    .order = 4,
    .force_evals_per_step = 4,
    .symplectic = 0,
    .create = rk4_create,
    .destroy = rk4_destroy,
    .step = rk4_step,
    .try_step = NULL,
}};

static const stepbench_plugin_table table = {STEPBENCH_PLUGIN_ABI_VERSION, 1, methods};

const stepbench_plugin_table* stepbench_plugin(void) { return &table; }
