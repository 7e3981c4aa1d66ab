#pragma once
// The game loop around the integrator (the lecture's game loop; G. Fiedler, "Fix Your
// Timestep!", 2004): a display clock shows frames at times the integrator does not
// choose, and each loop design decides what physics runs between two frames and which
// state is drawn. Simulated here per (problem, integrator): the whole run inlines, with
// no virtual call per physics step.
//
// Designs (one frame = the time between two displayed frames):
//   variable      one step of dt = the frame time; the new state is shown
//   fixed         the accumulator: accumulator += frame time; while it holds a whole
//                 dt, step dt and take dt off; the latest physics state is shown
//   interpolated  the same loop, showing previous * (1 - alpha) + current * alpha with
//                 alpha = accumulator / dt (in [0, 1))
//   substeps      k = ceil(physics rate / display rate) steps of frame time / k a frame
//                 (Box2D v3's and bepuphysics2's habit); the new state is shown
// The frame time is clamped (the lecture's 0.25 s) before it is used, when the clamp is
// on: a long pause then costs at most clamp / dt steps, and the game time falls behind
// the wall clock by what was cut.
//
// Clocks: the display interval is 1 / display rate; with jitter it is
// (1 + j (2u - 1)) / display rate, u uniform in [0, 1) from the top 53 bits of
// std::mt19937_64(seed) (a generator the standard defines output for output, so a seed
// gives the same frames on every platform; std's distributions are not so defined); a
// stall makes the frame that begins at or after `stall_at_s` on the wall clock last
// `stall_s` (an alt-tab).
//
// The run ends when the game clock reaches the horizon: the last frame is shortened to
// land on it. Every displayed frame's display time is the game clock after it: what the
// game believes the time is, the time the exact state is taken at.
//
// Stages per frame, as core/drive.hpp names them per step: the timer (frame time,
// clamp, accumulator: how many steps of what length), then per step advance and
// after_step, then record (the state the design shows).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/concepts.hpp"
#include "core/drive.hpp"
#include "core/system.hpp"

namespace stepbench {

enum class loop_design { variable, fixed, interpolated, substeps };
inline constexpr std::array<loop_design, 4> all_loop_designs{loop_design::variable, loop_design::fixed,
                                                             loop_design::interpolated, loop_design::substeps};

inline std::string_view to_string(loop_design d) {
  constexpr std::string_view names[] = {"variable", "fixed", "interpolated", "substeps"};
  return names[static_cast<int>(d)];
}

// The designs that step a fixed dt from an accumulator.
constexpr bool uses_accumulator(loop_design d) { return d == loop_design::fixed || d == loop_design::interpolated; }

// A step is taken while the accumulator holds a whole dt up to this relative slack, so
// that a run whose horizon is a whole number of steps (10 s at 60 Hz) takes all of them
// on every clock, whatever the rounding of the frame times summed into the accumulator.
inline constexpr double accumulator_slack = 1e-9;

struct loop_config {
  loop_design design = loop_design::fixed;
  double display_hz = 60.0;
  double physics_hz = 60.0;  // fixed, interpolated: dt = 1 / physics_hz; substeps: k from it; variable: unused
  double clamp_s = 0.25;     // the frame-time clamp; 0: off
  std::optional<std::uint64_t> jitter_seed;                      // jittered frame times, from this seed
  double jitter = 0.25;                                          // their relative half-width j
  double stall_at_s = std::numeric_limits<double>::quiet_NaN();  // NaN: no stall
  double stall_s = 1.0;
  double horizon = 0.0;  // the game time at which the run ends

