#pragma once
// Shared by the GSL and CVODE wrappers; not part of the interface (reference.hpp).
#include <cstdio>
#include <exception>
#include <span>
#include <string>
#include <string_view>

#include "references/reference.hpp"

namespace stepbench::detail {

// A time or value for an error message: %g, not std::to_string's fixed notation.
inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Both solvers are public, so both check their input, not only solve_reference.
void validate_reference_input(std::string_view source, const ode_system& sys, std::span<const double> times,
                              reference_tolerances tol);

// What a C callback needs, and what it hands back: a C++ exception must not cross the
// library's C frames, so it is stashed and rethrown once the library has returned; a
// non-finite derivative is recorded with its time.
struct callback_state {
  const ode_system* sys = nullptr;
  long calls = 0;
  std::exception_ptr error;
  bool non_finite = false;
  double non_finite_t = 0.0;
};

}  // namespace stepbench::detail
