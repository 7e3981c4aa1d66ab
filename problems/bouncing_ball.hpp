#pragma once
// A ball under gravity, launched horizontally, bouncing on the ground plane z = 0 with the
// lecture's collision response (particle and plane): after the step, a ball found on the
// wrong side, (x - p).n < 0, is moved back to the plane, and its velocity split into
// v_n = (v.n) n and v_t = v - v_n becomes v_b = (1 - k_f) v_t - k_r v_n. State (x, z);
// the ball is a point (the plane is where its centre touches).
//
// Truth: the exact bounce sequence (problems/exact/bouncing_ball.hpp): parabolas between
// contacts, contact times from quadratics, the Zeno limit included. Defaults: dropped
// from 1 m with vx0 = 1 m/s, k_r = 0.8, k_f = 0.1; the horizon, 2 s, holds three
// contacts (t = 0.452, 1.175, 1.753 s), far from the accumulation of contacts at 4.07 s.
//
// Two scenes of one physics, differing in the contact mode (core/drive.hpp):
// `bouncing_ball` resolves at the end of the step (what games do: the ball is put back on
// the plane at the step's end, a time up to dt after the true contact), and
// `bouncing_ball_locate` finds the contact time inside the step with the method's own
// step (or dense output), resolves there and finishes the step. Between contacts the
// motion is a parabola, which every method of order >= 2 integrates exactly: what the
// study measures on this problem is the contact handling.
#include <Eigen/Core>

#include "core/concepts.hpp"
#include "problems/exact/bouncing_ball.hpp"

namespace stepbench {

struct bouncing_ball {
  static constexpr std::string_view name = "bouncing_ball";
  static constexpr std::string_view description = "ball bouncing on the ground, k_r 0.8, k_f 0.1; contacts end_of_step";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = false;
  static constexpr int dim() { return 2; }
  using vec = Eigen::Vector2d;  // (x, z)
  using jacobian_matrix = Eigen::Matrix2d;

  double height = 1.0;
  double vx0 = 1.0;
  double restitution = 0.8;
  double friction = 0.1;
  double gravity = 9.8;
  double mass_kg = 1.0;
  // A scene of the registry: its name, description and contact mode. One type for both
  // (one compiled unit, registry/problem_unit.cpp.in); the instance says which it is.
  struct preset {
    std::string_view name, description;
    double locate;
  };
  static constexpr preset end_of_step{name, description, 0.0};

  const preset* scene = &end_of_step;
  double locate = scene->locate;
  double duration = 2.0;

  bouncing_ball() = default;
  explicit bouncing_ball(const preset& s) : scene(&s) {}
  std::string_view label() const { return scene->name; }
  std::string_view summary() const { return scene->description; }
  bouncing_ball defaults() const { return bouncing_ball(*scene); }

  static constexpr auto parameters() {
    using p = param<bouncing_ball>;
    return std::array{
        p{"height", &bouncing_ball::height, "m", "launch height", positive},
        p{"vx0", &bouncing_ball::vx0, "m/s", "horizontal launch speed"},
        p{"restitution", &bouncing_ball::restitution, "1", "k_r: 1 elastic, 0 sticks", in_closed(0.0, 1.0)},
        p{"friction", &bouncing_ball::friction, "1", "k_f: 1 stops the tangential motion, 0 none", in_closed(0.0, 1.0)},
        p{"gravity", &bouncing_ball::gravity, "m/s^2", "gravitational acceleration", positive},
        p{"mass_kg", &bouncing_ball::mass_kg, "kg", "mass", positive},
        p{"locate", &bouncing_ball::locate, "1", "contact mode", whole_from(0, 1), contact_mode_names},
        p{"duration", &bouncing_ball::duration, "s", "default horizon", positive},
    };
  }
  exact::bouncing_ball motion() const { return {gravity, height, vx0, 0.0, restitution, friction}; }

  double mass() const { return mass_kg; }
  double horizon() const { return duration; }
  void force(double, const vec&, const vec&, vec& f) const { f = vec(0.0, -mass_kg * gravity); }
  jacobian_matrix make_jacobian() const { return jacobian_matrix::Zero(); }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx.setZero();
    dfdv.setZero();
  }
  phase<vec> initial() const { return {vec(0.0, height), vec(vx0, 0.0)}; }
  phase<vec> exact(double t) const {
    const auto s = motion().at(t);
    return {vec(s.x, s.z), vec(s.vx, s.vz)};
  }
  double energy(const vec& x, const vec& v) const { return mass_kg * (0.5 * v.squaredNorm() + gravity * x.y()); }

  // Contacts: the plane z = 0 with normal n = (0, 1).
  double contact_gap(double, const vec& x, const vec&) const { return x.y(); }
  contact_outcome resolve_contacts(double, vec& x, vec& v) const {
    contact_outcome c;
    if (x.y() > 0.0 || (x.y() == 0.0 && v.y() >= 0.0)) return c;
    c.depth = -x.y();
    c.changed = x.y() < 0.0;
    x.y() = 0.0;        // back to the plane
    if (v.y() < 0.0) {  // approaching: v_b = (1 - k_f) v_t - k_r v_n
      v = vec((1.0 - friction) * v.x(), -restitution * v.y());
      c.resolved = 1;
      c.changed = true;
    }
    return c;
  }
  bool locate_contacts() const { return locate != 0.0; }

  // The exact contacts up to t_end: their times and the ball's position there.
  exact_contact_list exact_contacts(double t_end) const {
    exact_contact_list out;
    for (const auto& c : motion().contacts_until(t_end)) {
      out.times.push_back(c.t);
      out.positions.push_back({c.x, 0.0});
    }
    out.count = static_cast<long>(out.times.size());
    return out;
  }
};

inline constexpr bouncing_ball::preset bouncing_ball_locate_scene{
    "bouncing_ball_locate", "ball bouncing on the ground, k_r 0.8, k_f 0.1; contacts located", 1.0};
inline bouncing_ball bouncing_ball_locate() { return bouncing_ball(bouncing_ball_locate_scene); }

}  // namespace stepbench