  double dt() const { return 1.0 / physics_hz; }
  // Steps per frame of the substeps design: enough that none is longer than the physics dt
  // at the nominal display rate.
  int substeps() const { return std::max(1, static_cast<int>(std::ceil(physics_hz / display_hz * (1.0 - 1e-12)))); }
  bool stalls() const { return !std::isnan(stall_at_s); }
  // The longest interval the display clock can produce.
  double longest_interval() const {
    double longest = (1.0 + (jitter_seed ? jitter : 0.0)) / display_hz;
    return stalls() ? std::max(longest, stall_s) : longest;
  }
};

// Frames and steps a configuration may ask for before it is refused as bad input.
inline constexpr double max_loop_frames = 1e7;
inline constexpr double max_loop_steps = 1e9;

// "" when the configuration can run, else the reason in one line (the command line's
// words for the options).
inline std::string loop_config_error(const loop_config& c) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(c.display_hz)) return fmt::format("--display-hz must be > 0, got {:g}", c.display_hz);
  if (!positive(c.physics_hz)) return fmt::format("--physics-hz must be > 0, got {:g}", c.physics_hz);
  if (!positive(c.horizon)) return fmt::format("the horizon must be > 0, got {:g}", c.horizon);
  if (!(std::isfinite(c.clamp_s) && c.clamp_s >= 0.0))
    return fmt::format("--clamp must be a time > 0 or off, got {:g}", c.clamp_s);
  if (c.clamp_s > 0.0 && c.design != loop_design::variable && c.clamp_s < c.dt())
    return fmt::format(
        "--clamp {:g} s is below the physics dt {:g} s (1 / --physics-hz): a clamped frame could not "
        "hold one step",
        c.clamp_s, c.dt());
  if (c.jitter_seed && !(c.jitter >= 0.0 && c.jitter < 1.0))
    return fmt::format("the jitter must be in [0, 1), got {:g}", c.jitter);
  if (c.stalls()) {
    if (!(std::isfinite(c.stall_at_s) && c.stall_at_s >= 0.0))
      return fmt::format("--stall-at must be a time >= 0, got {:g}", c.stall_at_s);
    if (!positive(c.stall_s)) return fmt::format("the stall must last > 0 s, got {:g}", c.stall_s);
    if (c.stall_at_s + c.stall_s > c.horizon)
      return fmt::format("--stall-at {:g}: a {:g} s stall from there is longer than the run ({:g} s)", c.stall_at_s,
                         c.stall_s, c.horizon);
  }
  const double frames = c.horizon * c.display_hz * (c.jitter_seed ? 1.0 / (1.0 - c.jitter) : 1.0);
  if (frames > max_loop_frames)
    return fmt::format("the run would show {:.3g} frames (horizon x --display-hz); the limit is {:g}", frames,
                       max_loop_frames);
  const double steps = c.design == loop_design::variable   ? frames
                       : c.design == loop_design::substeps ? frames * c.substeps()
                                                           : c.horizon * c.physics_hz;
  if (steps > max_loop_steps)
    return fmt::format("the run would take {:.3g} physics steps; the limit is {:g}", steps, max_loop_steps);
  return {};
}

// One frame as the timer plans it.
struct frame_plan {
  double display_interval = 0.0;  // the display clock's interval: the frame's budget
  double interval = 0.0;    // wall duration of the frame: the clock's, or longer when the previous frame's work overran
  double frame_time = 0.0;  // game time it consumes: the interval clamped, shortened to land on the horizon
  double game_t = 0.0;      // the game clock after it: the display time of the state it shows
  double wall_t = 0.0;      // the wall clock after it
  int steps = 0;            // physics steps it takes
  double h = 0.0;           // their length
  double alpha = std::numeric_limits<double>::quiet_NaN();  // accumulator / dt after the steps (accumulator designs)
  bool clamped = false;                                     // the clamp cut its frame time
  bool stall = false;                                       // the clock's stall
  bool last = false;                                        // it lands on the horizon
};

// The loop's timing, without the physics: the display clock, the clamp, the accumulator,
// the end at the horizon. The physics loop below and the cost model (schedule_loop) both
// run on it, so they take the same frames and the same steps.
class loop_timer {
 public:
  explicit loop_timer(const loop_config& c)
      : c_(c), rng_(c.jitter_seed.value_or(0)), stall_pending_(c.stalls()), dt_(c.dt()), k_(c.substeps()) {}

  bool done() const { return done_; }
  double dt() const { return dt_; }

  // The next frame. `previous_work_s`: the wall time the previous frame's physics took,
  // when a cost model gives one: a frame cannot end before its work is done, so a
  // frame whose work overran its interval lasts as long as its work (the late frame's
  // time is the next frame time: the feedback behind the spiral of death).
  frame_plan next(double previous_work_s = 0.0) {
    frame_plan f;
    // The display clock's interval for the frame that begins at wall_: the stall's, once
    // the wall clock reaches it, else 1 / display rate, jittered when seeded.
    f.display_interval = 1.0 / c_.display_hz;
    if (stall_pending_ && wall_ >= c_.stall_at_s) {
      stall_pending_ = false;
      f.stall = true;
      f.display_interval = c_.stall_s;
    } else if (c_.jitter_seed) {
      const double u = static_cast<double>(rng_() >> 11) * 0x1.0p-53;  // [0, 1), 53 random bits
      f.display_interval = (1.0 + c_.jitter * (2.0 * u - 1.0)) / c_.display_hz;
    }
    f.interval = std::max(f.display_interval, previous_work_s);
    wall_ += f.interval;
    f.wall_t = wall_;
    double ft = f.interval;
    if (c_.clamp_s > 0.0 && ft > c_.clamp_s) ft = c_.clamp_s, f.clamped = true;
    if (game_ + ft >= c_.horizon * (1.0 - 1e-12)) {
      ft = c_.horizon - game_;
      f.last = true;
      done_ = true;
      game_ = c_.horizon;
    } else {
      game_ += ft;
    }
    f.frame_time = ft;
    f.game_t = game_;
    switch (c_.design) {
      case loop_design::variable:
        f.steps = 1;
        f.h = ft;
        break;
      case loop_design::substeps:
        f.steps = k_;
        f.h = ft / k_;
        break;
      default:
        accumulator_ += ft;
        while (accumulator_ >= dt_ * (1.0 - accumulator_slack)) {
          accumulator_ -= dt_;
          ++f.steps;
        }
        f.h = dt_;
        // Never below 0 (the slack may leave -1e-9 dt) and below 1 (the loop took every
        // whole dt): interpolation never extrapolates.
        f.alpha = std::max(accumulator_, 0.0) / dt_;
    }
    return f;
  }

