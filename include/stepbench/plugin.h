/* stepbench plugin ABI, version 1: your own method, compiled as a shared library, run and
 * measured by stepbench like its own (docs/plugins.md).
 *
 * A plugin exports one C function, stepbench_plugin(), which returns a table: the ABI
 * version it was written for (first, so that a plugin for another version is told so
 * rather than mistaken for garbage), then its methods. Each method steps the lecture's
 * second-order system x' = v, v' = a(t, x, v) of n coordinates; the host gives it a
 * callback that computes the accelerations a and counts every call. The host counts the
 * steps and rejected attempts itself, records the state, checks it stays finite, and
 * stops a run that exceeds its work budget.
 *
 * Plain C99; nothing here allocates or keeps state. Build a plugin with
 *   cc -shared -fPIC -O2 -I include -o libmy.so my.c
 */
#ifndef STEPBENCH_PLUGIN_H
#define STEPBENCH_PLUGIN_H

#ifdef __cplusplus
extern "C" {
#endif

/* The ABI this header describes. A plugin puts it in stepbench_plugin_table.abi_version;
 * the host refuses any other value. */
#define STEPBENCH_PLUGIN_ABI_VERSION 1

/* The name of the one symbol the host looks up (dlsym). */
#define STEPBENCH_PLUGIN_ENTRY "stepbench_plugin"

/* The method kinds: a fixed step of the host's dt, or an adaptive attempt at a tolerance. */
#define STEPBENCH_FIXED_STEP 0
#define STEPBENCH_ADAPTIVE 1

/* Status codes. A step returns 0, or a non-zero code of its own, which the host records as
 * the run's failure ("returned status N at t = ..."); a force callback that returns
 * non-zero (the run is over its work budget, or the problem could not evaluate) expects
 * the step to return that status at once. */
#define STEPBENCH_OK 0
#define STEPBENCH_HOST_STOP (-1000)

/* The accelerations a = F(t, x, v) / m at (t, x, v) into a[0..n-1]; x, v and a have the n
 * coordinates the workspace was created for. `ctx` is the host's: pass on what the step
 * was given. Returns 0, or STEPBENCH_HOST_STOP (then a is unspecified). */
typedef int (*stepbench_force_fn)(void* ctx, double t, const double* x, const double* v, double* a);

typedef struct stepbench_method {
  /* 1 to 40 characters of [a-z0-9_], starting with a letter; unique among the loaded
   * plugins and not the name of one of stepbench's own methods (`stepbench list`). */
  const char* name;
  /* One line for `stepbench list` and the report; may be NULL. */
  const char* description;
  int kind;                 /* STEPBENCH_FIXED_STEP or STEPBENCH_ADAPTIVE */
  int order;                /* the declared order of accuracy, 1 to 16 (the study fits it) */
  int force_evals_per_step; /* calls of the force callback a step (an accepted attempt), 1 to 64 */
  int symplectic;           /* 1 if the method is symplectic, else 0 (shown in the report) */

  /* A workspace for states of n coordinates (n >= 1), or NULL if it cannot be made. The
   * host creates one a run, before the first step, and destroys it after the last: size
   * your stage vectors here, so that a step allocates nothing. */
  void* (*create)(int n);
  void (*destroy)(void* workspace);

  /* STEPBENCH_FIXED_STEP: advance (x, v) in place from t by dt. NULL for adaptive methods.
   * A step must depend only on its arguments (the workspace is scratch): the host may
   * step again from a saved state, e.g. to land on a contact. */
  int (*step)(void* workspace, double t, double dt, double* x, double* v, stepbench_force_fn force, void* force_ctx);

  /* STEPBENCH_ADAPTIVE: one attempt of dt from t at the relative tolerance tol. Sets
   * *accepted to 1 if the step is taken ((x, v) advanced in place), else to 0 (the host
   * restores (x, v) to where the attempt began), and *dt_next to the next step to try
   * (finite, > 0). The host shortens a step only to land on the horizon or a record
   * time. NULL for fixed-step methods. */
  int (*try_step)(void* workspace, double t, double dt, double tol, double* x, double* v, stepbench_force_fn force,
                  void* force_ctx, double* dt_next, int* accepted);
} stepbench_method;

typedef struct stepbench_plugin_table {
  int abi_version;  /* STEPBENCH_PLUGIN_ABI_VERSION */
  int method_count; /* 1 to 64 */
  const stepbench_method* methods;
} stepbench_plugin_table;

/* The entry a plugin defines (with default visibility: the host finds it by name). Called
 * once, when the plugin is loaded; the table must live as long as the library. */
const stepbench_plugin_table* stepbench_plugin(void);

#ifdef __cplusplus
}
#endif

#endif /* STEPBENCH_PLUGIN_H */
