#pragma once
// A block on an incline with the lecture's friction (forces): normal force
// |F_n| = m g cos(theta), kinetic friction mu_k |F_n| against the motion while it slides,
// static friction up to mu_s |F_n| at rest. Pushed up the slope with v0, it decelerates
// at g (sin theta + mu_k cos theta), stops, and then either stays (static friction holds:
// tan theta <= mu_s) or slides back down at g (sin theta - mu_k cos theta). The coordinate
// s is along the slope, positive up; the closed form is piecewise
// (problems/exact/sliding_block.hpp, which also treats mu_s < tan theta <= mu_k as rest).
//
// The force is the lecture's, a function of the state: -m g sin theta - sign(v) mu_k
// |F_n| while moving; at v = 0 exactly, 0 if static friction holds, else the sliding
// force. A time-stepper never lands on v = 0 by itself: the step in which the block stops
// carries it past the stop with the reversed kinetic friction. Where static friction
// holds, the stop is therefore a contact in the drive loop's sense (core/concepts.hpp):
// the gap is v along the first motion, and the response sets v = 0 (the block sticks),
// in either contact mode (`locate`: at the stop time found inside the step). Without
// it a block with mu_k < tan theta <= mu_s (steel on steel at 30 degrees) would slide
// back down forever. Where static friction cannot hold there is no event: the block
// turns back, and the kink of the force inside a step is left to the integrator.
//
// Friction coefficients: `mu_s`, `mu_k`, or a material pair of the lecture's table
// (problems/exact/friction_table.hpp) by `material` (its row, 1..33, or its name:
// `--set sliding_block.material=steel_on_steel`), `lubricated` choosing the column.
// Two scenes: `sliding_block`, the lecture's worked example (30 degrees, mu = 0.5: it
// slides back with a = 0.656 m/s^2), and `sliding_block_stick`, steel on steel (dry) at
// 30 degrees, where static friction holds and kinetic friction alone would not.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/concepts.hpp"
#include "problems/exact/friction_table.hpp"
#include "problems/exact/sliding_block.hpp"

namespace stepbench {

// The row (1-based, as `stepbench list` numbers them) of a named material pair; 0 when
// there is none.
constexpr int friction_row(std::string_view name) {
  for (std::size_t i = 0; i < exact::friction_table.size(); ++i)
    if (exact::has_name(exact::friction_table[i], name)) return static_cast<int>(i) + 1;
  return 0;
}

struct sliding_block {
  static constexpr std::string_view name = "sliding_block";
  static constexpr std::string_view description = "block pushed up a 30 deg incline, mu = 0.5: stops, slides back";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = true;
  static constexpr int dim() { return 1; }
  using vec = Eigen::Matrix<double, 1, 1>;
  using jacobian_matrix = Eigen::Matrix<double, 1, 1>;

  // A scene of the registry: its name, description and the defaults that differ. One
  // type for both (one compiled unit, registry/problem_unit.cpp.in); the instance says
  // which it is.
  struct preset {
    std::string_view name, description;
    double angle_deg, v0, material, mu_s, mu_k;
  };
  // The lecture's friction worked example: 30 degrees, mu_k = 0.5 (and mu_s = 0.5, its
  // static example's): tan 30 = 0.577 > 0.5, so the block stops and slides back.
  static constexpr preset lecture{name, description, 30.0, 5.0, 0.0, 0.5, 0.5};

  const preset* scene = &lecture;
  double angle_deg = scene->angle_deg;
  double v0 = scene->v0;
  double mass_kg = 10.0;  // the lecture's block
  double gravity = 9.8;
  double material = scene->material;
  double lubricated = 0.0;
  double mu_s = scene->mu_s;
  double mu_k = scene->mu_k;
  double locate = 0.0;
  double duration = 2.0;

  sliding_block() = default;
  explicit sliding_block(const preset& s) : scene(&s) {}
  std::string_view label() const { return scene->name; }
  std::string_view summary() const { return scene->description; }
  sliding_block defaults() const { return sliding_block(*scene); }

  static constexpr auto parameters() {
    using p = param<sliding_block>;
    return std::array{
        p{"angle_deg", &sliding_block::angle_deg, "deg", "incline angle", in_closed_open(0.0, 90.0)},
        p{"v0", &sliding_block::v0, "m/s", "initial speed along the slope, positive up"},
        p{"mass_kg", &sliding_block::mass_kg, "kg", "mass", positive},
        p{"gravity", &sliding_block::gravity, "m/s^2", "gravitational acceleration", positive},
        p{"material", &sliding_block::material, "1",
          "friction pair of the lecture's table: its row or its name (0: none, mu_s and mu_k apply)",
          whole_from(0, static_cast<double>(exact::friction_table.size())), material_names},
        p{"lubricated", &sliding_block::lubricated, "1", "the table's column", whole_from(0, 1), lubrication_names},
        p{"mu_s", &sliding_block::mu_s, "1", "static friction coefficient (material 0)", non_negative},
        p{"mu_k", &sliding_block::mu_k, "1", "kinetic friction coefficient (material 0)", non_negative},
        p{"locate", &sliding_block::locate, "1", "contact mode", whole_from(0, 1), contact_mode_names},
        p{"duration", &sliding_block::duration, "s", "default horizon", positive},
    };
  }

