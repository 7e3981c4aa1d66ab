#pragma once
// Exact motion of a ball bouncing on the ground plane z = 0 with the lecture's collision
// response (particle and plane): at contact, with the plane's normal n = (0, 1),
//   v_n = (v . n) n,  v_t = v - v_n,  v_b = (1 - k_f) v_t - k_r v_n,
// k_r the restitution and k_f the friction, both in [0, 1]. In the x-z plane (x horizontal,
// z up), gravity (0, -g); launched at t = 0 from (0, h), h > 0, with velocity (vx0, vz0)
// (the brief's case is vz0 = 0).
//
// Between contacts the ball flies on parabolas. Contact k (k = 1, 2, ...) happens at t_k:
// - First flight: t_1 is the positive root of h + vz0 t - g t^2 / 2 = 0, by the stable
//   quadratic formula (time_to_ground). The impact speed is v_1 = sqrt(vz0^2 + 2 g h).
// - Each contact multiplies the vertical speed by -k_r and the horizontal one by (1 - k_f).
//   After contact k the ball leaves z = 0 upwards at w_k = k_r^k v_1, flies for
//   T_k = 2 w_k / g = D k_r^k (D = 2 v_1 / g) with vx_k = (1 - k_f)^k vx0, and lands again.
//   (From z = 0 the quadratic's positive root is exactly 2 w / g: no quadratic to solve.)
// - Hence, with S_j = k_r + ... + k_r^j = k_r (1 - k_r^j) / (1 - k_r) and q = (1 - k_f) k_r,
//   t_k = t_1 + D S_{k-1},  x_k = vx0 (t_1 + D (q + ... + q^{k-1})).
//   The geometric sums are evaluated as -expm1(j ln r) / (1 - r): no cancellation as r -> 1
//   (1 - r is exact there), and j when r = 1.
//
// Zeno limit (handled exactly, not by enumerating bounces). For k_r < 1 the contact times
// accumulate at
//   t_inf = t_1 + D k_r / (1 - k_r) = t_1 + 2 v_1 k_r / (g (1 - k_r)),
// with t_inf - t_k = D k_r^k / (1 - k_r): infinitely many bounces in finite time. From t_inf on
// the ball lies on the ground (z = 0, vz = 0) and moves with the limit horizontal speed
// vx0 (1 - k_f)^k as k -> infinity: 0 if k_f > 0, vx0 if k_f = 0 (sustained contact is the
// limit of infinitely many contacts in this model, not Coulomb friction). It sits at
// x_inf = vx0 (t_1 + D q / (1 - q)) at t_inf. k_r = 0 is the same with t_inf = t_1.
// For k_r = 1 there is no accumulation (t_inf = +inf): bounces forever, evenly spaced by D.
//
// The state at any t is allocation-free and needs no enumeration of bounces: the contact index
// k with t_k <= t < t_{k+1} comes from inverting t_inf - t_k = D k_r^k / (1 - k_r)
// (k = floor(ln((t_inf - t)(1 - k_r) / D) / ln k_r)), then is corrected against the same t_k
// formula (a few evaluations; O(log) when k_r -> 1 makes the guess coarse), so the index and
// the contact times agree to the last bit. Height on flight k is z = (g/2) (t - t_k) (t_{k+1} - t):
// the factored parabola, non-negative by construction, exactly 0 at both contacts, and free of
// the cancellation of w tau - g tau^2 / 2 near landing; vz = w_k - g (t - t_k).
//
// contacts_until() lists contacts (std::vector) up to a time, stopping early when a rebound's
// height falls below a threshold: by default eps * H, H = h + vz0^2 / (2 g) the launch apex,
// i.e. a bounce smaller than the rounding of a height of size H, which no double-precision
// simulation of this scene can resolve; and never at or past t_inf.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace stepbench::exact {

// Smallest tau >= 0 with z0 + w0 tau - g tau^2 / 2 = 0, for z0 >= 0, g > 0: the positive root
// (w0 + d) / g, d = sqrt(w0^2 + 2 g z0), written for w0 <= 0 as the equal 2 z0 / (d - w0)
// (d - w0 = d + |w0|: no cancellation). hypot keeps w0^2 from overflowing.
inline double time_to_ground(double z0, double w0, double g) {
  if (z0 <= 0.0 && w0 <= 0.0) return 0.0;
  const double d = std::hypot(w0, std::sqrt(2.0 * g * z0));
  return w0 > 0.0 ? (w0 + d) / g : 2.0 * z0 / (d - w0);
}

// 1 + r + ... + r^(j-1) for 0 <= r <= 1, j >= 0.
inline double geometric_sum(double r, double j) {
  if (j <= 0.0) return 0.0;
  if (r == 1.0) return j;
  if (r == 0.0) return 1.0;
  return -std::expm1(j * std::log(r)) / (1.0 - r);
}

struct ball_state {
  double x, z, vx, vz;
};

struct ball_contact {
  long long index;        // k = 1, 2, ...
  double t, x;            // when and where (z = 0)
  double vx_in, vz_in;    // velocity just before (vz_in <= 0)
  double vx_out, vz_out;  // just after: ((1 - k_f) vx_in, -k_r vz_in)
  double rebound_height;  // apex of the following flight, vz_out^2 / (2 g)
};

struct bouncing_ball {
  double g = 9.8;
  double h = 1.0;    // launch height, > 0
  double vx0 = 1.0;  // launch velocity
  double vz0 = 0.0;
  double k_r = 0.5;  // restitution, [0, 1]
  double k_f = 0.0;  // friction, [0, 1]

