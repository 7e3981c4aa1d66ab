#pragma once
// A problem's parameters as data. Each is declared once, in its problem's `parameters()`:
// name, data member, unit, one-line meaning, the values it admits and, for some, names
// that stand for values (a material pair of the lecture's friction table, a contact
// mode). Validation, `stepbench list`, every command's `--set`, the study file's
// /problems/<p>/parameters table and the report all derive from that declaration.
#include <cmath>
#include <concepts>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace stepbench {

// A name that stands for a parameter's value: `--set sliding_block.material=steel_on_steel`
// is the value of the entry named so.
struct named_value {
  std::string name;
  double value = 0.0;
  std::string description;
};

// The values a parameter admits: an interval, each end open or closed, optionally whole
// numbers only. NaN and the infinities never pass (an infinite end is always open).
struct constraint {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_closed = false;
  bool hi_closed = false;
  bool whole = false;

  bool admits(double v) const {
    if (!std::isfinite(v)) return false;
    if (lo_closed ? v < lo : !(v > lo)) return false;
    if (hi_closed ? v > hi : !(v < hi)) return false;
    return !whole || v == std::floor(v);
  }
  // What follows "<name> must be ": "finite", "a positive finite number", "in (0, 180)",
  // "a whole number from 2 to 1048576".
  std::string text() const;
  // "real", or "whole" for whole numbers (a parameter with names is "named").
  std::string_view kind() const { return whole ? "whole" : "real"; }
};

inline constexpr constraint finite{};
inline constexpr constraint positive{.lo = 0.0};
inline constexpr constraint non_negative{.lo = 0.0, .lo_closed = true};
constexpr constraint in_open(double lo, double hi) { return {.lo = lo, .hi = hi}; }
constexpr constraint in_closed(double lo, double hi) {
  return {.lo = lo, .hi = hi, .lo_closed = true, .hi_closed = true};
}
constexpr constraint in_closed_open(double lo, double hi) { return {.lo = lo, .hi = hi, .lo_closed = true}; }
constexpr constraint whole_from(double lo, double hi) {
  return {.lo = lo, .hi = hi, .lo_closed = true, .hi_closed = true, .whole = true};
}

// The names a parameter takes, or none.
using names_fn = std::vector<named_value> (*)();

// The contact modes of the problems with contacts (core/concepts.hpp's has_contacts).
std::vector<named_value> contact_mode_names();

// One declared parameter of problem type P, bound to its data member.
template <class P>
struct param {
  std::string_view name;
  double P::*member;
  std::string_view unit;
  std::string_view description;
  constraint allowed = finite;
  names_fn names = nullptr;
};

// A declared parameter with its value in one problem instance: what the registry hands
// out (`stepbench list`, the study file, --set).
struct param_value {
  std::string name;
  std::string unit;
  std::string description;
  double value = 0.0;
  double default_value = 0.0;
  constraint allowed;
  std::vector<named_value> names;  // empty for most

  std::string_view kind() const { return names.empty() ? allowed.kind() : "named"; }
  // The name of the current value, "" when it has none.
  std::string value_name() const;
  // "" when `value` is admitted, else the one-line reason ("theta0_deg must be in (0, 180)").
  std::string check(double value) const;
  // A number, or one of the names; throws std::invalid_argument naming the parameter and,
  // for a name it does not take, listing the ones it does.
  double parse(std::string_view text, std::string_view qualified_name) const;
};

// Declared parameters of P with their values in `p` (P's parameters() and its defaults:
// a default P's, or p.defaults() where the defaults are the instance's own, as a scene
// file's are).
template <class P>
std::vector<param_value> declared_params(const P& p) {
  const P defaults = [&] {
    if constexpr (requires {
                    { p.defaults() } -> std::same_as<P>;
                  })
      return p.defaults();
    else
      return P{};
  }();
  std::vector<param_value> out;
  for (const auto& q : P::parameters())
    out.push_back({std::string(q.name), std::string(q.unit), std::string(q.description), p.*q.member,
                   defaults.*q.member, q.allowed, q.names ? q.names() : std::vector<named_value>{}});
  return out;
}

// The first parameter `values` does not admit, as a one-line reason; "" when all are.
std::string check_params(std::span<const param_value> values);

// What no single parameter's constraint can say (a material pair excludes mu_s and mu_k;
// the balls fit the scene): a problem may add this check.
template <class P>
concept has_scene_check = requires(const P& p) {
  { p.scene_check() } -> std::convertible_to<std::string>;
};

// "" when every declared parameter of `p` is admitted and the scene check passes, else
// the first one-line reason.
template <class P>
std::string validate(const P& p) {
  if (auto why = check_params(declared_params(p)); !why.empty()) return why;
  if constexpr (has_scene_check<P>) return p.scene_check();
  return {};
}

}  // namespace stepbench
