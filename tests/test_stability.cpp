// Stability from the compiled steps (study/stability.hpp): the limits from the
// amplification matrix (a) agree with the long runs (b); the published limits hold; the
// flags; the regions equal the tableaux' stability functions; the /stability layout.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "integrators/all.hpp"
#include "integrators/tableaus.hpp"
#include "run/stability.hpp"
#include "store/h5.hpp"
#include "store/stability.hpp"
#include "study/stability.hpp"

using namespace stepbench;

namespace {

template <class... Ts>
constexpr std::size_t type_list_size(type_list<Ts...>) {
  return sizeof...(Ts);
}

// Computed once for the whole file (about 0.1 s).
const stability_data& data() {
  static const stability_data d = compute_stability();
  return d;
}

const stability_limit& limit(std::string_view name, stability_test test) {
  for (const auto& l : data().limits)
    if (l.integrator == name && l.test == test) return l;
  throw std::out_of_range(std::string(name));
}

constexpr auto osc = stability_test::oscillator;
constexpr auto decay = stability_test::decay;

// Explicit Euler as a one-stage tableau (b = 1): R(z) = 1 + z.
constexpr explicit_tableau<1> euler_tableau = {.b = {1.0}, .c = {0.0}, .order = 1};

// The end of the stable interval of R along a ray z = y dir from 0, by walking out in
// steps of dy and bisecting: the same definition as the compiled-step limits.
template <int S>
double ray_limit(const explicit_tableau<S>& tab, std::complex<double> dir, double dy = 1e-3) {
  double lo = 0.0;
  while (std::abs(stability_function(tab, (lo + dy) * dir)) <= 1.0 + 1e-15) lo += dy;
  double hi = lo + dy;
  while (hi - lo > 1e-15 * hi) {
    const double mid = 0.5 * (lo + hi);
    (std::abs(stability_function(tab, mid * dir)) <= 1.0 + 1e-15 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

TEST(stability, computed_quickly) {
  const auto& d = data();
  std::printf("  limits %.3f s, regions (%zu x %zu) %.3f s\n", d.limits_seconds, d.regions.re.size(),
              d.regions.im.size(), d.regions_seconds);
  EXPECT_EQ(d.limits.size(), 2 * type_list_size(all_integrators{}));  // every integrator x 2 tests
}

// The amplification matrix is the compiled step's: explicit Euler on x'' = -x is
// [[1, y], [-y, 1]], semi-implicit Euler [[1 - y^2, y], [-y, 1]] (exactly, in floating
// point), and on decay explicit Euler is [[1, y], [0, 1 - y]].
TEST(stability, amplification_matrix_of_the_step) {
  const double y = 0.375;
  Eigen::Matrix2d e;
  e << 1.0, y, -y, 1.0;
  EXPECT_EQ(amplification_matrix("euler", osc, y), e);
  e << 1.0 - y * y, y, -y, 1.0;
  EXPECT_EQ(amplification_matrix("semi_implicit_euler", osc, y), e);
  e << 1.0, y, 0.0, 1.0 - y;
  EXPECT_EQ(amplification_matrix("euler", decay, y), e);
  EXPECT_THROW(amplification_matrix("rk5", osc, y), std::invalid_argument);
  // Spectral radius from trace and determinant: a rotation, a shear, a real pair.
  Eigen::Matrix2d m;
  m << 0.6, -0.8, 0.8, 0.6;
  EXPECT_NEAR(spectral_radius(m), 1.0, 1e-15);
  m << 1.0, 5.0, 0.0, 1.0;
  EXPECT_EQ(spectral_radius(m), 1.0);
  m << -3.0, 0.0, 0.0, 0.5;
  EXPECT_EQ(spectral_radius(m), 3.0);
}

// (a) and (b) agree within 1 % for every finite limit, and the runs confirm every flag.
TEST(stability, amplification_and_long_runs_agree) {
  for (const auto& l : data().limits) {
    SCOPED_TRACE(l.integrator + " on " + std::string(to_string(l.test)) + ": " + l.note);
    EXPECT_FALSE(l.unstable_for_all_dt && l.unconditionally_stable);
    if (std::isfinite(l.theory)) {
      ASSERT_TRUE(std::isfinite(l.measured));
      if (l.measured > 1.01 * l.theory) {
        // A growth too weak for the runs to show (run/stability.cpp measured_limit):
        // rho - 1 at the runs' limit below 1.01^(2 / 10000) - 1.
        const double rho = spectral_radius(amplification_matrix(l.integrator, l.test, l.measured));
        EXPECT_LT(rho - 1.0, std::pow(1.01, 2.0 / 10000) - 1.0);
        EXPECT_NE(l.note.find("below what"), std::string::npos);
      } else {
        EXPECT_NEAR(l.measured / l.theory, 1.0, 0.01);
      }
    } else {
      EXPECT_TRUE(l.unstable_for_all_dt || l.unconditionally_stable);
      EXPECT_TRUE(std::isnan(l.measured));
    }
    EXPECT_TRUE(l.run_confirms);
    EXPECT_TRUE(std::isnan(l.step_failed_at)) << "the step failed at y = " << l.step_failed_at;
  }
}

// Published limits (Hairer & Wanner, Solving ODEs II, sec. IV.2; Hairer, Lubich &
// Wanner, Geometric Numerical Integration, sec. I.1 for the symplectic methods on the
// oscillator: stable while |trace M| < 2, i.e. omega dt < 2).
TEST(stability, published_limits) {
  EXPECT_NEAR(limit("rk4", osc).theory, 2.0 * std::numbers::sqrt2, 1e-10);  // imaginary axis: 2 sqrt 2
  EXPECT_NEAR(limit("rk4", decay).theory, 2.785293563405282, 1e-10);        // real axis
  for (const char* name : {"semi_implicit_euler", "momentum", "velocity_verlet"})
    EXPECT_NEAR(limit(name, osc).theory, 2.0, 1e-10) << name;
  // On decay every first- or second-order explicit method here has the real-axis
  // interval [-2, 0] (R = 1 + z or 1 + z + z^2/2); adaptive_euler's two half steps,
  // R = (1 + z/2)^2, reach -4.
  for (const char* name : {"euler", "semi_implicit_euler", "midpoint", "momentum", "velocity_verlet"})
    EXPECT_NEAR(limit(name, decay).theory, 2.0, 1e-10) << name;
  EXPECT_NEAR(limit("adaptive_euler", decay).theory, 4.0, 1e-10);
  // rk45 is Dormand-Prince's step: its limits are those of its tableau.
  EXPECT_NEAR(limit("rk45", decay).theory, ray_limit(dopri5_tableau, {-1.0, 0.0}), 1e-9);
  EXPECT_NEAR(limit("rk45", decay).theory, 3.3066, 1e-4);
  EXPECT_NEAR(limit("rk45", osc).theory, ray_limit(dopri5_tableau, {0.0, 1.0}), 1e-9);
  std::printf("  rk45: oscillator %.10f, decay %.10f; adaptive_euler decay %.10f\n", limit("rk45", osc).theory,
              limit("rk45", decay).theory, limit("adaptive_euler", decay).theory);
}

TEST(stability, flags) {
  for (const char* name : {"euler", "midpoint", "adaptive_euler"}) {
    const auto& l = limit(name, osc);  // |R(iy)| > 1 for every y > 0
    EXPECT_TRUE(l.unstable_for_all_dt) << name << ": " << l.note;
    EXPECT_FALSE(l.unconditionally_stable) << name;
    EXPECT_TRUE(std::isnan(l.theory)) << name;
  }
  for (const char* name : {"implicit_euler", "implicit_midpoint"})
    for (auto test : {osc, decay}) {
      const auto& l = limit(name, test);  // A-stable
      EXPECT_TRUE(l.unconditionally_stable) << name << " on " << to_string(test) << ": " << l.note;
      EXPECT_FALSE(l.unstable_for_all_dt) << name;
      EXPECT_TRUE(std::isnan(l.theory)) << name;
    }
  // Every other method has a finite limit on both tests, except on the oscillator the
  // three above.
  for (const auto& l : data().limits) {
    const bool flagged = l.unstable_for_all_dt || l.unconditionally_stable;
    EXPECT_EQ(flagged, !std::isfinite(l.theory)) << l.integrator;
  }
}

// The regions from the compiled steps equal the stability functions: of the tableaux
// for the Runge-Kutta methods, and the closed forms of the others (on the damper every
// velocity update is a Runge-Kutta method in v).
TEST(stability, regions_match_the_stability_functions) {
  using c = std::complex<double>;
  const auto& r = data().regions;
  ASSERT_EQ(r.integrators.size(), type_list_size(all_integrators{}));
  const std::size_t nre = r.re.size(), nim = r.im.size();
  EXPECT_EQ(r.re.front(), -6.0);
  EXPECT_EQ(r.re.back(), 2.0);
  EXPECT_EQ(r.im.front(), -5.0);
  EXPECT_EQ(r.im.back(), 5.0);
  const std::pair<const char*, c (*)(c)> cases[] = {
      {"euler", [](c z) { return stability_function(euler_tableau, z); }},
      {"midpoint", [](c z) { return stability_function(midpoint_tableau, z); }},
      {"rk4", [](c z) { return stability_function(rk4_tableau, z); }},
      {"rk45", [](c z) { return stability_function(dopri5_tableau, z); }},
      {"semi_implicit_euler", [](c z) { return 1.0 + z; }},
      {"momentum", [](c z) { return 1.0 + z; }},
      {"velocity_verlet", [](c z) { return 1.0 + z + z * z / 2.0; }},  // Heun's velocity update
      {"adaptive_euler", [](c z) { return (1.0 + z / 2.0) * (1.0 + z / 2.0); }},
      {"implicit_euler", [](c z) { return 1.0 / (1.0 - z); }},
      {"implicit_midpoint", [](c z) { return (1.0 + z / 2.0) / (1.0 - z / 2.0); }},
  };
  for (const auto& [name, R] : cases) {
    const auto& grid = r.of(name);
    ASSERT_EQ(grid.size(), nre * nim) << name;
    double worst = 0.0;
    int poles = 0;
    for (std::size_t i = 0; i < nim; ++i)
      for (std::size_t j = 0; j < nre; ++j) {
        const c z(r.re[j], r.im[i]);
        const double expected = std::abs(R(z)), got = grid[i * nre + j];
        if (!std::isfinite(expected)) {  // a pole: z = 1 (implicit Euler), z = 2 (implicit midpoint)
          EXPECT_TRUE(std::isnan(got)) << name << " at " << z;
          ++poles;
          continue;
        }
        ASSERT_TRUE(std::isfinite(got)) << name << " at " << z;
        worst = std::max(worst, std::abs(got - expected) / std::max(1.0, expected));
      }
    EXPECT_LE(worst, 1e-13) << name;
    EXPECT_EQ(poles, std::string_view(name).starts_with("implicit") ? 1 : 0) << name;
    std::printf("  %-20s largest relative difference from R(z): %.1e\n", name, worst);
  }
}

TEST(stability, written_to_the_study_file) {
  const auto path = std::filesystem::temp_directory_path() / "stepbench_test_stability.h5";
  {
    H5::H5File file(path.string(), H5F_ACC_TRUNC);
    write_stability(file, data());
  }
  H5::H5File file(path.string(), H5F_ACC_RDONLY);
  H5::Group g = file.openGroup("stability");
  const h5::table_data limits = h5::read_table(g.openDataSet("limits"));
  const auto& names = limits.strings("integrator");
  const auto& tests = limits.strings("test");
  const auto& theory = limits.reals("theory");
  const auto& measured = limits.reals("measured");
  const auto& uncond = limits.ints("unconditionally_stable");
  ASSERT_EQ(names.size(), data().limits.size());
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto& l = data().limits[k];
    EXPECT_EQ(names[k], l.integrator);
    EXPECT_EQ(tests[k], to_string(l.test));
    EXPECT_TRUE(theory[k] == l.theory || (std::isnan(theory[k]) && std::isnan(l.theory)));
    EXPECT_TRUE(measured[k] == l.measured || (std::isnan(measured[k]) && std::isnan(l.measured)));
    EXPECT_EQ(uncond[k], l.unconditionally_stable ? 1 : 0);
  }
  EXPECT_EQ(h5::read_vector(g.openDataSet("region_re")), data().regions.re);
  EXPECT_EQ(h5::read_vector(g.openDataSet("region_im")), data().regions.im);
  const H5::DataSet rk4 = g.openGroup("regions").openDataSet("rk4");
  hsize_t dims[2] = {0, 0};
  ASSERT_EQ(rk4.getSpace().getSimpleExtentDims(dims), 2);
  EXPECT_EQ(dims[0], data().regions.im.size());  // rows: Im
  EXPECT_EQ(dims[1], data().regions.re.size());  // columns: Re
  std::vector<double> values(dims[0] * dims[1]);
  rk4.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  // Stored as float32 (a figure's resolution): equal to the computed values rounded to float.
  std::vector<double> rounded;
  for (double x : data().regions.of("rk4")) rounded.push_back(static_cast<double>(static_cast<float>(x)));
  EXPECT_EQ(values, rounded);
  file.close();
  std::filesystem::remove(path);
}
