#pragma once
// The exact truth for the lecture's closing example program, many bouncing balls in a
// box, by event-driven simulation: between contacts every ball flies on
// its parabola, so the state is known in closed form; contact times are roots of
// polynomials; at a contact the lecture's collision response is applied.
//
// Scene: N equal balls (radius r, mass m) in the box [0, W] x [0, H]; x horizontal, z
// vertical (stored as the second component), gravity g along -z, walls on all four sides.
//
// Contact response, the lecture's rule (momentum and collisions), exactly as implemented:
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
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
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
  std::string validate() const;
};

// A uniform double in [0, 1) from the top 53 bits of one std::mt19937_64 draw. The
// engine's output is fixed by the standard; std::uniform_real_distribution is not (it
// differs between standard libraries), so this keeps a seed's scene the same everywhere.
inline double unit_draw(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

// A scene reproducible from a seed: s.n balls placed in the box W x H and radius r of s
// (x0 and v0 replaced). Balls sit on a loose grid of cols = ceil(sqrt(n W / H)) columns
// and rows = ceil(n / cols) rows of cells (cw = W / cols, ch = H / rows), ball i in
// column i % cols, row i / cols from the bottom, at the cell centre plus a jitter uniform
// in [-jx, jx) x [-jz, jz) with jx = (cw / 2 - r) / 2, jz = (ch / 2 - r) / 2 (so no ball
// leaves its cell: no overlaps). Velocity components are uniform in [-2, 2) m/s. Draw
// order per ball: jitter x, jitter z, v_x, v_z, each one unit_draw of
// std::mt19937_64(seed). Returns the smaller side of a cell, which must exceed 2 r. In
// the default box (W = 2 m, H = 1 m, r = 0.05 m: the floor holds 20 balls in a row) the
// cells are too small for more than 171 balls; that scene with g = 9.8, k_r = 1, k_f = 0,
// m = 1 kg is the tests' default_ball_scene (tests/default_ball_scene.hpp).
double place_on_grid(ball_scene& s, std::uint64_t seed);

enum class contact_kind { left_wall, right_wall, floor, ceiling, ball };  // the walls in slot order

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
  inelastic_collapse(double t, int a, int b, const std::string& why);
  double time;
  int i, j;
};

class event_driven_balls {
 public:
  explicit event_driven_balls(const ball_scene& scene);

  // Processes every event at or before t, then evaluates all balls at t on their
  // parabolas. t must be finite and not precede the last processed event. Throws
  // inelastic_collapse (leaving the state at the collapse time) when t lies beyond a
  // collapse, now or on any later call.
  void advance_to(double t);

  // Processes the next event if it happens at or before t_max and leaves the state at
  // its time; returns false (state unchanged) otherwise. Throws inelastic_collapse when
  // the next event cannot be found.
  bool next_event(double t_max);

  double time() const { return t_now_; }
  double last_event_time() const { return t_last_; }
  double next_event_time() const { return next_.time; }  // inf when none (or after a collapse)
  // The time up to which the truth exists: inf unless an inelastic collapse was met.
  double collapse_time() const { return collapse_ ? collapse_->time : std::numeric_limits<double>::infinity(); }
  int size() const { return s_.n; }
  const ball_scene& scene() const { return s_; }
  const std::vector<vec2>& positions() const { return x_now_; }
  const std::vector<vec2>& velocities() const { return v_now_; }
  const std::vector<contact_event>& events() const { return events_; }
  bool resting(int i) const { return resting_[static_cast<std::size_t>(i)] != 0; }

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
  void evaluate(std::size_t i, double t, vec2& x, vec2& v) const;
  void set_now(double t);
  // Delay from the base state to ball i's contact with wall w, or inf.
  double wall_delay(std::size_t i, int w) const;
  // Latest contact of every ball it involves: such a contact is not re-triggered at
  // zero delay; one that cannot recur without another event is not re-triggered at all.
  bool is_repeat(const key& k) const;
  void find_next_event();
  void process_next();
  // New anchor after a contact. A resting ball given vertical speed flies again (if
  // pushed into the floor, the floor contact follows at zero delay).
  void anchor(std::size_t i, double t, const vec2& x, const vec2& v);

  ball_scene s_;
  std::vector<vec2> x_ref_, v_ref_;  // anchors: state of each ball at t_ref_
  std::vector<double> t_ref_;
  std::vector<char> resting_;
  std::vector<key> last_;              // latest contact of each ball
  std::vector<vec2> x_base_, v_base_;  // all balls at t_last_ (scan workspace)
  std::vector<vec2> x_now_, v_now_;    // all balls at t_now_
  std::vector<contact_event> events_;
  candidate next_{std::numeric_limits<double>::infinity(), {0, 0}};
  double t_last_ = 0.0, t_now_ = 0.0, w_rest_sq_ = 0.0;
  long same_time_ = 0, max_same_time_ = 0;
  std::optional<inelastic_collapse> collapse_;
};

}  // namespace stepbench::exact
