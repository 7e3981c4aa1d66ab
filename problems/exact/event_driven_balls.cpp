// The event-driven truth for many bouncing balls: the scene, the event search and the
// contact response (problems/exact/event_driven_balls.hpp describes them).
#include "problems/exact/event_driven_balls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace stepbench::exact {

std::string ball_scene::validate() const {
  auto pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (n < 1) return "n must be >= 1";
  if (!pos(radius) || !pos(mass) || !pos(rest_height)) return "radius, mass and rest_height must be finite and > 0";
  if (!pos(width) || !pos(height) || width <= 2.0 * radius || height <= 2.0 * radius)
    return "the box must be wider and higher than one ball";
  if (!(std::isfinite(gravity) && gravity >= 0.0)) return "gravity must be finite and >= 0";
  if (!(restitution >= 0.0 && restitution <= 1.0)) return "restitution must be in [0, 1]";
  if (!(friction >= 0.0 && friction <= 1.0)) return "friction must be in [0, 1]";
  if (x0.size() != static_cast<std::size_t>(n) || v0.size() != static_cast<std::size_t>(n))
    return "x0 and v0 must hold n entries each";
  for (int i = 0; i < n; ++i) {
    if (!x0[i].allFinite() || !v0[i].allFinite()) return "ball " + std::to_string(i) + ": non-finite state";
    if (x0[i].x() < radius || x0[i].x() > width - radius || x0[i].y() < radius || x0[i].y() > height - radius)
      return "ball " + std::to_string(i) + " is not inside the box";
    for (int j = 0; j < i; ++j)
      if ((x0[i] - x0[j]).squaredNorm() < 4.0 * radius * radius)
        return "balls " + std::to_string(j) + " and " + std::to_string(i) + " overlap";
  }
  return {};
}

double place_on_grid(ball_scene& s, std::uint64_t seed) {
  const int n = s.n;
  const int cols = static_cast<int>(std::ceil(std::sqrt(n * s.width / s.height)));
  const int rows = (n + cols - 1) / cols;
  const double cw = s.width / cols, ch = s.height / rows;
  const double jx = 0.5 * (0.5 * cw - s.radius), jz = 0.5 * (0.5 * ch - s.radius), vmax = 2.0;
  std::mt19937_64 rng(seed);
  auto symmetric = [&](double amp) { return amp * (2.0 * unit_draw(rng) - 1.0); };
  s.x0.clear();
  s.v0.clear();
  for (int i = 0; i < n; ++i) {
    const double cx = ((i % cols) + 0.5) * cw, cz = ((i / cols) + 0.5) * ch;
    const double dx = symmetric(jx), dz = symmetric(jz);
    s.x0.emplace_back(cx + dx, cz + dz);
    const double vx = symmetric(vmax), vz = symmetric(vmax);
    s.v0.emplace_back(vx, vz);
  }
  return std::min(cw, ch);
}

inelastic_collapse::inelastic_collapse(double t, int a, int b, const std::string& why)
    : std::runtime_error("event_driven_balls: inelastic collapse at t = " + std::to_string(t) + ": " + why +
                         "; no event-driven truth beyond"),
      time(t),
      i(a),
      j(b) {}

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

// Real roots of A t^2 + B t + C = 0, ascending, in the form that avoids cancellation
// (q = -(B + sign(B) sqrt(B^2 - 4 A C)) / 2, roots q / A and C / q). Returns the count.
int quadratic_roots(double A, double B, double C, double r[2]) {
  if (A == 0.0) {
    if (B == 0.0) return 0;
    r[0] = -C / B;
    return 1;
  }
  const double disc = B * B - 4.0 * A * C;
  if (disc < 0.0) return 0;
  const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  if (q == 0.0) {  // B = C = 0
    r[0] = r[1] = 0.0;
    return 2;
  }
  r[0] = q / A;
  r[1] = C / q;
  if (r[0] > r[1]) std::swap(r[0], r[1]);
  return 2;
}

// Root of a function monotone on [lo, hi] with f(lo) = flo and the opposite sign (or
// zero) at hi; fd(t) returns {f(t), f'(t)}. Newton inside the bracket, bisection when
// Newton would leave it; stops when the bracket is two neighbouring doubles.
template <class F>
double bracketed_root(const F& fd, double lo, double hi, double flo) {
  double t = lo + 0.5 * (hi - lo);
  for (int it = 0; it < 200; ++it) {
    const auto [ft, dft] = fd(t);
    if (ft == 0.0) return t;
    if ((ft > 0.0) == (flo > 0.0))
      lo = t;
    else
      hi = t;
    const double mid = lo + 0.5 * (hi - lo);
    if (!(mid > lo && mid < hi)) break;
    double next = t - ft / dft;
    if (!(next > lo && next < hi)) next = mid;
    if (next == t) return t;
    t = next;
  }
  return hi;
}