 private:
  loop_config c_;
  std::mt19937_64 rng_;
  bool stall_pending_;
  double dt_;
  int k_;
  double wall_ = 0.0, game_ = 0.0, accumulator_ = 0.0;
  bool done_ = false;
};

// A simulated run: what each frame showed, and the physics at the end. Frame j is the
// j-th displayed frame after t = 0 (the initial state, shown at t = 0, is not a frame).
struct loop_result {
  int dim = 0;
  std::vector<double> display_t;   // the game clock at each frame
  std::vector<double> interval;    // the frame's wall duration
  std::vector<double> frame_time;  // the game time it consumed
  std::vector<double> shown_t;     // the simulated time of the state it showed (n dt; the blend's (n - 1 + alpha) dt)
  std::vector<double> alpha;       // accumulator / dt after its steps; NaN for variable and substeps
  std::vector<int> steps;          // physics steps it took
  std::vector<std::int8_t> clamped, stall;
  std::vector<double> shown;          // the shown position, dim per frame
  std::vector<double> final_physics;  // [x; v] after the last whole physics step
  std::vector<double> final_shown;    // [x; v] shown at the last frame (display time = the horizon)
  double physics_t = 0.0;             // the simulated time of final_physics
  long physics_steps = 0;
  work_counters work{};
  bool non_finite = false;  // a NaN or Inf appeared: the run stopped at that frame

  std::size_t frames() const { return display_t.size(); }
  template <class X>
  void record(const frame_plan& f, double t_shown, const Eigen::MatrixBase<X>& x) {
    display_t.push_back(f.game_t);
    interval.push_back(f.interval);
    frame_time.push_back(f.frame_time);
    shown_t.push_back(t_shown);
    alpha.push_back(f.alpha);
    steps.push_back(f.steps);
    clamped.push_back(f.clamped);
    stall.push_back(f.stall);
    shown.insert(shown.end(), x.derived().data(), x.derived().data() + x.size());
  }
};

// Runs `cfg` (checked with loop_config_error first) for one problem and integrator: one
// instance per pair, the design a run-time choice. Not flattened as drive() is: the loop
// study's runs are measured for what they show, not timed, and a flattened copy of every
// step in every pair's loop cost the build more than the rest of it (an implicit step on
// n_pendulum flattened into the loop: 74 s to compile against 10 s).
template <problem P, integrator I>
loop_result simulate_loop(const P& problem, const I& method, const loop_config& cfg) {
  using Vec = typename P::vec;
  const loop_design design = cfg.design;
  const bool accumulator = uses_accumulator(design);
  counted_system<P> sys{problem};
  step_state<Vec> s = start_state(problem);
  stepper_t<I, counted_system<P>> stepper(method);
  prepare_stepper(stepper, sys, s.x);
  // The state a step started from, for the blend. It starts as the initial state: the
  // lecture's snippet blends a state it never initialised; before the first step the
  // correct blend is the initial state itself.
  Vec previous_x = s.x, previous_v = s.v;
  Vec shown_x = s.x, shown_v = s.v;  // workspace for the blend

  // Contacts in `locate` mode are found inside the step, as in drive() (core/drive.hpp's
  // advance stage; `contacts` is its record of them, unused here).
  step_state<Vec> start = s;
  drive_result<Vec> contacts;
  contacts.start(problem.dim(), 0);
  auto advance = [&](double t, double h) {
    if constexpr (has_contacts<P>) {
      if (problem.locate_contacts()) return advance_locating(problem, stepper, sys, t, s, h, start, contacts);
    }
    stepper.step(sys, t, s, h);
  };

  loop_timer timer(cfg);
  loop_result out;
  out.dim = problem.dim();
  const double expected = cfg.horizon * cfg.display_hz * 1.5 + 2.0;
  out.display_t.reserve(static_cast<std::size_t>(expected));
  const double dt = timer.dt();
  long n = 0;            // whole steps of the accumulator designs
  double t_frame = 0.0;  // the game time at the start of a frame (variable, substeps)
  while (!timer.done()) {
    const frame_plan f = timer.next();
    for (int i = 0; i < f.steps; ++i) {
      // advance (t = n dt on the accumulator designs, not a running sum: the step sees the
      // same time on every clock), then after_step
      if (design == loop_design::interpolated) previous_x = s.x, previous_v = s.v;
      if (accumulator) {
        advance(static_cast<double>(n) * dt, dt);
        ++n;
        stepbench::after_step(problem, static_cast<double>(n) * dt, s);
      } else {
        advance(t_frame + i * f.h, f.h);
        stepbench::after_step(problem, i + 1 == f.steps ? f.game_t : t_frame + (i + 1) * f.h, s);
      }
    }
    if (!accumulator) n += f.steps;
    t_frame = f.game_t;
    // record: the state the design shows
    if (design == loop_design::interpolated) {
      shown_x = (1.0 - f.alpha) * previous_x + f.alpha * s.x;
      shown_v = (1.0 - f.alpha) * previous_v + f.alpha * s.v;
      out.record(f, n == 0 ? 0.0 : (static_cast<double>(n - 1) + f.alpha) * dt, shown_x);
    } else if (design == loop_design::fixed) {
      out.record(f, static_cast<double>(n) * dt, s.x);
    } else {
      out.record(f, f.game_t, s.x);
    }
    if (!all_finite(s.x, s.v)) {
      out.non_finite = true;
      break;
    }
  }
  out.physics_steps = n;
  out.physics_t = accumulator ? static_cast<double>(n) * dt : t_frame;
  out.final_physics = stacked(s.x, s.v);
  out.final_shown = design == loop_design::interpolated ? stacked(shown_x, shown_v) : out.final_physics;
  out.work = sys.work;
  return out;
}