  double first_contact_time() const { return time_to_ground(h, vz0, g); }
  double impact_speed() const { return std::hypot(vz0, std::sqrt(2.0 * g * h)); }  // v_1
  double apex_height() const { return h + (vz0 > 0.0 ? vz0 * vz0 / (2.0 * g) : 0.0); }
  // D = 2 v_1 / g: flight k after the first lasts D k_r^k.
  double flight_scale() const { return 2.0 * impact_speed() / g; }
  // Accumulation time of the contacts (+inf for k_r = 1).
  double rest_time() const { return k_r == 1.0 ? inf : flights(k_r, inf); }
  // Horizontal speed on the ground after t_inf: vx0 (1 - k_f)^infinity.
  double rest_speed() const { return k_f > 0.0 ? 0.0 : vx0; }
  double rest_position() const { return vx0 * flights(q(), inf); }

  // Time of contact k >= 1: t_1 + D S_{k-1}.
  double contact_time(long long k) const { return flights(k_r, double(k - 1)); }
  // Where contact k >= 1 happens: vx0 (t_1 + D (q + ... + q^{k-1})).
  double contact_position(long long k) const { return vx0 * flights(q(), double(k - 1)); }
  ball_contact contact(long long k) const {
    const double kr_in = std::pow(k_r, double(k - 1)), kf_in = std::pow(1.0 - k_f, double(k - 1));
    const double vz_out = k_r * kr_in * impact_speed();
    return {k,
            contact_time(k),
            contact_position(k),
            vx0 * kf_in,
            -kr_in * impact_speed(),
            vx0 * kf_in * (1.0 - k_f),
            vz_out,
            vz_out * vz_out / (2.0 * g)};
  }

  // The k >= 1 with contact_time(k) <= t < contact_time(k + 1), for first_contact_time() <= t <
  // rest_time(). The guess from inverting t_inf - t_k = D k_r^k / (1 - k_r) is off by at most
  // ln 2 / |ln k_r| + 1 (when t_inf - t is a few ulps, its relative error is O(1)), which is
  // many steps for k_r -> 1; so it is corrected by a galloping search and a bisection, whose
  // invariant contact_time(lo) <= t < contact_time(hi) gives the bracket above exactly (even
  // were the rounded contact times not monotone). t_k saturates at exactly rest_time() (same
  // expression, geometric_sum(k_r, j) -> 1 / (1 - k_r)), so an upper end exists for t < t_inf.
  long long contact_index(double t) const {
    const double t1 = first_contact_time(), D = flight_scale();
    double guess;
    if (k_r == 1.0) {
      guess = 1.0 + std::floor((t - t1) / D);
    } else {
      guess = std::floor(std::log((rest_time() - t) * (1.0 - k_r) / D) / std::log(k_r));
    }
    constexpr long long k_max = 1LL << 52;
    long long lo = static_cast<long long>(std::clamp(guess, 1.0, double(k_max))), step = 1;
    while (lo > 1 && contact_time(lo) > t) {  // gallop down to a time at or before t
      lo = std::max(1LL, lo - step);
      step *= 2;
    }
    long long hi = lo + 1;
    for (step = 1; hi < k_max && contact_time(hi) <= t; step *= 2) {  // gallop up past t
      lo = hi;
      hi = std::min(k_max, lo + step);
    }
    while (hi - lo > 1) {
      const long long mid = lo + (hi - lo) / 2;
      if (contact_time(mid) <= t) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

  ball_state at(double t) const {
    const double t1 = first_contact_time();
    if (t < t1) {
      // z = (g/2) (t1 - t) (t - t_minus), t_minus = -2 h / (g t1) the other root (the
      // roots' product is -2 h / g).
      const double t_minus = -2.0 * h / (g * t1);
      return {vx0 * t, 0.5 * g * (t1 - t) * (t - t_minus), vx0, vz0 - g * t};
    }
    const double t_rest = rest_time();
    if (k_r == 0.0 || t >= t_rest) return {rest_position() + rest_speed() * (t - t_rest), 0.0, rest_speed(), 0.0};
    const long long k = contact_index(t);
    const double tk = contact_time(k), tk1 = contact_time(k + 1), tau = t - tk;
    if (!(tk1 > t)) return {rest_position() + rest_speed() * (t - t_rest), 0.0, rest_speed(), 0.0};  // unreachable
    const double w = std::pow(k_r, double(k)) * impact_speed();
    const double vx = vx0 * std::pow(1.0 - k_f, double(k));
    return {contact_position(k) + vx * tau, 0.5 * g * (t - tk) * (tk1 - t), vx, w - g * tau};
  }

  // Contacts with t_k <= t_end, in order, stopping after the first whose rebound height is
  // below min_rebound_height (default eps * apex_height(), see above), before t_inf, and when
  // the rounded contact times stop increasing. t_end must be finite when k_r = 1.
  std::vector<ball_contact> contacts_until(double t_end, double min_rebound_height = -1.0) const {
    if (min_rebound_height < 0.0) min_rebound_height = std::numeric_limits<double>::epsilon() * apex_height();
    std::vector<ball_contact> out;
    const double t_rest = rest_time();
    for (long long k = 1;; ++k) {
      const ball_contact c = contact(k);
      if (c.t > t_end || (k > 1 && (c.t >= t_rest || c.t <= out.back().t))) break;
      out.push_back(c);
      if (c.rebound_height < min_rebound_height) break;
    }
    return out;
  }

 private:
  static constexpr double inf = std::numeric_limits<double>::infinity();
  double q() const { return (1.0 - k_f) * k_r; }
  // t_1 + D (r + ... + r^j).
  double flights(double r, double j) const { return first_contact_time() + flight_scale() * (r * geometric_sum(r, j)); }
};

}  // namespace stepbench::exact
