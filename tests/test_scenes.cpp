// Scene files (docs/scenes.md, problems/scene.hpp, problems/scene_file.cpp): the built-in
// scenes re-expressed as files step as the built-ins do, a closed form, the Pleiades
// end positions published by the IVP test set, the analytic Jacobians against
// differences, the energy, and every bad-file case refused in one line with its place.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "problems/scene_file.hpp"
#include "references/reference.hpp"
#include "registry/registry.hpp"
#include "registry/scenes.hpp"

namespace stepbench {
namespace {

std::string scene_path(const std::string& file) { return std::string(STEPBENCH_SCENE_DIR) + "/" + file; }

// The moving masses' positions of a run's samples: the built-in spring_chain carries its
// pinned mass (coordinates 0..2) in the state, the scene file does not.
std::vector<double> positions(const run_result& r, int dim, int skip) {
  std::vector<double> out;
  for (const auto& y : r.sample_y) out.insert(out.end(), y.begin() + skip, y.begin() + dim);
  return out;
}

struct equivalence {
  std::string file, builtin;
  int skip = 0;  // leading coordinates of the built-in's state the scene does not hold
  double dt = 0.0;
  int methods = 0;  // how many run on both (and are compared): `stepbench list --json`, 2026-12-06
};

// Every method that runs on both, at one step size (fixed-step) or tolerance (adaptive):
// the same positions at every sample. Bit for bit is what the arithmetic gives (the scene
// keeps the built-in's order of operations, problems/scene.hpp); 1e-12 relative is the
// bound the issue asks. An adaptive method's error norm is an RMS over the state, so on the
// rope, whose built-in state carries the pinned mass's six zero coordinates, its steps
// differ: there the fixed-step methods are compared.
TEST(scene_files, the_built_in_scenes_as_files_step_as_the_built_ins) {
  // The smooth scenes share 29 methods with their built-ins (the built-ins' constraint
  // group does not run on a scene); the rope's 18 fixed-step ones are compared; the
  // bouncing ball's 13 are the methods that run on contacts.
  const std::vector<equivalence> cases{{"damped_spring.toml", "damped_spring", 0, 10.0 / 512, 29},
                                       {"stiff_spring.toml", "stiff_spring", 0, (32.0 / 60) / 4096, 29},
                                       {"projectile.toml", "projectile", 0, 0.05, 29},
                                       {"falling_drag.toml", "falling_drag", 0, 5.0 / 256, 29},
                                       {"spring_chain.toml", "spring_chain", 3, (32.0 / 60) / 2048, 18},
                                       {"bouncing_ball.toml", "bouncing_ball", 0, 2.0 / 256, 13}};
  for (const auto& c : cases) {
    const auto scene = make_problem(load_scene(scene_path(c.file)));
    const auto builtin = make_problem(c.builtin);
    ASSERT_EQ(scene->dim() + c.skip, builtin->dim()) << c.file;
    ASSERT_EQ(scene->horizon(), builtin->horizon()) << c.file;
    const std::vector<double> times{builtin->horizon() / 4, builtin->horizon() / 2, builtin->horizon()};
    int compared = 0;
    for (const auto& m : scene->methods()) {
      const auto theirs = builtin->methods();
      if (std::find_if(theirs.begin(), theirs.end(), [&](const method_info& b) { return b.name == m.name; }) ==
          theirs.end())
        continue;
      const bool adaptive = m.kind != method_kind::fixed_step;
      if (adaptive && c.skip > 0) continue;
      const double param = adaptive ? 1e-6 : c.dt;
      const run_result a = scene->run(m.name, param, builtin->horizon(), times);
      const run_result b = builtin->run(m.name, param, builtin->horizon(), times);
      ASSERT_EQ(a.sample_y.size(), b.sample_y.size()) << c.file << " " << m.name;
      const auto pa = positions(a, scene->dim(), 0), pb = positions(b, builtin->dim(), c.skip);
      ASSERT_EQ(pa.size(), pb.size());
      // Relative to the motion's size: a coordinate passing through 0 (the projectile
      // landing) has no size of its own.
      double scale = 0.0;
      for (const double q : pb) scale = std::max(scale, std::isfinite(q) ? std::abs(q) : 0.0);
      for (std::size_t i = 0; i < pa.size(); ++i) {
        if (!std::isfinite(pb[i])) {
          EXPECT_FALSE(std::isfinite(pa[i])) << c.file << " " << m.name;
          continue;
        }
        EXPECT_LE(std::abs(pa[i] - pb[i]), 1e-12 * scale)
            << c.file << " " << m.name << " coordinate " << i << ": " << pa[i] << " vs " << pb[i];
      }
      // An adaptive method's steps follow its error estimate, which on a motion its order
      // integrates exactly (the projectile) is round-off: there the positions are compared.
      if (!adaptive) {
        EXPECT_EQ(a.steps, b.steps) << c.file << " " << m.name;
      }
      EXPECT_EQ(a.contacts, b.contacts) << c.file << " " << m.name;
      ++compared;
    }
    EXPECT_EQ(compared, c.methods) << c.file;
    EXPECT_EQ(scene->contact_mode(), builtin->contact_mode()) << c.file;
  }
}

// One mass on a damped spring has a closed form (the built-in's, problems/damped_spring.hpp):
// the scene's references reach it, and rk4 at a small step does.
TEST(scene_files, one_mass_on_a_spring_follows_its_closed_form) {
  const auto scene = make_problem(load_scene(scene_path("damped_spring.toml")));
  const auto builtin = make_problem("damped_spring");
  const std::vector<double> times{1.0, 2.5, 10.0};
  for (const char* source : {"gsl_rk8pd", "cvode_adams"}) {
    const reference_solution r = solve_reference(source, scene->ode(), times);
    for (std::size_t k = 0; k < times.size(); ++k) {
      const auto exact = builtin->exact(times[k]);
      EXPECT_NEAR(r.y[k][0], exact[0], 1e-10) << source << " t=" << times[k];
      EXPECT_NEAR(r.y[k][1], exact[1], 1e-10) << source << " t=" << times[k];
    }
  }
  const run_result rk4 = scene->run("rk4", 1e-3, 10.0, times);
  for (std::size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(rk4.sample_y[k][0], builtin->exact(times[k])[0], 1e-11);
}

// A ball bouncing on a plane: the scene's references (CVODE locating the contacts as roots
// of the gap) against the built-in's exact bounce sequence (problems/exact/bouncing_ball.hpp),
// three contacts in 2 s.
TEST(scene_files, a_ball_on_a_plane_follows_the_exact_bounces) {
  const auto scene = make_problem(load_scene(scene_path("bouncing_ball.toml")));
  const auto builtin = make_problem("bouncing_ball");
  EXPECT_EQ(scene->contact_mode(), "end_of_step");
  const std::vector<double> times{0.3, 1.0, 1.5, 2.0};
  for (const char* source : {"cvode_bdf", "cvode_adams"}) {
    ASSERT_TRUE(reference_handles_contacts(source));
    const reference_solution r = solve_reference(source, scene->ode(), times);
    EXPECT_EQ(r.contacts, 3) << source;
    for (std::size_t k = 0; k < times.size(); ++k) {
      const auto exact = builtin->exact(times[k]);
      for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(r.y[k][i], exact[i], 1e-9) << source << " t=" << times[k];
    }
  }
}

// The lecture's incline as a scene: a block on a wall tilted 30 degrees, pushed up the
// slope at 5 m/s, g = 9.8, restitution 0 and Coulomb's friction on the wall. Its slope
// coordinate s = t . x and speed against the built-in sliding_block's closed form
// (problems/exact/sliding_block.hpp): with mu = 0.5 it stops and slides back (tan 30 >
// mu_s), steel on steel (mu_s 0.74, mu_k 0.57) it sticks where it stops. Each step the
// wall takes the normal speed gravity gave and with it mu_k g cos(theta) dt of the slip,
// so the speed is the closed form's to round-off but for the step in which the block
// stops (within g dt then), and the position lags by O(dt): semi-implicit Euler moves
// with the speed before the wall's friction. Both fall tenfold from dt = 1e-3 to 1e-4.
// (Measured at dt = 1e-4: position 6.2e-4 m.)
std::string incline_scene(double mu_s, double mu_k) {
  const double theta = std::numbers::pi / 6, c = std::cos(theta), s = std::sin(theta);
  return fmt::format(R"(name = "incline_{:.0f}_{:.0f}"
dim = 2
horizon = 2.0
gravity = [0.0, -9.8]
[[mass]]
mass = 10.0
position = [0.0, 0.0]
velocity = [{:.17g}, {:.17g}]
[[plane]]
normal = [{:.17g}, {:.17g}]
restitution = 0.0
friction = {}
static_friction = {}
)",
                     mu_s * 100, mu_k * 100, 5.0 * c, 5.0 * s, -s, c, mu_k, mu_s);
}

struct incline_errors {
  double position = 0.0, speed = 0.0;
};

incline_errors incline_against(const std::string& builtin, double mu_s, double mu_k, double dt) {
  const std::string path = testing::TempDir() + "/incline.toml";
  std::ofstream(path) << incline_scene(mu_s, mu_k);
  const auto scene = make_problem(load_scene(path));
  const auto exact = make_problem(builtin);
  const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
  const std::vector<double> times{0.25, 0.5, 0.75, 1.0, 1.5, 2.0};
  const run_result r = scene->run("semi_implicit_euler", dt, 2.0, times);
  incline_errors e;
  for (std::size_t k = 0; k < times.size(); ++k) {
    const auto& y = r.sample_y[k];
    const auto want = exact->exact(times[k]);
    EXPECT_NEAR(-s * y[0] + c * y[1], 0.0, 1e-12) << "on the wall at t = " << times[k];
    e.position = std::max(e.position, std::abs(c * y[0] + s * y[1] - want[0]));
    e.speed = std::max(e.speed, std::abs(c * y[2] + s * y[3] - want[1]));
  }
  return e;
}

TEST(scene_files, a_block_on_a_wall_with_friction_follows_the_lecture_incline) {
  for (const auto& [builtin, mu_s, mu_k] :
       {std::tuple{"sliding_block", 0.5, 0.5}, std::tuple{"sliding_block_stick", 0.74, 0.57}}) {
    const incline_errors coarse = incline_against(builtin, mu_s, mu_k, 1e-3);
    const incline_errors fine = incline_against(builtin, mu_s, mu_k, 1e-4);
    SCOPED_TRACE(builtin);
    EXPECT_LT(fine.speed, 9.8 * 1e-4);
    EXPECT_LT(fine.position, 10.0 * 1e-4);
    EXPECT_LT(fine.position, coarse.position / 5.0);
  }
  // The references locate contacts as roots of the gap, which a block pressed to its wall
  // never crosses: each fails with that reason rather than pass through the wall unseen.
  const std::string path = testing::TempDir() + "/incline.toml";
  std::ofstream(path) << incline_scene(0.5, 0.5);
  const auto scene = make_problem(load_scene(path));
  for (const char* source : {"cvode_bdf", "cvode_adams"}) {
    try {
      solve_reference(source, scene->ode(), std::vector<double>{1.0});
      ADD_FAILURE() << source << " went on through the wall";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("a lasting contact, which root location cannot follow"), std::string::npos)
          << e.what();
    }
  }
}

// Implicit Euler damps an undamped spring to rest at its rest length, 1 m from the anchor:
// its Newton solve must end there, though the velocities fall far below the position's
// ulps over h (the solve failed at t = 42 s before integrators/implicit_newton.hpp's
// position_floor). Amplitude 0.5 m, omega = 10/s, dt = 0.01 s: (1 + (omega dt)^2)^(-n/2).
TEST(scene_files, implicit_euler_settles_at_an_equilibrium_away_from_the_origin) {
  const auto p = make_problem(load_scene(std::string(STEPBENCH_TEST_DATA) + "/undamped_spring.toml"));
  const run_result r = p->run("implicit_euler", 0.01, 80.0, std::vector<double>{80.0});
  ASSERT_TRUE(r.stop_reason.empty()) << r.stop_reason;
  EXPECT_NEAR(r.final_y[0], 1.0, 0.5 * std::pow(1.0 + 0.01, -8000.0 / 2) + 4e-15);
}

// Free fall: x = x0 + v0 t + g t^2 / 2 exactly (every method of order >= 2 is exact on it).
TEST(scene_files, free_fall_is_exact) {
  const std::string text = R"(name = "free_fall"
dim = 2
horizon = 2.0
gravity = [0.0, -9.81]
[[mass]]
mass = 2.0
position = [1.0, 10.0]
velocity = [3.0, 4.0]
)";
  const std::string path = testing::TempDir() + "/free_fall.toml";
  std::ofstream(path) << text;
  const auto p = make_problem(load_scene(path));
  const run_result r = p->run("rk4", 0.125, 2.0, std::vector<double>{2.0});
  EXPECT_NEAR(r.sample_y[0][0], 1.0 + 3.0 * 2.0, 1e-13);
  EXPECT_NEAR(r.sample_y[0][1], 10.0 + 4.0 * 2.0 - 0.5 * 9.81 * 4.0, 1e-13);
  EXPECT_NEAR(r.sample_y[0][3], 4.0 - 9.81 * 2.0, 1e-13);
}

