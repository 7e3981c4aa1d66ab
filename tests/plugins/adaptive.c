/* An adaptive plugin for the tests (tests/test_plugins.cpp): Heun's method with Euler's
 * as its embedded error estimate (the Heun-Euler 2(1) pair, Hairer, Norsett & Wanner,
 * Solving ODEs I, sec. II.4), and the usual controller, dt_next = dt min(5, max(0.2,
 * 0.9 err^(-1/2))) (HNW I eq. 4.13 with q = 1). Built three ways: as it is
 * (heun_euler); scribbling over x and v on a rejected attempt, which the host must undo
 * (HEUN_DIRTY: heun_euler_dirty); proposing a NaN next step (HEUN_BAD_PROPOSAL). */
#include <math.h>
#include <stdlib.h>

#include "stepbench/plugin.h"

typedef struct {
  int n;
  double *a1, *xe, *ve, *a2;
} workspace;

static void* create(int n) {
  workspace* w = malloc(sizeof *w);
  double* block = malloc(4 * (size_t)n * sizeof(double));
  if (w == NULL || block == NULL) {
    free(w);
    free(block);
    return NULL;
  }
  w->n = n;
  w->a1 = block, w->xe = block + n, w->ve = block + 2 * n, w->a2 = block + 3 * n;
  return w;
}

static void destroy(void* p) {
  workspace* w = p;
  free(w->a1);
  free(w);
}

static int try_step(void* p, double t, double dt, double tol, double* x, double* v, stepbench_force_fn force, void* ctx,
                    double* dt_next, int* accepted) {
  workspace* w = p;
  const int n = w->n;
  int status = force(ctx, t, x, v, w->a1);
  if (status != STEPBENCH_OK) return status;
  for (int i = 0; i < n; ++i) w->xe[i] = x[i] + dt * v[i], w->ve[i] = v[i] + dt * w->a1[i];
  if ((status = force(ctx, t + dt, w->xe, w->ve, w->a2)) != STEPBENCH_OK) return status;
  /* Heun's step minus Euler's: dt/2 (k2 - k1), scaled by tol (1 + max(|y0|, |y1|)). */
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double ex = 0.5 * dt * (w->ve[i] - v[i]), ev = 0.5 * dt * (w->a2[i] - w->a1[i]);
    const double sx = tol * (1.0 + fmax(fabs(x[i]), fabs(w->xe[i] + ex)));
    const double sv = tol * (1.0 + fmax(fabs(v[i]), fabs(w->ve[i] + ev)));
    sum += (ex / sx) * (ex / sx) + (ev / sv) * (ev / sv);
  }
  const double err = sqrt(sum / (2.0 * n));
  *accepted = err <= 1.0;
  *dt_next = dt * fmin(5.0, fmax(0.2, 0.9 / sqrt(fmax(err, 1e-10))));
#if defined(HEUN_BAD_PROPOSAL)
  *dt_next = NAN;
#endif
  if (*accepted) {
    for (int i = 0; i < n; ++i) {
      x[i] += 0.5 * dt * (v[i] + w->ve[i]);
      v[i] += 0.5 * dt * (w->a1[i] + w->a2[i]);
    }
  } else {
#if defined(HEUN_DIRTY)
    for (int i = 0; i < n; ++i) x[i] = v[i] = 1e300;
#endif
  }
  return STEPBENCH_OK;
}

#if defined(HEUN_DIRTY)
#define NAME "heun_euler_dirty"
#elif defined(HEUN_BAD_PROPOSAL)
#define NAME "bad_proposal"
#else
#define NAME "heun_euler"
#endif

static const stepbench_method methods[] = {{
    .name = NAME,
    .description = "Heun's method with Euler's error estimate, for the tests",
    .kind = STEPBENCH_ADAPTIVE,
    .order = 2,
    .force_evals_per_step = 2,
    .symplectic = 0,
    .create = create,
    .destroy = destroy,
    .step = NULL,
    .try_step = try_step,
}};

static const stepbench_plugin_table table = {STEPBENCH_PLUGIN_ABI_VERSION, 1, methods};

const stepbench_plugin_table* stepbench_plugin(void) { return &table; }