  // `material` by name: every pair of the lecture's table, with its coefficients.
  static std::vector<named_value> material_names() {
    auto cell = [](const std::optional<double>& c) { return c ? fmt::format("{:g}", *c) : std::string("-"); };
    std::vector<named_value> out{{"none", 0.0, "mu_s and mu_k apply"}};
    for (std::size_t i = 0; i < exact::friction_table.size(); ++i) {
      const auto& r = exact::friction_table[i];
      out.push_back({exact::friction_name(r), static_cast<double>(i + 1),
                     fmt::format("dry {} / {}, lubricated {} / {} (mu_s / mu_k)", cell(r.mu_s_dry), cell(r.mu_k_dry),
                                 cell(r.mu_s_lubricated), cell(r.mu_k_lubricated))});
    }
    return out;
  }
  static std::vector<named_value> lubrication_names() {
    return {{"dry", 0.0, "the table's dry column"}, {"lubricated", 1.0, "the table's lubricated column"}};
  }

  const exact::friction_record* record() const {
    return material >= 1 ? &exact::friction_table[static_cast<std::size_t>(material) - 1] : nullptr;
  }
  // The table's mu_s or mu_k (kinetic) in the chosen column.
  const std::optional<double>& table_cell(const exact::friction_record& r, bool kinetic) const {
    if (lubricated != 0.0) return kinetic ? r.mu_k_lubricated : r.mu_s_lubricated;
    return kinetic ? r.mu_k_dry : r.mu_s_dry;
  }
  // The coefficients in force: the table's (material > 0) or the parameters'.
  double static_coefficient() const { return record() ? *table_cell(*record(), false) : mu_s; }
  double kinetic_coefficient() const { return record() ? *table_cell(*record(), true) : mu_k; }

  // What no single parameter's constraint says: a material pair excludes mu_s and mu_k,
  // and the table must hold both coefficients in the chosen column.
  std::string scene_check() const {
    if (const auto* r = record()) {
      if (mu_s != scene->mu_s || mu_k != scene->mu_k) return "give either material or mu_s and mu_k, not both";
      const auto &s = table_cell(*r, false), &k = table_cell(*r, true);
      if (!s || !k)
        return fmt::format(
            "the lecture's table has no {} coefficient for {} ({}); choose another pair or give mu_s "
            "and mu_k",
            !s ? "static" : "kinetic", exact::friction_name(*r), lubricated != 0.0 ? "lubricated" : "dry");
    }
    return {};
  }

  double theta() const { return angle_deg * (std::numbers::pi / 180.0); }
  exact::sliding_block motion() const { return {gravity, theta(), static_coefficient(), kinetic_coefficient(), v0}; }
  // Once at rest, the block stays (static friction holds; see the exact motion for the
  // case mu_s < tan theta <= mu_k).
  bool holds() const { return motion().stays_at_rest(); }

  double mass() const { return mass_kg; }
  double horizon() const { return duration; }
  void force(double, const vec&, const vec& v, vec& f) const {
    const double w = mass_kg * gravity, along = w * std::sin(theta()),
                 kinetic = kinetic_coefficient() * w * std::cos(theta());
    if (v[0] > 0.0)
      f[0] = -along - kinetic;
    else if (v[0] < 0.0)
      f[0] = -along + kinetic;
    else
      f[0] = holds() ? 0.0 : -(along - kinetic);
  }
  // The same friction as a set-valued force (core/concepts.hpp), for the implicit
  // methods: gravity along the slope is the smooth force, and friction is up to
  // mu_s |F_n| at rest, mu_k |F_n| sliding, |F_n| = m g cos theta.
  void smooth_force(double, const vec&, const vec&, vec& f) const { f[0] = -mass_kg * gravity * std::sin(theta()); }
  friction_limits friction(double, const vec&) const {
    const double normal = mass_kg * gravity * std::cos(theta());
    return {.static_max = static_coefficient() * normal, .kinetic = kinetic_coefficient() * normal};
  }
  // The force is piecewise constant in v (its jump at v = 0 is the stop event's): both
  // derivatives are zero. Given, so that no implicit method differences across the jump.
  jacobian_matrix make_jacobian() const { return jacobian_matrix::Zero(); }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx.setZero();
    dfdv.setZero();
  }
  phase<vec> initial() const { return {vec(0.0), vec(v0)}; }
  phase<vec> exact(double t) const {
    const auto s = motion().at(t);
    return {vec(s.s), vec(s.v)};
  }
  double energy(const vec& x, const vec& v) const {
    return 0.5 * mass_kg * v.squaredNorm() + mass_kg * gravity * std::sin(theta()) * x[0];
  }

  // The stop as a contact, where static friction holds: v along the first motion.
  bool has_stop() const { return v0 != 0.0 && holds(); }
  double contact_gap(double, const vec&, const vec& v) const {
    return has_stop() ? std::copysign(1.0, v0) * v[0] : 1.0;
  }
  contact_outcome resolve_contacts(double, vec&, vec& v) const {
    contact_outcome c;
    if (has_stop() && std::copysign(1.0, v0) * v[0] < 0.0) {
      v[0] = 0.0;  // static friction holds it
      c.resolved = 1;
      c.changed = true;
    }
    return c;
  }
  bool locate_contacts() const { return locate != 0.0; }
};

// Steel on steel, dry (mu_s 0.74, mu_k 0.57), at 30 degrees: mu_k < tan 30 = 0.577 <=
// mu_s, so the block sticks where it stops, and kinetic friction alone would let it creep
// back at 0.06 m/s^2.
inline constexpr sliding_block::preset sliding_block_stick_scene{
    "sliding_block_stick",
    "block pushed up a 30 deg incline, steel on steel: stops and sticks",
    30.0,
    5.0,
    friction_row("steel_on_steel"),
    0.5,
    0.5};
inline sliding_block sliding_block_stick() { return sliding_block(sliding_block_stick_scene); }

}  // namespace stepbench