// Pleiades (Hairer, Norsett & Wanner, Solving ODEs I, II.10; the IVP test set's PLEI):
// the references' positions at t = 3 against the published ones, to 1e-9.
TEST(scene_files, pleiades_matches_the_published_end_positions) {
  const auto p = make_problem(load_scene(scene_path("pleiades.toml")));
  ASSERT_EQ(p->dim(), 14);
  std::ifstream in(scene_path("pleiades_reference.txt"));
  std::vector<double> published;  // x_i y_i, body by body
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream row(line);
    double x = 0, y = 0;
    row >> x >> y;
    published.push_back(x), published.push_back(y);
  }
  ASSERT_EQ(published.size(), 14u);
  const std::vector<double> t{3.0};
  for (const char* source : {"gsl_rk8pd", "cvode_adams"}) {
    const reference_solution r = solve_reference(source, p->ode(), t);
    for (std::size_t i = 0; i < 14; ++i) EXPECT_NEAR(r.y[0][i], published[i], 1e-9) << source << " coordinate " << i;
  }
  const run_result v9 = p->run("vern9", 1e-12, 3.0, t);
  for (std::size_t i = 0; i < 14; ++i) EXPECT_NEAR(v9.sample_y[0][i], published[i], 1e-8) << "vern9 coordinate " << i;
}