// Delay to a ball-ball contact in uniform relative motion, d + u t (both in flight or
// both resting): the entering root of |d + u t|^2 = s^2, or inf.
double uniform_pair_delay(const vec2& d, const vec2& u, double s) {
  const double b = d.dot(u);
  if (!(b < 0.0)) return inf;  // not approaching: in linear relative motion, never again
  const double c = d.squaredNorm() - s * s;
  if (c <= 0.0) return 0.0;  // touching (or inside by rounding) and approaching: now
  const double a = u.squaredNorm();
  const double disc = b * b - a * c;
  if (!(disc > 0.0)) return inf;  // passes by, or grazes
  return c / (-b + std::sqrt(disc));
}

// Delay in [0, T] to a ball-ball contact under relative acceleration a, p(t) = d + u t +
// a t^2 / 2: the first time f(t) = |p|^2 - s^2 falls to zero (or 0 when the balls are in
// contact and start approaching at once), inf if none. f is a quartic: the roots of f''
// (a quadratic, closed form) split [0, T] into pieces on which f' is monotone; the roots
// of f' found there split it into pieces on which f is monotone; the first decreasing
// piece that reaches f <= 0 holds the contact.
//
// A contact that starts with zero approach speed (the balls touch, f' = 0, and the
// acceleration pulls them together) is counted only if, left alone, the balls would
// overlap by more than depth_tol before T: two balls side by side on the floor, one a
// few nm above it and settling, would otherwise make an endless run of contacts that each
// change nothing (the overlap they prevent is of order 1e-17 m).
double accelerated_pair_delay(const vec2& d, const vec2& u, const vec2& a, double s, double T, double depth_tol) {
  if (!(T >= 0.0) || !std::isfinite(T)) return inf;
  // Cannot touch before T: the gap exceeds what the relative motion can close.
  if (d.norm() - s > T * (u.norm() + 0.5 * a.norm() * T)) return inf;
  auto f_df = [&](double t) -> std::pair<double, double> {
    const vec2 p = d + t * (u + 0.5 * t * a), w = u + t * a;
    return {p.squaredNorm() - s * s, 2.0 * p.dot(w)};
  };
  auto f = [&](double t) { return f_df(t).first; };
  auto df_ddf = [&](double t) -> std::pair<double, double> {
    const vec2 p = d + t * (u + 0.5 * t * a), w = u + t * a;
    return {2.0 * p.dot(w), 2.0 * (w.squaredNorm() + p.dot(a))};
  };
  const double df0 = 2.0 * d.dot(u);
  if (T == 0.0) return (f(0.0) <= 0.0 && df0 < 0.0) ? 0.0 : inf;

  // f''/2 = 3/2 |a|^2 t^2 + 3 (u.a) t + (|u|^2 + d.a).
  double r2[2];
  const int n2 = quadratic_roots(1.5 * a.squaredNorm(), 3.0 * u.dot(a), u.squaredNorm() + d.dot(a), r2);
  std::array<double, 4> bp{};  // bp[0] = 0
  int nb = 1;
  for (int k = 0; k < n2; ++k)
    if (r2[k] > bp[nb - 1] && r2[k] < T) bp[nb++] = r2[k];
  bp[nb++] = T;

  std::array<double, 5> cp{};  // cp[0] = 0
  int nc = 1;
  for (int k = 0; k + 1 < nb; ++k) {
    const double g0 = df_ddf(bp[k]).first, g1 = df_ddf(bp[k + 1]).first;
    if ((g0 < 0.0 && g1 > 0.0) || (g0 > 0.0 && g1 < 0.0)) {
      const double root = bracketed_root(df_ddf, bp[k], bp[k + 1], g0);
      if (root > cp[nc - 1] && root < T) cp[nc++] = root;
    }
  }
  cp[nc++] = T;

  std::array<double, 5> fc{};
  for (int k = 0; k < nc; ++k) fc[k] = f(cp[k]);
  for (int k = 0; k + 1 < nc; ++k) {
    const double lo = cp[k], hi = cp[k + 1];
    const double flo = fc[k], fhi = fc[k + 1];
    if (flo <= 0.0) {
      // In contact (to rounding) at lo: a contact if the balls approach here with a
      // nonzero speed, or start to and would overlap by more than depth_tol.
      if (k == 0 && df0 < 0.0) return lo;
      if (fhi < flo) {
        const double f_min = *std::min_element(fc.begin() + k, fc.begin() + nc);
        if (s - std::sqrt(std::max(s * s + f_min, 0.0)) > depth_tol) return lo;
      }
      continue;
    }
    if (fhi < 0.0) return bracketed_root(f_df, lo, hi, flo);
    if (fhi == 0.0 && hi == T) return T;
  }
  return inf;
}

}  // namespace

