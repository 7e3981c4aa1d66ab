#pragma once
// The registries behind the command line: the one place where problems and
// integrators are type-erased. A problem_instance owns one problem value with its
// parameters; run() dispatches to the drive loop instantiated for that problem and the
// named integrator, so the step loop itself has no virtual calls.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "references/reference.hpp"

namespace stepbench {

struct param_value {
  std::string name;
  std::string unit;
  std::string description;
  double value = 0.0;
};

struct integrator_info {
  std::string name;
  std::string description;
  int order = 0;
};

// One fixed-step run, in plain vectors (length dim each).
struct run_result {
  std::string problem;
  std::string integrator;
  double dt = 0.0;
  double horizon = 0.0;
  long steps_planned = 0;
  long steps = 0;
  long force_evals = 0;
  bool non_finite = false;
  std::vector<double> position;  // final
  std::vector<double> velocity;  // final
  std::vector<double> sample_t;
  std::vector<std::vector<double>> sample_y;  // [x; v] after each sampled step
};

class problem_instance {
 public:
  virtual ~problem_instance() = default;
  virtual std::string_view name() const = 0;
  virtual std::string_view description() const = 0;
  virtual int dim() const = 0;
  virtual std::string_view position_unit() const = 0;
  virtual std::vector<param_value> params() const = 0;
  // Sets a parameter; throws std::invalid_argument naming an unknown parameter.
  virtual void set(std::string_view param, double value) = 0;
  virtual std::string validate() const = 0;  // "" when valid
  virtual double horizon() const = 0;
  virtual bool has_closed_form() const = 0;
  virtual bool has_energy() const = 0;
  // [x; v] of the closed form at t; throws std::logic_error without a closed form.
  virtual std::vector<double> exact(double t) const = 0;
  // Total energy of [x; v]; NaN when the problem defines none.
  virtual double energy(std::span<const double> y) const = 0;
  virtual std::vector<double> initial() const = 0;  // [x0; v0]
  // The first-order form y' = [v; F/m] for the reference solvers.
  virtual ode_system ode() const = 0;
  // Runs `integrator` with step dt to `horizon`, recording [x; v] after each step in
  // record_steps. Throws std::invalid_argument for an unknown integrator.
  virtual run_result run(std::string_view integrator, double dt, double horizon,
                         std::span<const long> record_steps) const = 0;
  virtual std::unique_ptr<problem_instance> clone() const = 0;
};

std::vector<std::string> problem_names();
// Throws std::invalid_argument naming the unknown problem and the known ones.
std::unique_ptr<problem_instance> make_problem(std::string_view name);

std::vector<integrator_info> integrators();
// Throws std::invalid_argument naming the unknown integrator and the known ones.
const integrator_info& find_integrator(std::string_view name);

}  // namespace stepbench