// The analytic Jacobians (springs, drag, attraction, fixed ends, 1-3 dimensions) against
// central differences of the force at a perturbed state.
TEST(scene_files, jacobians_match_differences) {
  const std::string text = R"(name = "jacobian_check"
dim = 3
horizon = 1.0
gravity = [0.0, 0.0, -9.8]
[[mass]]
name = "pin"
position = [0.0, 0.0, 1.0]
fixed = true
mass = 5.0
[[mass]]
mass = 1.0
position = [1.0, 0.2, 0.0]
velocity = [0.1, -0.3, 0.2]
[[mass]]
mass = 2.0
position = [2.0, -0.1, 0.3]
velocity = [-0.2, 0.1, 0.4]
[[mass]]
mass = 0.5
position = [0.5, 1.5, -0.5]
[[spring]]
between = ["pin", 1]
stiffness = 50.0
damping = 0.7
[[spring]]
between = [1, 2]
stiffness = 80.0
damping = 0.3
rest_length = 0.5
[[spring]]
between = [3, 1]
stiffness = 20.0
[drag]
linear = 0.2
quadratic = 0.05
[attraction]
G = 3.0
)";
  const scene_data data = parse_scene(text, "jacobian_check.toml");
  const scene s(std::make_shared<const scene_data>(data));
  auto st = s.initial();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (Eigen::Index i = 0; i < st.x.size(); ++i) st.x[i] += jitter(rng), st.v[i] += 0.1 + jitter(rng);
  auto dadx = s.make_jacobian(), dadv = s.make_jacobian();
  s.jacobian(0.0, st.x, st.v, dadx, dadv);
  const int n = s.dim();
  Eigen::VectorXd fp(n), fm(n);
  for (int j = 0; j < n; ++j) {
    for (int which = 0; which < 2; ++which) {
      Eigen::VectorXd xp = st.x, xm = st.x, vp = st.v, vm = st.v;
      const double h = 1e-6;
      (which == 0 ? xp : vp)[j] += h;
      (which == 0 ? xm : vm)[j] -= h;
      s.force(0.0, xp, vp, fp);
      s.force(0.0, xm, vm, fm);
      for (int i = 0; i < n; ++i) {
        const double fd = (fp[i] - fm[i]) / (2 * h);
        const double an = (which == 0 ? dadx : dadv)(i, j);
        EXPECT_NEAR(an, fd, 1e-6 * std::max(1.0, std::abs(fd)))
            << (which ? "da/dv" : "da/dx") << "(" << i << ", " << j << ")";
      }
    }
  }
}