// The cost model. Each physics step costs `step_cost_s` of wall time; a frame lasts
// its display interval or its physics work, whichever is longer, and the next frame's
// frame time is that duration. The run to the horizon gives the frames' work; then
// the loop is followed on the clock's steady frames for up to `settle_frames` more:
//   keeps_up     the work fits the frames again (at once, or after catching up)
//   slow_motion  the frames stay late but bounded: the clamp caps the steps a frame,
//                and the game runs slower than the wall clock
//   spiral       a frame's work grew past spiral_factor x the longest frame the clock
//                or the clamp allows: each late frame asks for more steps than the last
// A spiral needs a step to cost more than the simulated time it advances (work per
// game second > 1); `load` is that ratio over the run.
enum class loop_outcome { keeps_up, slow_motion, spiral };
inline std::string_view to_string(loop_outcome o) {
  constexpr std::string_view names[] = {"keeps_up", "slow_motion", "spiral"};
  return names[static_cast<int>(o)];
}

struct loop_schedule {
  double frame_budget_s = 0.0;  // 1 / display rate
  long frames = 0;              // frames to the horizon
  long late_frames = 0;         // frames whose physics work outlasted their display interval (their budget)
  int steps_max = 0;            // most steps in one frame (with the feedback)
  double worst_work_s = 0.0;    // the most physics work in one frame
  double load = 0.0;            // physics work over the game time it advanced, over the run
  double wall_s = 0.0;          // wall time the run took to reach the horizon
  loop_outcome outcome = loop_outcome::keeps_up;
};

inline constexpr double spiral_factor = 10.0;
inline constexpr long settle_frames = 10000;

inline loop_schedule schedule_loop(const loop_config& cfg, double step_cost_s) {
  loop_schedule out;
  out.frame_budget_s = 1.0 / cfg.display_hz;
  loop_config endless = cfg;
  endless.horizon = std::numeric_limits<double>::infinity();
  loop_timer timer(endless);
  const double cap = spiral_factor * std::max(cfg.longest_interval(), cfg.clamp_s);
  double work = 0.0, total_work = 0.0, game = 0.0;
  long after = 0, fitting = 0;
  while (true) {
    const frame_plan f = timer.next(work);
    if (f.interval > cap) {
      out.outcome = loop_outcome::spiral;
      break;
    }
    work = step_cost_s * f.steps;
    const bool late = work > f.display_interval;
    if (f.game_t <= cfg.horizon) {
      ++out.frames;
      out.late_frames += late;
      out.steps_max = std::max(out.steps_max, f.steps);
      out.worst_work_s = std::max(out.worst_work_s, work);
      total_work += work;
      game = f.game_t;
      out.wall_s = f.wall_t;
      continue;
    }
    // After the horizon: has the loop caught up, for 10 frames in a row?
    fitting = late ? 0 : fitting + 1;
    if (fitting >= 10) break;
    if (++after >= settle_frames) {
      out.outcome = loop_outcome::slow_motion;
      break;
    }
  }
  out.load = game > 0.0 ? total_work / game : 0.0;
  return out;
}

}  // namespace stepbench