event_driven_balls::event_driven_balls(const ball_scene& scene) : s_(scene) {
  if (const std::string err = s_.validate(); !err.empty()) throw std::invalid_argument("ball_scene: " + err);
  const auto n = static_cast<std::size_t>(s_.n);
  x_ref_ = s_.x0;
  v_ref_ = s_.v0;
  t_ref_.assign(n, 0.0);
  resting_.assign(n, 0);
  last_.assign(n, key{-1, -1});
  x_base_.resize(n);
  v_base_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    if (s_.gravity > 0.0 && x_ref_[i].y() == s_.radius && v_ref_[i].y() == 0.0) resting_[i] = 1;
  w_rest_sq_ = 2.0 * s_.gravity * s_.rest_height;
  max_same_time_ = 1000 + 100L * s_.n * s_.n;
  x_now_ = x_ref_;
  v_now_ = v_ref_;
  find_next_event();
}

void event_driven_balls::advance_to(double t) {
  if (!(t >= t_last_) || !std::isfinite(t))
    throw std::invalid_argument("event_driven_balls::advance_to: t must be finite and not before the last event");
  while (!collapse_ && next_.time <= t) process_next();
  if (collapse_ && t > collapse_->time) {
    set_now(collapse_->time);
    throw *collapse_;
  }
  set_now(t);
}

bool event_driven_balls::next_event(double t_max) {
  if (collapse_) throw *collapse_;
  if (!(next_.time <= t_max)) return false;
  process_next();
  if (collapse_) throw *collapse_;
  set_now(t_last_);
  return true;
}

void event_driven_balls::evaluate(std::size_t i, double t, vec2& x, vec2& v) const {
  const double tau = t - t_ref_[i], g = g_of(i);
  const vec2& x0 = x_ref_[i];
  const vec2& v0 = v_ref_[i];
  x = {x0.x() + v0.x() * tau, x0.y() + tau * (v0.y() - 0.5 * g * tau)};
  v = {v0.x(), v0.y() - g * tau};
}

void event_driven_balls::set_now(double t) {
  t_now_ = t;
  for (std::size_t i = 0; i < x_now_.size(); ++i) evaluate(i, t, x_now_[i], v_now_[i]);
}

double event_driven_balls::wall_delay(std::size_t i, int w) const {
  const double r = s_.radius, g = s_.gravity;
  const vec2 &x = x_base_[i], &v = v_base_[i];
  switch (w) {
    case 0:
      return v.x() < 0.0 ? std::max(x.x() - r, 0.0) / -v.x() : inf;
    case 1:
      return v.x() > 0.0 ? std::max(s_.width - r - x.x(), 0.0) / v.x() : inf;
    case 2: {
      if (resting_[i]) return inf;
      const double gap = std::max(x.y() - r, 0.0), vz = v.y();
      if (vz < 0.0) return 2.0 * gap / (std::sqrt(vz * vz + 2.0 * g * gap) - vz);
      return g > 0.0 ? (vz + std::sqrt(vz * vz + 2.0 * g * gap)) / g : inf;
    }
    default: {
      if (resting_[i] || !(v.y() > 0.0)) return inf;
      const double gap = std::max(s_.height - r - x.y(), 0.0), vz = v.y();
      const double disc = vz * vz - 2.0 * g * gap;
      return disc > 0.0 ? 2.0 * gap / (vz + std::sqrt(disc)) : inf;
    }
  }
}

bool event_driven_balls::is_repeat(const key& k) const {
  if (k.slot < pair_slot) return last_[static_cast<std::size_t>(k.i)] == k;
  return last_[static_cast<std::size_t>(k.i)] == k && last_[static_cast<std::size_t>(k.slot - pair_slot)] == k;
}