// Without dampers and drag the energy is conserved: the references keep it to 1e-9
// relative over the cloth-free web, and the dampers make it fall.
TEST(scene_files, energy_is_conserved_without_dissipation) {
  const auto web = make_problem(load_scene(scene_path("web.toml")));
  web->set("damping_scale", 0.0);
  const double e0 = web->energy(web->initial());
  const std::vector<double> t{web->horizon()};
  const reference_solution r = solve_reference("gsl_rk8pd", web->ode(), t);
  EXPECT_NEAR(web->energy(r.y[0]), e0, 1e-9 * std::abs(e0) + 1e-12);
  web->set("damping_scale", 1.0);
  const reference_solution damped = solve_reference("gsl_rk8pd", web->ode(), t);
  EXPECT_LT(web->energy(damped.y[0]), e0 - 1e-6);
}

// What a scene file may not say: each refused in one line naming the file, the line and
// the column, and what is wrong.
TEST(scene_files, bad_files_are_refused_in_one_line_with_their_place) {
  const std::string head = "name = \"s\"\ndim = 2\nhorizon = 1.0\n";
  const std::string mass = "[[mass]]\nmass = 1.0\nposition = [0.0, 0.0]\n";
  struct bad {
    std::string text, expected;
  };
  const std::vector<bad> cases{
      {"", "bad.toml:1:1: empty scene file"},
      {std::string("name = \"s\"\0dim = 2\n", 18), "bad.toml:1:11: not a text file"},
      {"name = \n", "bad.toml:1:"},  // not valid TOML: toml++ says where
      {"dim = 2\nhorizon = 1.0\n" + mass, "bad.toml:1:1: missing key 'name'"},
      {head + "horizn = 2.0\n" + mass, "bad.toml:4:1: unknown key 'horizn' in the scene (did you mean 'horizon'?)"},
      {head + mass + "[[spring]]\nbetween = [0, 1]\nstifness = 1.0\n",
       "unknown key 'stifness' in [[spring]] (did you mean 'stiffness'?)"},
      {"name = \"s\"\ndim = 4\nhorizon = 1.0\n" + mass, "bad.toml:2:7: 'dim' must be 1, 2 or 3 (is 4)"},
      {"name = \"s\"\ndim = \"2\"\nhorizon = 1.0\n" + mass, "bad.toml:2:7: 'dim' must be a number, not a string"},
      {"name = \"s\"\ndim = 2\nhorizon = nan\n" + mass, "bad.toml:3:11: 'horizon' must be finite"},
      {"name = \"s\"\ndim = 2\nhorizon = -1.0\n" + mass, "'horizon' must be positive (is -1)"},
      {head + "[[mass]]\nmass = 0.0\nposition = [0.0, 0.0]\n", "bad.toml:5:8: 'mass' must be positive (is 0)"},
      {head + "[[mass]]\nmass = 1.0\nposition = [0.0]\n",
       "bad.toml:6:12: 'position' must have 2 entries (dim = 2), not 1"},
      {head + "[[mass]]\nmass = 1.0\n", "bad.toml:4:1: missing key 'position' in [[mass]]"},
      {head + "[[mass]]\nposition = [0.0, 0.0]\n", "missing key 'mass' in [[mass]] (a moving mass needs one)"},
      {head + "[[mass]]\nname = \"a\"\nmass = 1.0\nposition = [0.0, 0.0]\n[[mass]]\nname = \"a\"\nmass = 1.0\nposition "
              "= [1.0, 0.0]\n",
       "bad.toml:9:8: two masses are named 'a'"},
      {head + mass + "[[spring]]\nbetween = [0, 5]\nstiffness = 1.0\n", "bad.toml:8:15: mass index 5 does not exist"},
      {head + mass + "[[spring]]\nbetween = [0, \"nobody\"]\nstiffness = 1.0\n", "no mass is named 'nobody'"},
      {head + mass + "[[spring]]\nbetween = [0, 0]\nstiffness = 1.0\n", "a spring joins two different masses"},
      {head + mass + "[[mass]]\nmass = 1.0\nposition = [1.0, 0.0]\n[[spring]]\nbetween = [0, 1]\nstiffness = -1.0\n",
       "'stiffness' must be non-negative (is -1)"},
      {head + mass + "[[mass]]\nmass = 1.0\nposition = [1.0, 0.0]\n[[spring]]\nbetween = [0, 1]\n",
       "missing key 'stiffness' in [[spring]]"},
      {head + mass + "[[plane]]\nnormal = [0.0, 0.0]\n", "bad.toml:8:10: 'normal' must be a non-zero vector"},
      {head + mass + "[[plane]]\nnormal = [0.0, 1.0]\noffset = 0.5\n",
       "bad.toml:7:1: mass 0 starts on the wrong side of this plane (normal . x = 0 < offset 0.5)"},
      {head + mass + "[[plane]]\nnormal = [0.0, 1.0]\nrestitution = 1.5\n", "'restitution' must be in [0, 1] (is 1.5)"},
      {head + mass + "[[plane]]\nnormal = [0.0, 1.0]\nstatic_friction = -0.5\n",
       "'static_friction' must be >= 0 (is -0.5)"},
      {head + mass + "[[plane]]\nnormal = [0.0, 1.0]\ntangential_loss = 2\n",
       "'tangential_loss' must be in [0, 1] (is 2)"},
      {head + mass + "[[plane]]\noffset = 0.0\n", "missing key 'normal' in [[plane]]"},
      {head + "[[mass]]\nfixed = true\nposition = [0.0, 0.0]\n", "every [[mass]] is fixed"},
      {head + mass + "[attraction]\nG = 0.0\n", "'G' must be positive (is 0)"},
      {head + mass + "[drag]\nlinear = inf\n", "'linear' must be finite"},
      {head + mass + "mass = 2.0\n", "bad.toml:7:"},  // a key twice: not valid TOML
      {"name = \"has space\"\ndim = 2\nhorizon = 1.0\n" + mass, "bad.toml:1:8: 'name' must be an identifier"},
  };
  for (const auto& c : cases) {
    try {
      parse_scene(c.text, "bad.toml");
      ADD_FAILURE() << "accepted:\n" << c.text;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.expected), std::string::npos) << "message: " << what << "\nexpected: " << c.expected;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.rfind("bad.toml:", 0), 0u) << what;
    }
  }
  // A scene whose force Jacobian would not fit in memory: 2000 masses in a line, the
  // first joined to the last (a band of every coordinate: 0.8 GiB).
  {
    std::string text = "name = \"long_spring\"\ndim = 3\nhorizon = 1.0\n";
    for (int i = 0; i < 2000; ++i) text += fmt::format("[[mass]]\nmass = 1.0\nposition = [{}.0, 0.0, 0.0]\n", i);
    text += "[[spring]]\nbetween = [0, 1999]\nstiffness = 1.0\n";
    try {
      parse_scene(text, "long.toml");
      ADD_FAILURE() << "a scene of 2000 masses with a spring from the first to the last was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("long.toml:1:1: the scene's force Jacobian would take"), std::string::npos)
          << e.what();
    }
  }
  // A scene may not take a built-in problem's name, nor a loaded scene's from another file.
  const std::string path = testing::TempDir() + "/pendulum_scene.toml";
  std::ofstream(path) << "name = \"pendulum\"\ndim = 2\nhorizon = 1.0\n" << mass;
  try {
    load_scene(path);
    ADD_FAILURE() << "a scene named pendulum was loaded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(":1:8: the scene's name 'pendulum' is a built-in problem's"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(read_scene_file(testing::TempDir() + "/no_such_scene.toml"), std::invalid_argument);
}

}  // namespace
}  // namespace stepbench
