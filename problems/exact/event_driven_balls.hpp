#pragma once
// The exact truth for the lecture's closing program, many bouncing balls in a box
// (digest section 8), by event-driven simulation: between contacts every ball flies on
// its parabola, so the state is known in closed form; contact times are roots of
// polynomials; at a contact the lecture's response (digest section 5) is applied.
//
// Scene: N equal balls (radius r, mass m) in the box [0, W] x [0, H]; x horizontal, z
// vertical (stored as the second component), gravity g along -z, walls on all four sides.
//
// Contact response, the lecture's rule (digest section 5), exactly as implemented:
// - Wall with inward normal n: v_n = (v.n) n, v_t = v - v_n, v <- (1 - k_f) v_t - k_r v_n,
//   and the centre is put on the contact line (x = r, x = W - r, z = r or z = H - r).
//   With axis-aligned walls: floor/ceiling v <- ((1 - k_f) v_x, -k_r v_z), side walls
//   v <- (-k_r v_x, (1 - k_f) v_z).
// - Balls i, j touching: n = (x_j - x_i) / |x_j - x_i|, relative velocity u = v_j - v_i,
//   u_n = (u.n) n, u_t = u - u_n; the rule gives the new relative velocity
//   u' = (1 - k_f) u_t - k_r u_n, i.e. a change du = -k_f u_t - (1 + k_r) u_n, split equally
//   (equal masses, momentum conserved): v_i <- v_i - du / 2, v_j <- v_j + du / 2. With
//   k_r = 1, k_f = 0 this exchanges the normal components (elastic). Centres are not moved.
//
// Event times (the step is: find the earliest next event, evaluate the involved balls
// on their parabolas at that time, apply the response, repeat until the horizon):
// - Side walls: linear, t = gap / |v_x| when moving towards the wall.
// - Floor: z + v_z t - g t^2 / 2 = r, the larger root, written without cancellation:
//   t = 2 gap / (sqrt(v_z^2 + 2 g gap) - v_z) for v_z < 0, (v_z + sqrt(...)) / g otherwise.
//   Ceiling: the smaller root of the same form, t = 2 gap / (v_z + sqrt(v_z^2 - 2 g gap)).
// - Pair, both in flight (or both resting): gravity cancels in relative motion,
//   |d + u t|^2 = (2r)^2 with d = x_j - x_i; with b = d.u, a = u.u, c = d.d - 4 r^2 the
//   entering root is t = c / (-b + sqrt(b^2 - a c)) (stable form, b < 0).
// - Pair, one resting and one in flight: relative acceleration g e_z, a quartic
//   |d + u t + a t^2 / 2|^2 = 4 r^2; its first entering root is isolated through the
//   roots of its derivatives (f'' is a quadratic, solved in closed form; f' and f are
//   monotone between the breakpoints) and polished by bracketed Newton.
// Only approaching contacts count: relative normal velocity < 0 at the contact (b < 0,
// f decreasing). Grazing contacts (zero normal velocity at the touching point, a double
// root) are not contacts: the response would change nothing but the friction term. A
// ball found slightly inside a wall or another ball (rounding, of order 1e-16 of the box)
// and approaching collides at once (t = 0).
//
// Determinism. Candidates are compared by time, then by the key (i, slot): the lower
// ball index, then slot 0..3 for the walls left, right, floor, ceiling and 4 + j for the
// pair (i, j > i). Simultaneous events are therefore processed one at a time in that
// order; after each, every candidate is recomputed, so the others fire at zero delay if
// their balls still approach (sequential pairwise resolution; for three balls touching
// at once this is one convention of several, as in every hard-sphere code). A contact
// that was the latest event of all its balls is not re-triggered at zero delay (that
// would only be rounding in the post-contact normal velocity); walls other than the
// floor and pairs in uniform relative motion cannot recur without an intervening event,
// so such repeats are skipped at any delay. The next event is always searched from the
// last event's state, never from the time the caller asked for, so the trajectory does
// not depend on when or how often the state is sampled (tested bit for bit). Each ball
// keeps its own anchor (time, position, velocity of its last contact) and is evaluated
// on its parabola from there: no stepping, and balls not in a contact are never touched.
//
// Zeno guard. With k_r < 1 a ball bouncing on the floor makes infinitely many bounces in
// finite time (the bounce speeds w, k_r w, k_r^2 w, ... sum to a rest time
// t + 2 w / (g (1 - k_r))). When a floor bounce leaves with a vertical speed w whose
// bounce height w^2 / (2 g) is below `rest_height` (default 1e-12 m, i.e.
// w < sqrt(2 g h_rest) = 4.4e-6 m/s, a time between floor contacts below 2 w / g = 9e-7 s),
// the ball is put at rest on the floor (z = r, v_z = 0) and treated as resting: it keeps
// z = r, has no acceleration (the floor carries its weight) and slides with constant v_x
// until a contact gives it vertical speed again. For the truth this means: after the
// cut, z differs from the infinite bounce sequence by at most h_rest and v_z by at most
// w; with k_f = 0, v_x is exact (floor bounces keep it); with k_f > 0 the infinite
// sequence multiplies v_x by (1 - k_f) at every bounce, so its limit is v_x = 0, which is
// what the cut sets; the horizontal position is then off by at most
// |v_x| 2 w / (g (1 - k_r (1 - k_f))) (about 1.5e-6 m for v_x = 1 m/s, k_r = 0.5,
// k_f = 0.2), the distance the bounce sequence would still have slid. A consequence of
// the lecture's rule (friction proportional to v_t at every contact, however small the
// normal speed; not Coulomb's): with k_f > 0 a resting ball pushed with any downward
// component bounces in a vanishing sequence whose limit again has v_x = 0, so it is
// hard to push aside, as in a time-stepped game using the rule at every step.
// Beyond the floor, inelastic collapse: a ball that comes to stay on another ball (lands
// on a resting ball and sits on it, slides down its side, is wedged between it and a
// wall) is a sustained contact, which has no event-driven description: the contacts
// between the two balls and the floor recur at one time with normal speeds falling to
// zero. A contact that begins with zero approach speed is counted only if the balls
// would otherwise overlap by more than rest_height before the flying ball lands (two
// balls side by side on the floor, one settling onto it, would otherwise stall the run
// for nothing). When a contact with a resting ball recurs at zero delay, or more than
// 1000 + 100 N^2 events happen at one and the same time (1-D collapse of a row on the
// floor), the simulation stops and throws inelastic_collapse carrying the time: the
// truth is exact up to that time and does not exist beyond it; later calls throw again.
// Measured over 30 seeds of default_ball_scene, 30 s each: k_r = 1 never collapses
// (N = 4, 8, 16); k_r = 0.5: N = 4 comes to rest in 29 of 30 seeds, N = 16 collapses in
// all 30 (at t = 0.31 to 0.80 s, mean 0.54 s); k_r = 0.9: N = 16 comes to rest in 28 of
// 30 with k_f = 0, but collapses in 21 of 30 with k_f = 0.1 (earliest 1.8 s). For lossy
// many-ball scenes a benchmark compares up to collapse_time() or uses fewer balls.
//
// Cost: an O(N^2) scan of all walls and pairs per event (a truth for N <= 64; the
// time-stepped problem has its own broad phase): about 1.2 us per event at N = 16
// (199 events for 2 s of the default scene), 11 us at N = 64 (g++ 12 -O2).
//
// Choosing the comparison horizon (chaos). Hard-ball contacts are defocusing: a small
// difference in position before a ball-ball contact comes out larger, so differences
// grow by a factor per contact, exponentially in time, and in bursts when a contact
// nearly grazes (it then happens in one copy and not in the other). Measured on
// default_ball_scene(16, seed) (W = 2, H = 1, r = 0.05, k_r = 1), two copies whose
// initial x of ball 0 differ by 1e-12 m (chaos.separation_growth prints this):
//   seed 1:  t [s]             0.25     0.5      0.75     1.0      1.25     1.5      2.0
//            ball-ball contacts  14       26       34       50       56       67       99
//            max |dx| [m]      8.6e-11  1.1e-7   3.5e-6   4.4e-4   3.2e-3   1.9e-1   8.3e-1
// Over seeds 1 to 8, while 1e-11 < |dx| < 1e-3: a growth of 1.41 (1.27 to 1.56) per
// ball-ball contact in the scene, a Lyapunov exponent of 18 /s (14 to 24), i.e. a
// factor 10 every 0.13 s; from 1e-12 the separation passes 1e-6 m at t = 0.75 to 1.3 s
// and 1e-3 m at 1.1 to 1.55 s, then saturates at the box size (about 1 m) by 2 to 2.5 s.
// This also bounds the truth itself: moving every initial coordinate by one ulp (its own
// rounding, about 1e-16 m) the copies differ by 1e-6 m at t = 1.05 to 1.7 s and by
// 1e-3 m at 1.3 to 2.1 s, so beyond about 1 s a double-precision truth of this scene is
// no longer exact to 1e-6 m, and beyond about 1.3 s not to 1e-3 m.
// A benchmark should therefore compare a time-stepped run with this truth position by
// position only up to the time at which an initial difference the size of the run's
// own error has grown to the tolerance: with e0 the run's error at its first contacts
// (for fixed-step contact handling of order v dt, 1e-3 m at dt = 1e-3 s and v = 1 m/s;
// of order dt^p otherwise), up to T_c = t_first + ln(tol / e0) / lambda, or over the
// first K contacts with e0 G^K < tol (G = 1.4 per contact). The reliable recipe, since
// growth is bursty: run the truth and the truth with its initial state moved by e0 (and
// by one ulp), and end the comparison where either pair differs by the tolerance. Past
// that horizon compare only what chaos does not scramble: energy (with k_r = 1
// conserved here to 1e-12 relative, measured 3e-16), momentum in ball-ball contacts,
// counts and rates of contacts, the time for all balls to come to rest (k_r < 1), or
// distributions (height, speed) over the run.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace stepbench::exact {