void event_driven_balls::find_next_event() {
  const std::size_t n = x_ref_.size();
  for (std::size_t i = 0; i < n; ++i) evaluate(i, t_last_, x_base_[i], v_base_[i]);
  const double s = 2.0 * s_.radius;
  candidate best{inf, {s_.n, 0}};
  auto offer = [&](double delay, key k) {
    const double t = t_last_ + delay;
    if (t < best.time || (t == best.time && (k.i < best.k.i || (k.i == best.k.i && k.slot < best.k.slot))))
      best = {t, k};
  };
  for (std::size_t i = 0; i < n; ++i)
    for (int w = 0; w < 4; ++w) {
      const double delay = wall_delay(i, w);
      const key k{static_cast<int>(i), w};
      if (delay == inf || (is_repeat(k) && (t_last_ + delay == t_last_ || w != 2))) continue;
      offer(delay, k);
    }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      if (resting_[i] != resting_[j]) continue;
      const key k{static_cast<int>(i), pair_slot + static_cast<int>(j)};
      if (is_repeat(k)) continue;
      const double delay = uniform_pair_delay(x_base_[j] - x_base_[i], v_base_[j] - v_base_[i], s);
      if (delay != inf) offer(delay, k);
    }
  // Mixed pairs (one resting, one in flight) last, searched only up to the best so
  // far and up to the flying ball's next floor contact (finite: g > 0 when a ball rests).
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      if (resting_[i] == resting_[j]) continue;
      const key k{static_cast<int>(i), pair_slot + static_cast<int>(j)};
      const std::size_t flying = resting_[i] ? j : i;
      const double window = std::min(best.time - t_last_, wall_delay(flying, 2));
      const vec2 a{0.0, resting_[i] ? -s_.gravity : s_.gravity};  // a_j - a_i
      const double delay =
          accelerated_pair_delay(x_base_[j] - x_base_[i], v_base_[j] - v_base_[i], a, s, window, s_.rest_height);
      if (delay == inf) continue;
      if (is_repeat(k) && t_last_ + delay == t_last_) {
        const auto other = resting_[i] ? i : j;
        collapse_.emplace(
            t_last_, static_cast<int>(flying), static_cast<int>(other),
            "ball " + std::to_string(flying) + " stays in contact with resting ball " + std::to_string(other));
        next_ = {inf, {s_.n, 0}};
        return;
      }
      offer(delay, k);
    }
  next_ = best;
}

void event_driven_balls::process_next() {
  const candidate c = next_;
  const double t = c.time;
  same_time_ = (!events_.empty() && events_.back().time == t) ? same_time_ + 1 : 0;
  if (same_time_ > max_same_time_) {
    collapse_.emplace(t, c.k.i, c.k.slot < pair_slot ? -1 : c.k.slot - pair_slot,
                      "more than " + std::to_string(max_same_time_) + " events at one time");
    next_ = {inf, {s_.n, 0}};
    return;
  }
  const double r = s_.radius, kr = s_.restitution, kf = s_.friction;
  contact_event ev{t, contact_kind::ball, c.k.i, -1, vec2::Zero(), 0.0, false};
  const auto i = static_cast<std::size_t>(c.k.i);
  vec2 xi, vi;
  evaluate(i, t, xi, vi);
  if (c.k.slot < pair_slot) {
    // Wall: slots 0, 1 the sides (axis x), 2, 3 the floor and ceiling (axis z), the even
    // slot the wall at 0. Snap the centre onto the contact line, apply
    // v <- (1 - k_f) v_t - k_r v_n.
    const int axis = c.k.slot / 2, along = 1 - axis;
    const bool lower = c.k.slot % 2 == 0;  // the wall at 0
    const double extent = axis == 0 ? s_.width : s_.height;
    ev.kind = static_cast<contact_kind>(c.k.slot);
    ev.normal_speed = lower ? -vi[axis] : vi[axis];
    xi[axis] = lower ? r : extent - r;
    vi[axis] = -kr * vi[axis];
    vi[along] = (1.0 - kf) * vi[along];
    ev.point[axis] = lower ? 0.0 : extent;
    ev.point[along] = xi[along];
    // Zeno guard: a bounce lower than rest_height ends the bounce sequence.
    if (ev.kind == contact_kind::floor && s_.gravity > 0.0 && vi.y() * vi.y() < w_rest_sq_) {
      vi.y() = 0.0;
      if (kf > 0.0) vi.x() = 0.0;  // the limit of (1 - k_f)^n over the remaining bounces
      resting_[i] = 1;
      ev.came_to_rest = true;
    }
    anchor(i, t, xi, vi);
  } else {
    const auto j = static_cast<std::size_t>(c.k.slot - pair_slot);
    vec2 xj, vj;
    evaluate(j, t, xj, vj);
    const vec2 nrm = (xj - xi).normalized(), u = vj - vi;
    const double un = u.dot(nrm);
    const vec2 u_n = un * nrm, u_t = u - u_n;
    const vec2 du = -kf * u_t - (1.0 + kr) * u_n;
    vi -= 0.5 * du;
    vj += 0.5 * du;
    ev.j = static_cast<int>(j);
    ev.normal_speed = -un;
    ev.point = 0.5 * (xi + xj);
    anchor(i, t, xi, vi);
    anchor(j, t, xj, vj);
    last_[j] = c.k;
  }
  last_[i] = c.k;
  events_.push_back(ev);
  t_last_ = t;
  find_next_event();
}

void event_driven_balls::anchor(std::size_t i, double t, const vec2& x, const vec2& v) {
  if (resting_[i] && v.y() != 0.0) resting_[i] = 0;
  t_ref_[i] = t;
  x_ref_[i] = x;
  v_ref_[i] = v;
}

}  // namespace stepbench::exact
