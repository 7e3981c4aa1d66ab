// Input validation shared by the reference solvers, and dispatch by source name.
#include "references/reference.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "references/detail.hpp"

namespace stepbench {
namespace detail {

void validate_reference_input(std::string_view source, const ode_system& sys, std::span<const double> times,
                              reference_tolerances tol) {
  const auto fail = [&](const std::string& what) { throw std::invalid_argument(std::string(source) + ": " + what); };
  if (sys.n <= 0) fail("system dimension n must be positive, got " + std::to_string(sys.n));
  if (sys.y0.size() != static_cast<std::size_t>(sys.n))
    fail("y0 has " + std::to_string(sys.y0.size()) + " entries, expected n = " + std::to_string(sys.n));
  for (double v : sys.y0)
    if (!std::isfinite(v)) fail("y0 has a non-finite entry");
  if (!sys.rhs) fail("rhs is not set");
  if (sys.max_steps_per_output < 1) fail("the step budget must be positive");
  if (sys.has_contacts() && !reference_handles_contacts(source))
    fail("this reference does not handle contacts (only CVODE's root finding does)");
  if (static_cast<bool>(sys.contact_gap) != static_cast<bool>(sys.resolve_contacts))
    fail("contact_gap and resolve_contacts come together");
  if (times.empty()) fail("no output times");
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]) || times[i] <= 0.0)
      fail("output time " + std::to_string(i) + " is not finite and > 0");
    if (i > 0 && !(times[i] > times[i - 1]))
      fail("output times are not strictly increasing at index " + std::to_string(i));
  }
  // Both solvers need non-negative tolerances (GSL manual, gsl_odeiv2_control_standard_new;
  // CVODE user guide, CVodeSStolerances); all-zero makes a pure relative test that fails at y = 0.
  if (!std::isfinite(tol.rtol) || !std::isfinite(tol.atol) || tol.rtol < 0.0 || tol.atol < 0.0 ||
      (tol.rtol == 0.0 && tol.atol == 0.0))
    fail("tolerances must be finite, >= 0 and not both zero");
}

}  // namespace detail

bool reference_handles_contacts(std::string_view source) { return source == "cvode_bdf" || source == "cvode_adams"; }

reference_solution solve_reference(std::string_view source, const ode_system& sys, std::span<const double> times,
                                   reference_tolerances tol) {
  // Each solver validates its input, times itself (steady_clock) and fills source, times,
  // rtol and atol, so that calling it directly gives the same record as calling it here.
  if (source == "gsl_rk8pd") return solve_gsl(sys, times, gsl_method::rk8pd, tol);
  if (source == "cvode_bdf") return solve_cvode(sys, times, cvode_method::bdf, tol);
  if (source == "cvode_adams") return solve_cvode(sys, times, cvode_method::adams, tol);
  if (source == "arkode_erk8") return solve_arkode_erk(sys, times, 8, tol);
  throw std::invalid_argument("unknown reference source '" + std::string(source) +
                              "' (expected gsl_rk8pd, cvode_bdf, cvode_adams or arkode_erk8)");
}

}  // namespace stepbench