using vec2 = Eigen::Vector2d;  // (x, z)

struct ball_scene {
  int n = 0;
  double radius = 0.05;        // m
  double width = 2.0;          // m, box [0, width] in x
  double height = 1.0;         // m, box [0, height] in z
  double gravity = 9.8;        // m/s^2, along -z (the lecture's value); 0 is allowed
  double restitution = 1.0;    // k_r in [0, 1]
  double friction = 0.0;       // k_f in [0, 1]
  double mass = 1.0;           // kg, every ball
  double rest_height = 1e-12;  // m, bounce height below which a ball is put at rest on the floor
  std::vector<vec2> x0, v0;    // initial centres and velocities, n each

  // Empty when the scene is valid: balls inside the box (centres in [r, W - r] x
  // [r, H - r]) and not overlapping (touching is allowed).
  std::string validate() const {
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
};

// A uniform double in [0, 1) from the top 53 bits of one std::mt19937_64 draw. The
// engine's output is fixed by the standard; std::uniform_real_distribution is not (it
// differs between standard libraries), so this keeps a seed's scene the same everywhere.
inline double unit_draw(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

// The default scene, reproducible from a seed. Box W = 2 m, H = 1 m, r = 0.05 m (the
// floor holds 20 balls in a row), g = 9.8, k_r = 1, k_f = 0, m = 1 kg. Balls sit on a
// loose grid of cols = ceil(sqrt(n W / H)) columns and rows = ceil(n / cols) rows of
// cells (cw = W / cols, ch = H / rows), ball i in column i % cols, row i / cols from the
// bottom, at the cell centre plus a jitter uniform in [-jx, jx) x [-jz, jz) with
// jx = (cw / 2 - r) / 2, jz = (ch / 2 - r) / 2 (so no ball leaves its cell: no overlaps).
// Velocity components are uniform in [-2, 2) m/s. Draw order per ball: jitter x, jitter
// z, v_x, v_z, each one unit_draw of std::mt19937_64(seed). Throws
// std::invalid_argument when the cells are too small for the balls (n > 171).
inline ball_scene default_ball_scene(int n = 16, std::uint64_t seed = 1) {
  ball_scene s;
  if (n < 1) throw std::invalid_argument("default_ball_scene: n must be >= 1");
  s.n = n;
  const int cols = static_cast<int>(std::ceil(std::sqrt(n * s.width / s.height)));
  const int rows = (n + cols - 1) / cols;
  const double cw = s.width / cols, ch = s.height / rows;
  if (std::min(cw, ch) <= 2.0 * s.radius)
    throw std::invalid_argument("default_ball_scene: too many balls for a loose grid in the box");
  const double jx = 0.5 * (0.5 * cw - s.radius), jz = 0.5 * (0.5 * ch - s.radius), vmax = 2.0;
  std::mt19937_64 rng(seed);
  auto symmetric = [&](double amp) { return amp * (2.0 * unit_draw(rng) - 1.0); };
  for (int i = 0; i < n; ++i) {
    const double cx = ((i % cols) + 0.5) * cw, cz = ((i / cols) + 0.5) * ch;
    const double dx = symmetric(jx), dz = symmetric(jz);
    s.x0.emplace_back(cx + dx, cz + dz);
    const double vx = symmetric(vmax), vz = symmetric(vmax);
    s.v0.emplace_back(vx, vz);
  }
  return s;
}

enum class contact_kind { left_wall, right_wall, floor, ceiling, ball };

inline const char* to_string(contact_kind k) {
  switch (k) {
    case contact_kind::left_wall:
      return "left_wall";
    case contact_kind::right_wall:
      return "right_wall";
    case contact_kind::floor:
      return "floor";
    case contact_kind::ceiling:
      return "ceiling";
    case contact_kind::ball:
      return "ball";
  }
  return "?";
}

struct contact_event {
  double time;
  contact_kind kind;
  int i;                // the ball; for a pair the lower index
  int j;                // the other ball of a pair, -1 for a wall
  vec2 point;           // the wall's point nearest the centre, or the midpoint of the two centres
  double normal_speed;  // approach speed along the normal before the response (>= 0)
  bool came_to_rest;    // floor contact that ended a bounce sequence: ball i rests from now on
};

// Thrown when the scene reaches a state with no event-driven truth: a sustained contact
// between balls (inelastic collapse). `time` is the last time the truth is exact; a
// benchmark ends its comparison there. i, j: the balls involved (j = -1 for a wall).
struct inelastic_collapse : std::runtime_error {
  inelastic_collapse(double t, int a, int b, const std::string& why)
      : std::runtime_error("event_driven_balls: inelastic collapse at t = " + std::to_string(t) + ": " + why +
                           "; no event-driven truth beyond"),
        time(t),
        i(a),
        j(b) {}
  double time;
  int i, j;
};

namespace detail {

inline constexpr double inf = std::numeric_limits<double>::infinity();

// Real roots of A t^2 + B t + C = 0, ascending, in the form that avoids cancellation
// (q = -(B + sign(B) sqrt(B^2 - 4 A C)) / 2, roots q / A and C / q). Returns the count.
inline int quadratic_roots(double A, double B, double C, double r[2]) {
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
inline double uniform_pair_delay(const vec2& d, const vec2& u, double s) {
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
inline double accelerated_pair_delay(const vec2& d, const vec2& u, const vec2& a, double s, double T,
                                     double depth_tol) {
  if (!(T >= 0.0) || !std::isfinite(T)) return inf;
  // Cannot touch before T: the gap exceeds what the relative motion can close.
  if (d.norm() - s > T * (u.norm() + 0.5 * a.norm() * T)) return inf;
  auto f = [&](double t) -> double {
    const vec2 p = d + t * (u + 0.5 * t * a);
    return p.squaredNorm() - s * s;
  };
  auto f_df = [&](double t) -> std::pair<double, double> {
    const vec2 p = d + t * (u + 0.5 * t * a), w = u + t * a;
    return {p.squaredNorm() - s * s, 2.0 * p.dot(w)};
  };
  auto df_ddf = [&](double t) -> std::pair<double, double> {
    const vec2 p = d + t * (u + 0.5 * t * a), w = u + t * a;
    return {2.0 * p.dot(w), 2.0 * (w.squaredNorm() + p.dot(a))};
  };
  const double df0 = 2.0 * d.dot(u);
  if (T == 0.0) return (f(0.0) <= 0.0 && df0 < 0.0) ? 0.0 : inf;

  // f''/2 = 3/2 |a|^2 t^2 + 3 (u.a) t + (|u|^2 + d.a).
  double r2[2];
  const int n2 = quadratic_roots(1.5 * a.squaredNorm(), 3.0 * u.dot(a), u.squaredNorm() + d.dot(a), r2);
  std::array<double, 4> bp{0.0, 0.0, 0.0, 0.0};
  int nb = 0;
  bp[nb++] = 0.0;
  for (int k = 0; k < n2; ++k)
    if (r2[k] > bp[nb - 1] && r2[k] < T) bp[nb++] = r2[k];
  bp[nb++] = T;

  std::array<double, 5> cp{0.0, 0.0, 0.0, 0.0, 0.0};
  int nc = 0;
  cp[nc++] = 0.0;
  for (int k = 0; k + 1 < nb; ++k) {
    const double g0 = df_ddf(bp[k]).first, g1 = df_ddf(bp[k + 1]).first;
    if ((g0 < 0.0 && g1 > 0.0) || (g0 > 0.0 && g1 < 0.0)) {
      const double root = bracketed_root(df_ddf, bp[k], bp[k + 1], g0);
      if (root > cp[nc - 1] && root < T) cp[nc++] = root;
    }
  }
  cp[nc++] = T;

  std::array<double, 5> fc{0.0, 0.0, 0.0, 0.0, 0.0};
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

}  // namespace detail

class event_driven_balls {
 public:
  explicit event_driven_balls(const ball_scene& scene) : s_(scene) {
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

  // Processes every event at or before t, then evaluates all balls at t on their
  // parabolas. t must be finite and not precede the last processed event. Throws
  // inelastic_collapse (leaving the state at the collapse time) when t lies beyond a
  // collapse, now or on any later call.
  void advance_to(double t) {
    if (!(t >= t_last_) || !std::isfinite(t))
      throw std::invalid_argument("event_driven_balls::advance_to: t must be finite and not before the last event");
    while (!collapse_ && next_.time <= t) process_next();
    if (collapse_ && t > collapse_->time) {
      set_now(collapse_->time);
      throw *collapse_;
    }
    set_now(t);
  }

  // Processes the next event if it happens at or before t_max and leaves the state at
  // its time; returns false (state unchanged) otherwise. Throws inelastic_collapse when
  // the next event cannot be found.
  bool next_event(double t_max) {
    if (collapse_) throw *collapse_;
    if (!(next_.time <= t_max)) return false;
    process_next();
    if (collapse_) throw *collapse_;
    set_now(t_last_);
    return true;
  }

  double time() const { return t_now_; }
  double last_event_time() const { return t_last_; }
  double next_event_time() const { return next_.time; }  // inf when none (or after a collapse)
  // The time up to which the truth exists: inf unless an inelastic collapse was met.
  double collapse_time() const { return collapse_ ? collapse_->time : detail::inf; }
  int size() const { return s_.n; }
  const ball_scene& scene() const { return s_; }
  const std::vector<vec2>& positions() const { return x_now_; }
  const std::vector<vec2>& velocities() const { return v_now_; }
  const std::vector<contact_event>& events() const { return events_; }
  bool resting(int i) const { return resting_[static_cast<std::size_t>(i)] != 0; }
  int resting_count() const { return static_cast<int>(std::count(resting_.begin(), resting_.end(), 1)); }

  // Kinetic plus potential energy, sum m |v|^2 / 2 + m g z, at time().
  double energy() const {
    double e = 0.0;
    for (int i = 0; i < s_.n; ++i) e += 0.5 * v_now_[i].squaredNorm() + s_.gravity * x_now_[i].y();
    return s_.mass * e;
  }
  vec2 momentum() const {
    vec2 p = vec2::Zero();
    for (const vec2& v : v_now_) p += v;
    return s_.mass * p;
  }

 private:
  // A contact's identity and tie-break key: the (lower) ball, then slot 0..3 for the
  // walls left, right, floor, ceiling and 4 + j for the pair (i, j).
  struct key {
    int i, slot;
    bool operator==(const key&) const = default;
  };
  struct candidate {
    double time;  // absolute
    key k;
  };
  static constexpr int pair_slot = 4;

  double g_of(std::size_t i) const { return resting_[i] ? 0.0 : s_.gravity; }

  // Ball i on its parabola from its anchor.
  void evaluate(std::size_t i, double t, vec2& x, vec2& v) const {
    const double tau = t - t_ref_[i], g = g_of(i);
    const vec2& x0 = x_ref_[i];
    const vec2& v0 = v_ref_[i];
    x = {x0.x() + v0.x() * tau, x0.y() + tau * (v0.y() - 0.5 * g * tau)};
    v = {v0.x(), v0.y() - g * tau};
  }
  void set_now(double t) {
    t_now_ = t;
    for (std::size_t i = 0; i < x_now_.size(); ++i) evaluate(i, t, x_now_[i], v_now_[i]);
  }

  // Delay from the base state to ball i's contact with wall w, or inf.
  double wall_delay(std::size_t i, int w) const {
    const double r = s_.radius, g = s_.gravity;
    const vec2 &x = x_base_[i], &v = v_base_[i];
    switch (w) {
      case 0:
        return v.x() < 0.0 ? std::max(x.x() - r, 0.0) / -v.x() : detail::inf;
      case 1:
        return v.x() > 0.0 ? std::max(s_.width - r - x.x(), 0.0) / v.x() : detail::inf;
      case 2: {
        if (resting_[i]) return detail::inf;
        const double gap = std::max(x.y() - r, 0.0), vz = v.y();
        if (vz < 0.0) return 2.0 * gap / (std::sqrt(vz * vz + 2.0 * g * gap) - vz);
        return g > 0.0 ? (vz + std::sqrt(vz * vz + 2.0 * g * gap)) / g : detail::inf;
      }
      default: {
        if (resting_[i] || !(v.y() > 0.0)) return detail::inf;
        const double gap = std::max(s_.height - r - x.y(), 0.0), vz = v.y();
        const double disc = vz * vz - 2.0 * g * gap;
        return disc > 0.0 ? 2.0 * gap / (vz + std::sqrt(disc)) : detail::inf;
      }
    }
  }

  // Latest contact of every ball it involves: such a contact is not re-triggered at
  // zero delay; one that cannot recur without another event is not re-triggered at all.
  bool is_repeat(const key& k) const {
    if (k.slot < pair_slot) return last_[static_cast<std::size_t>(k.i)] == k;
    return last_[static_cast<std::size_t>(k.i)] == k && last_[static_cast<std::size_t>(k.slot - pair_slot)] == k;
  }

  void find_next_event() {
    const std::size_t n = x_ref_.size();
    for (std::size_t i = 0; i < n; ++i) evaluate(i, t_last_, x_base_[i], v_base_[i]);
    const double s = 2.0 * s_.radius;
    candidate best{detail::inf, {s_.n, 0}};
    auto offer = [&](double delay, key k) {
      const double t = t_last_ + delay;
      if (t < best.time || (t == best.time && (k.i < best.k.i || (k.i == best.k.i && k.slot < best.k.slot))))
        best = {t, k};
    };
    for (std::size_t i = 0; i < n; ++i)
      for (int w = 0; w < 4; ++w) {
        const double delay = wall_delay(i, w);
        const key k{static_cast<int>(i), w};
        if (delay == detail::inf || (is_repeat(k) && (t_last_ + delay == t_last_ || w != 2))) continue;
        offer(delay, k);
      }
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) {
        if (resting_[i] != resting_[j]) continue;
        const key k{static_cast<int>(i), pair_slot + static_cast<int>(j)};
        if (is_repeat(k)) continue;
        const double delay = detail::uniform_pair_delay(x_base_[j] - x_base_[i], v_base_[j] - v_base_[i], s);
        if (delay != detail::inf) offer(delay, k);
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
        const double delay = detail::accelerated_pair_delay(x_base_[j] - x_base_[i], v_base_[j] - v_base_[i], a, s,
                                                            window, s_.rest_height);
        if (delay == detail::inf) continue;
        if (is_repeat(k) && t_last_ + delay == t_last_) {
          const auto other = resting_[i] ? i : j;
          collapse_.emplace(
              t_last_, static_cast<int>(flying), static_cast<int>(other),
              "ball " + std::to_string(flying) + " stays in contact with resting ball " + std::to_string(other));
          next_ = {detail::inf, {s_.n, 0}};
          return;
        }
        offer(delay, k);
      }
    next_ = best;
  }

  void process_next() {
    const candidate c = next_;
    const double t = c.time;
    same_time_ = (!events_.empty() && events_.back().time == t) ? same_time_ + 1 : 0;
    if (same_time_ > max_same_time_) {
      collapse_.emplace(t, c.k.i, c.k.slot < pair_slot ? -1 : c.k.slot - pair_slot,
                        "more than " + std::to_string(max_same_time_) + " events at one time");
      next_ = {detail::inf, {s_.n, 0}};
      return;
    }
    const double r = s_.radius, kr = s_.restitution, kf = s_.friction;
    contact_event ev{t, contact_kind::ball, c.k.i, -1, vec2::Zero(), 0.0, false};
    const auto i = static_cast<std::size_t>(c.k.i);
    vec2 xi, vi;
    evaluate(i, t, xi, vi);
    if (c.k.slot < pair_slot) {
      // Wall: snap the centre onto the contact line, apply v <- (1 - k_f) v_t - k_r v_n.
      switch (c.k.slot) {
        case 0:
          ev.kind = contact_kind::left_wall;
          ev.normal_speed = -vi.x();
          xi.x() = r;
          vi = {-kr * vi.x(), (1.0 - kf) * vi.y()};
          ev.point = {0.0, xi.y()};
          break;
        case 1:
          ev.kind = contact_kind::right_wall;
          ev.normal_speed = vi.x();
          xi.x() = s_.width - r;
          vi = {-kr * vi.x(), (1.0 - kf) * vi.y()};
          ev.point = {s_.width, xi.y()};
          break;
        case 2:
          ev.kind = contact_kind::floor;
          ev.normal_speed = -vi.y();
          xi.y() = r;
          vi = {(1.0 - kf) * vi.x(), -kr * vi.y()};
          ev.point = {xi.x(), 0.0};
          // Zeno guard: a bounce lower than rest_height ends the bounce sequence.
          if (s_.gravity > 0.0 && vi.y() * vi.y() < w_rest_sq_) {
            vi.y() = 0.0;
            if (kf > 0.0) vi.x() = 0.0;  // the limit of (1 - k_f)^n over the remaining bounces
            resting_[i] = 1;
            ev.came_to_rest = true;
          }
          break;
        default:
          ev.kind = contact_kind::ceiling;
          ev.normal_speed = vi.y();
          xi.y() = s_.height - r;
          vi = {(1.0 - kf) * vi.x(), -kr * vi.y()};
          ev.point = {xi.x(), s_.height};
          break;
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

  // New anchor after a contact. A resting ball given vertical speed flies again (if
  // pushed into the floor, the floor contact follows at zero delay).
  void anchor(std::size_t i, double t, const vec2& x, const vec2& v) {
    if (resting_[i] && v.y() != 0.0) resting_[i] = 0;
    t_ref_[i] = t;
    x_ref_[i] = x;
    v_ref_[i] = v;
  }

  ball_scene s_;
  std::vector<vec2> x_ref_, v_ref_;  // anchors: state of each ball at t_ref_
  std::vector<double> t_ref_;
  std::vector<char> resting_;
  std::vector<key> last_;              // latest contact of each ball
  std::vector<vec2> x_base_, v_base_;  // all balls at t_last_ (scan workspace)
  std::vector<vec2> x_now_, v_now_;    // all balls at t_now_
  std::vector<contact_event> events_;
  candidate next_{detail::inf, {0, 0}};
  double t_last_ = 0.0, t_now_ = 0.0, w_rest_sq_ = 0.0;
  long same_time_ = 0, max_same_time_ = 0;
  std::optional<inelastic_collapse> collapse_;
};

}  // namespace stepbench::exact
