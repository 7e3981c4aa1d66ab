#pragma once
// Coefficients of the Runge-Kutta and composition methods, as constexpr data with
// their sources. Types and the stability function are in integrators/tableau.hpp;
// tests/test_tableaus.cpp proves every set: row sums, all order conditions up to the
// declared order (and a failing one beyond it), dense output, stability limits, and
// the observed order of the compositions on the pendulum.
//
// Conventions: stages are numbered from 0 here (a[i][j] is a_{i+1,j+1} of the
// papers); where a long table is written out, set_entries takes the papers' 1-based
// indices of a row's nonzero entries, then their values in the same order, so each row
// can be checked against the source by eye.
#include <array>
#include <initializer_list>

#include "integrators/tableau.hpp"

namespace stepbench {

// row[j - 1] = v for the 1-based indices js and their values vs, in turn.
template <std::size_t N>
constexpr void set_entries(std::array<double, N>& row, std::initializer_list<int> js,
                           std::initializer_list<double> vs) {
  if (js.size() != vs.size()) throw "set_entries: as many values as indices";  // fails the constant evaluation
  const double* v = vs.begin();
  for (int j : js) row[j - 1] = *v++;
}

// ---------------------------------------------------------------------------------
// Explicit midpoint rule (Runge, Math. Ann. 46 (1895) 167), order 2:
//   k1 = f(t, y), k2 = f(t + h/2, y + h/2 k1), y_1 = y + h k2.
// Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed. (HNW I below), sec. II.1.
inline constexpr explicit_tableau<2> midpoint_tableau = {
    .a = {{{0.0, 0.0}, {0.5, 0.0}}},
    .b = {0.0, 1.0},
    .c = {0.0, 0.5},
    .order = 2,
};

// Classic fourth-order Runge-Kutta (Kutta, Z. Math. Phys. 46 (1901) 435; HNW I,
// sec. II.1): weights 1/6, 1/3, 1/3, 1/6 at c = 0, 1/2, 1/2, 1.
inline constexpr explicit_tableau<4> rk4_tableau = {
    .a = {{{0.0, 0.0, 0.0, 0.0}, {0.5, 0.0, 0.0, 0.0}, {0.0, 0.5, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}}},
    .b = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0},
    .c = {0.0, 0.5, 0.5, 1.0},
    .order = 4,
};

// ---------------------------------------------------------------------------------
// Dormand-Prince 5(4), "RK5(4)7M": Dormand & Prince, A family of embedded Runge-Kutta
// formulae, J. Comp. Appl. Math. 6 (1980) 19-26; HNW I, sec. II.5, Table 5.2 (the
// DOPRI5 table). 7 stages, order 5, embedded order 4, FSAL (row 7 of A is b, so the
// 7th stage is f(t + h, y_1), the next step's k1: 6 evaluations per step).
// Read from Hairer's dopri5.f (subroutine CDOPRI, version of April 25, 1996, in the
// public copy github.com/cpmech/hwode); the rationals there are the paper's. dopri5.f
// stores E = b - b_hat (E1 = 71/57600, ...) rather than b_hat; the test checks both.
inline constexpr explicit_tableau<7> dopri5_tableau = {
    .a = {{
        {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
        {1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
        {3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0},
        {44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0},
        {19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0, 0.0},
        {9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0, 0.0},
        {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0},
    }},
    .b = {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0},
    .c = {0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0},
    .order = 5,
    .b_hat = {5179.0 / 57600.0, 0.0, 7571.0 / 16695.0, 393.0 / 640.0, -92097.0 / 339200.0, 187.0 / 2100.0, 1.0 / 40.0},
    .embedded_order = 4,
};

// Dense output of DOPRI5: the quartic continuous extension of Shampine, Some practical
// Runge-Kutta formulas, Math. Comp. 46 (1986) 135-150, as used in HNW I, sec. II.6 and
// in dopri5.f (CDOPRI's D1..D7, evaluated by CONTD5). With theta = (t - t_n) / h,
//   y(t_n + theta h) = y_n + h sum_i b_i(theta) k_i,
//   b(theta) = theta (b + (1 - theta) ((e_1 - b) + theta ((2 b - e_1 - e_7) + (1 - theta) d))),
// e_i the unit vectors: CONTD5's nested form, written for the weights instead of the
// stored differences (ydiff = h b.k, bspl = h k_1 - ydiff, ...). Order 4 for every
// theta in [0, 1]; b(1) = b, b(0) = 0.
inline constexpr int dopri5_dense_order = 4;
inline constexpr std::array<double, 7> dopri5_dense_d = {
    -12715105075.0 / 11282082432.0,  0.0,
    87487479700.0 / 32700410799.0,   -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0, -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
};

constexpr std::array<double, 7> dopri5_dense_weights(double theta) {
  const double t1 = 1.0 - theta;
  std::array<double, 7> w{};
  for (int i = 0; i < 7; ++i) {
    const double b = dopri5_tableau.b[i];
    const double e1 = i == 0 ? 1.0 : 0.0, e7 = i == 6 ? 1.0 : 0.0;
    w[i] = theta * (b + t1 * ((e1 - b) + theta * ((2.0 * b - e1 - e7) + t1 * dopri5_dense_d[i])));
  }
  return w;
}

// ---------------------------------------------------------------------------------
// DOP853: the explicit Runge-Kutta method of order 8 of Dormand & Prince with error
// estimators of orders 5 and 3 and a dense output of order 7, from HNW I, 2nd ed.
// (1993); dop853.f's header points to its sec. II.6.
// Every number below is copied digit for digit from the PARAMETER statements of
// Hairer's dop853.f (subroutine DP86CO), read in two public copies whose 154
// parameters are identical: github.com/cpmech/hwode (version of April 25, 1996, small
// corrections March 4, 2002) and github.com/djps/homoclinic-orbits (version of
// October 11, 2009); spot-checked against scipy/integrate/_ivp/dop853_coefficients.py.
// Names in the comments are dop853.f's (a21, b1, er1, d41, ...).
//
// The step uses 12 stages (stage 12 has c = 1 but is not y_1). The 13th evaluation,
// f(t + h, y_1), is the next step's k1 (12 evaluations per step) and is also stage 13
// of the dense output, whose stages 14-16 cost 3 more evaluations per step that asks
// for it. All 16 are stored as one extended tableau (row 13 of A is b);
// `dop853_tableau` is its leading 12 stages.
//
// Error estimate (dop853.f, after label 35): with k the 12 stages and ||.|| the RMS
// norm scaled by atol + rtol max(|y|, |y_1|) per component,
//   err5 = || sum_i e5_i k_i ||,  e5 = b - b_hat5 (dop853.f's er),
//   err3 = || sum_i e3_i k_i ||,  e3 = b - b_hat3 (b_hat3 = bhh1, bhh2, bhh3 on stages
//   1, 9, 12),
//   err  = |h| err5^2 / sqrt(err5^2 + dop853_err3_weight err3^2).
// As h -> 0, err5 = O(h^5) and err3 = O(h^3), so err ~ |h| err5^2 / (0.1 err3) = O(h^8):
// the step-size controller uses the exponent 1/8.
inline constexpr double dop853_err3_weight = 0.01;

// dop853.f's er1..er12 (zero for stages 2-5), over the 16 stages of dop853_extended
// below (zero beyond stage 12).
inline constexpr std::array<double, 16> dop853_e5 = [] {
  std::array<double, 16> e{};
  set_entries(
      e, {1, 6, 7, 8, 9, 10, 11, 12},
      {0.1312004499419488073250102996e-01, -0.1225156446376204440720569753e+01, -0.4957589496572501915214079952e+00,
       0.1664377182454986536961530415e+01, -0.3503288487499736816886487290e+00, 0.3341791187130174790297318841e+00,
       0.8192320648511571246570742613e-01, -0.2235530786388629525884427845e-01});
  return e;
}();

inline constexpr explicit_tableau<16> dop853_extended = [] {
  explicit_tableau<16> t{};
  // c_12 = c_13 = 1: stages 12 and 13 are evaluated at X + H in dop853.f.
  set_entries(
      t.c, {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
      {0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01, 0.118350341907227396726757197510e+00,
       0.281649658092772603273242802490e+00, 0.333333333333333333333333333333e+00, 0.25e+00,
       0.307692307692307692307692307692e+00, 0.651282051282051282051282051282e+00, 0.6e+00,
       0.857142857142857142857142857142e+00, 1.0, 1.0, 0.1e+00, 0.2e+00, 0.777777777777777777777777777778e+00});
  auto a = [&t](int i, std::initializer_list<int> js, std::initializer_list<double> vs) {
    set_entries(t.a[i - 1], js, vs);
  };
  a(2, {1}, {5.26001519587677318785587544488e-2});
  a(3, {1, 2}, {1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2});
  a(4, {1, 3}, {2.95875854768068491816892993775e-2, 8.87627564304205475450678981324e-2});
  a(5, {1, 3, 4},
    {2.41365134159266685502369798665e-1, -8.84549479328286085344864962717e-1, 9.24834003261792003115737966543e-1});
  a(6, {1, 4, 5},
    {3.7037037037037037037037037037e-2, 1.70828608729473871279604482173e-1, 1.25467687566822425016691814123e-1});
  a(7, {1, 4, 5, 6},
    {3.7109375e-2, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2, -1.7578125e-2});
  a(8, {1, 4, 5, 6, 7},
    {3.70920001185047927108779319836e-2, 1.70383925712239993810214054705e-1, 1.07262030446373284651809199168e-1,
     -1.53194377486244017527936158236e-2, 8.27378916381402288758473766002e-3});
  a(9, {1, 4, 5, 6, 7, 8},
    {6.24110958716075717114429577812e-1, -3.36089262944694129406857109825e0, -8.68219346841726006818189891453e-1,
     2.75920996994467083049415600797e1, 2.01540675504778934086186788979e1, -4.34898841810699588477366255144e1});
  a(10, {1, 4, 5, 6, 7, 8, 9},
    {4.77662536438264365890433908527e-1, -2.48811461997166764192642586468e0, -5.90290826836842996371446475743e-1,
     2.12300514481811942347288949897e1, 1.52792336328824235832596922938e1, -3.32882109689848629194453265587e1,
     -2.03312017085086261358222928593e-2});
  a(11, {1, 4, 5, 6, 7, 8, 9, 10},
    {-9.3714243008598732571704021658e-1, 5.18637242884406370830023853209e0, 1.09143734899672957818500254654e0,
     -8.14978701074692612513997267357e0, -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1,
     2.49360555267965238987089396762e0, -3.0467644718982195003823669022e0});
  a(12, {1, 4, 5, 6, 7, 8, 9, 10, 11},
    {2.27331014751653820792359768449e0, -1.05344954667372501984066689879e1, -2.00087205822486249909675718444e0,
     -1.79589318631187989172765950534e1, 2.79488845294199600508499808837e1, -2.85899827713502369474065508674e0,
     -8.87285693353062954433549289258e0, 1.23605671757943030647266201528e1, 6.43392746015763530355970484046e-1});
  a(14, {1, 7, 8, 9, 10, 11, 12, 13},
    {5.61675022830479523392909219681e-2, 2.53500210216624811088794765333e-1, -2.46239037470802489917441475441e-1,
     -1.24191423263816360469010140626e-1, 1.5329179827876569731206322685e-1, 8.20105229563468988491666602057e-3,
     7.56789766054569976138603589584e-3, -8.298e-3});
  a(15, {1, 6, 7, 8, 11, 12, 13, 14},
    {3.18346481635021405060768473261e-2, 2.83009096723667755288322961402e-2, 5.35419883074385676223797384372e-2,
     -5.49237485713909884646569340306e-2, -1.08347328697249322858509316994e-4, 3.82571090835658412954920192323e-4,
     -3.40465008687404560802977114492e-4, 1.41312443674632500278074618366e-1});
  a(16, {1, 6, 7, 8, 9, 13, 14, 15},
    {-4.28896301583791923408573538692e-1, -4.69762141536116384314449447206e0, 7.68342119606259904184240953878e0,
     4.06898981839711007970213554331e0, 3.56727187455281109270669543021e-1, -1.39902416515901462129418009734e-3,
     2.9475147891527723389556272149e0, -9.15095847217987001081870187138e0});
  set_entries(
      t.b, {1, 6, 7, 8, 9, 10, 11, 12},
      {5.42937341165687622380535766363e-2, 4.45031289275240888144113950566e0, 1.89151789931450038304281599044e0,
       -5.8012039600105847814672114227e0, 3.1116436695781989440891606237e-1, -1.52160949662516078556178806805e-1,
       2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2});
  t.a[12] = t.b;  // b_j is also a_{13,j}: stage 13 is f(t + h, y_1).
  t.order = 8;
  for (int j = 0; j < 12; ++j) t.b_hat[j] = t.b[j] - dop853_e5[j];
  t.embedded_order = 5;
  return t;
}();

inline constexpr explicit_tableau<12> dop853_tableau = leading_stages<12>(dop853_extended);

// The order-3 embedded weights (dop853.f's bhh1, bhh2, bhh3, on stages 1, 9, 12).
inline constexpr int dop853_b_hat3_order = 3;
inline constexpr std::array<double, 12> dop853_b_hat3 = [] {
  std::array<double, 12> w{};
  w[1 - 1] = 0.244094488188976377952755905512e+00;   // bhh1
  w[9 - 1] = 0.733846688281611857341361741547e+00;   // bhh2
  w[12 - 1] = 0.220588235294117647058823529412e-01;  // bhh3
  return w;
}();

// Dense output of order 7 (dop853.f, "final preparation for dense output" and CONTD8):
// with theta = (t - t_n) / h, y(t_n + theta h) = y_n + h sum_{i<=16} b_i(theta) k_i,
//   b(theta) = theta (b + (1 - theta) ((e_1 - b) + theta ((2 b - e_1 - e_13)
//              + (1 - theta) (d4 + theta (d5 + (1 - theta) (d6 + theta d7)))))),
// d4..d7 the rows below (dop853.f's d41..d716; its CONT(5..8) are h d_r.k), e_i the
// unit vectors; b(1) = b, b(0) = 0.
inline constexpr int dop853_dense_order = 7;
inline constexpr std::array<std::array<double, 16>, 4> dop853_dense_d = [] {
  std::array<std::array<double, 16>, 4> t{};
  auto d = [&t](int r, std::initializer_list<int> js, std::initializer_list<double> vs) {
    set_entries(t[r - 4], js, vs);
  };
  d(4, {1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
    {-0.84289382761090128651353491142e+01, 0.56671495351937776962531783590e+00, -0.30689499459498916912797304727e+01,
     0.23846676565120698287728149680e+01, 0.21170345824450282767155149946e+01, -0.87139158377797299206789907490e+00,
     0.22404374302607882758541771650e+01, 0.63157877876946881815570249290e+00, -0.88990336451333310820698117400e-01,
     0.18148505520854727256656404962e+02, -0.91946323924783554000451984436e+01, -0.44360363875948939664310572000e+01});
  d(5, {1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
    {0.10427508642579134603413151009e+02, 0.24228349177525818288430175319e+03, 0.16520045171727028198505394887e+03,
     -0.37454675472269020279518312152e+03, -0.22113666853125306036270938578e+02, 0.77334326684722638389603898808e+01,
     -0.30674084731089398182061213626e+02, -0.93321305264302278729567221706e+01, 0.15697238121770843886131091075e+02,
     -0.31139403219565177677282850411e+02, -0.93529243588444783865713862664e+01, 0.35816841486394083752465898540e+02});
  d(6, {1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
    {0.19985053242002433820987653617e+02, -0.38703730874935176555105901742e+03, -0.18917813819516756882830838328e+03,
     0.52780815920542364900561016686e+03, -0.11573902539959630126141871134e+02, 0.68812326946963000169666922661e+01,
     -0.10006050966910838403183860980e+01, 0.77771377980534432092869265740e+00, -0.27782057523535084065932004339e+01,
     -0.60196695231264120758267380846e+02, 0.84320405506677161018159903784e+02, 0.11992291136182789328035130030e+02});
  d(7, {1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
    {-0.25693933462703749003312586129e+02, -0.15418974869023643374053993627e+03, -0.23152937917604549567536039109e+03,
     0.35763911791061412378285349910e+03, 0.93405324183624310003907691704e+02, -0.37458323136451633156875139351e+02,
     0.10409964950896230045147246184e+03, 0.29840293426660503123344363579e+02, -0.43533456590011143754432175058e+02,
     0.96324553959188282948394950600e+02, -0.39177261675615439165231486172e+02, -0.14972683625798562581422125276e+03});
  return t;
}();

constexpr std::array<double, 16> dop853_dense_weights(double theta) {
  const double t1 = 1.0 - theta;
  std::array<double, 16> w{};
  for (int i = 0; i < 16; ++i) {
    const double b = dop853_extended.b[i];
    const double e1 = i == 0 ? 1.0 : 0.0, e13 = i == 12 ? 1.0 : 0.0;
    const auto& d = dop853_dense_d;
    const double tail = d[0][i] + theta * (d[1][i] + t1 * (d[2][i] + theta * d[3][i]));
    w[i] = theta * (b + t1 * ((e1 - b) + theta * ((2.0 * b - e1 - e13) + t1 * tail)));
  }
  return w;
}

// ---------------------------------------------------------------------------------
// Verner's "most efficient" pairs: J. H. Verner, Numerically optimal Runge-Kutta pairs
// with interpolants, Numer. Algorithms 53 (2010) 383-396, whose coefficients are
// published on his web page (www.sfu.ca/~jverner/, "Jim Verner's Refuge for
// Runge-Kutta Pairs") exactly and to 40 digits, in files dated December 2008 (the
// 081206 and 081209 in their names; the page has later sets too). These are the
// coefficients of OrdinaryDiffEq.jl's Vern7 and Vern9; the pairs are meant to step
// with b, the higher order.
//
// Digits. Verner's 40-digit decimals, verbatim but for a leading 0, read from two
// public copies of his float files that agree digit for digit: QuTiP
// (qutip/solver/integrator/verner7efficient.py, verner9efficient.py) and rklib
// (jacobwilliams/rklib, src/rklib_variable_steps.f90, rkv76e and rkv98e). Except: a
// row (of A, or c, b, b_hat) whose entries are all rationals p/q with |p| and q below
// 2^53 is written as those rationals (exact in double, so p/q is correctly rounded),
// read from OrdinaryDiffEq.jl (lib/OrdinaryDiffEqVerner/src/verner_tableaus.jl,
// Vern7Tableau and Vern9Tableau for generic number types), which carries Verner's exact
// values (rationals; for 9(8) also rationals times sqrt(6)). In 80-digit arithmetic the
// decimals agree with those exact values to 5e-40 (7(6)) and 1.4e-38 (9(8)) relative,
// and every double below is the correctly rounded exact value. (OrdinaryDiffEq.jl's own
// Float64 literals are not: 12 of the 58 nonzero entries of 7(6) are off by one unit in
// the last place, 38 of the 108 of 9(8) by up to 38 units (a_{12,9}); they were not
// used.) Both pairs are proved in tests/test_tableaus.cpp.

// Verner 7(6), "RKV76.IIa Most efficient" (file RKV76.IIa.Efficient.00001675585.081206):
// 10 stages, order 7, embedded order 6. Not FSAL: b_10 = 0, so stage 10 (c = 1) enters
// only b_hat; an adaptive step costs 10 evaluations, a fixed step 9. (Verner's
// interpolant starts from an 11th stage, f(t + h, y_1), and adds more; not stored here.)
inline constexpr explicit_tableau<10> vern7_tableau = [] {
  explicit_tableau<10> t{};
  auto a = [&t](int i, std::initializer_list<int> js, std::initializer_list<double> vs) {
    set_entries(t.a[i - 1], js, vs);
  };
  set_entries(t.c, {2, 3, 4, 5, 6, 7, 8, 9, 10},
              {1.0 / 200.0, 49.0 / 450.0, 49.0 / 300.0, 911.0 / 2000.0, 3480084980.0 / 5709648941.0, 221.0 / 250.0,
               37.0 / 40.0, 1.0, 1.0});
  a(2, {1}, {1.0 / 200.0});
  a(3, {1, 2}, {-4361.0 / 4050.0, 2401.0 / 2025.0});
  a(4, {1, 3}, {49.0 / 1200.0, 49.0 / 400.0});
  a(5, {1, 3, 4}, {2454451729.0 / 3841600000.0, -9433712007.0 / 3841600000.0, 4364554539.0 / 1920800000.0});
  a(6, {1, 3, 4, 5},
    {-2.661577375018757131119259297861818119279, 10.80451388645613769565396655365532838482,
     -8.353914657396199411968048547819291691541, 0.8204875949566569791420417341743839209619});
  a(7, {1, 3, 4, 5, 6},
    {6.067741434696770992718360183877276714679, -24.71127363591108579734203485290746001803,
     20.42751793078889394045773111748346612697, -1.906157978816647150624096784352757010879,
     1.006172249242068014790040335899474187268});
  a(8, {1, 3, 4, 5, 6, 7},
    {12.05467007625320299509109452892778311648, -49.75478495046898932807257615331444758322,
     41.14288863860467663259698416710157354209, -4.461760149974004185641911603484815375051,
     2.042334822239174959821717077708608543738, -0.9834843665406107379530801693870224403537e-1});
  a(9, {1, 3, 4, 5, 6, 7, 8},
    {10.13814652288180787641845141981689030769, -42.64113603171750214622846006736635730625,
     35.76384003992257007135021178023160054034, -4.348022840392907653340370296908245943710,
     2.009862268377035895441943593011827554771, 0.3487490460338272405953822853053145879140,
     -0.2714390051048312842371587140910297407572});
  a(10, {1, 3, 4, 5, 6, 7},
    {-45.03007203429867712435322405073769635151, 187.3272437654588840752418206154201997384,
     -154.0288236935018690596728621034510402582, 18.56465306347536233859492332958439136765,
     -7.141809679295078854925420496823551192821, 1.308808578161378625114762706007696696508});
  set_entries(t.b, {1, 4, 5, 6, 7, 8, 9},
              {0.4715561848627222170431765108838175679569e-1, 0.2575056429843415189596436101037687580986,
               0.2621665397741262047713863095764527711129, 0.1521609265673855740323133199165117535523,
               0.4939969170032484246907175893227876844296, -0.2943031171403250441557244744092703429139,
               0.8131747232495109999734599440136761892478e-1});
  set_entries(t.b_hat, {1, 4, 5, 6, 7, 10},
              {0.4460860660634117628731817597479197781432e-1, 0.2671640378571372680509102260943837899738,
               0.2201018300177293019979715776650753096323, 0.2188431703143156830983120833512893824578,
               0.2289871705411202883378173889763552365362, 0.2029518466335628222767054793810430358554e-1});
  t.order = 7;
  t.embedded_order = 6;
  return t;
}();

// Verner 9(8), "RKV98.IIa Most efficient" (file RKV98.IIa.Efficient.000000349.081209):
// 16 stages, order 9, embedded order 8. Nodes c_3, c_4, c_6, c_7 and the entries that
// depend on them involve sqrt(6), hence decimals. Not FSAL: b_16 = 0, so stage 16
// (c = 1) enters only b_hat; an adaptive step costs 16 evaluations, a fixed step 15.
inline constexpr explicit_tableau<16> vern9_tableau = [] {
  explicit_tableau<16> t{};
  auto a = [&t](int i, std::initializer_list<int> js, std::initializer_list<double> vs) {
    set_entries(t.a[i - 1], js, vs);
  };
  set_entries(t.c, {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
              {0.3462e-1, 0.9702435063878044594828361677100617517633e-1, 0.1455365259581706689224254251565092627645,
               0.561, 0.2290079115904850126662751771814700052182, 0.5449920884095149873337248228185299947818, 0.645,
               0.4837500000000000000000000000000000000000, 0.6757e-1, 0.2500,
               0.6590650618730998549405331618649220295334, 0.8206, 0.9012, 1.0, 1.0});
  a(2, {1}, {1731.0 / 50000.0});
  a(3, {1, 2}, {-0.389335438857287327017042687229284478532e-1, 0.1359578945245091786499878854939346230295});
  a(4, {1, 3}, {0.3638413148954266723060635628912731569111e-1, 0.1091523944686280016918190688673819470733});
  a(5, {1, 3, 4},
    {2.025763914393969636805657604282571047511, -7.638023836496292020387602153091964592952,
     6.173259922102322383581944548809393545442});
  a(6, {1, 4, 5},
    {0.5112275589406060872792270881648288397197e-1, 0.1770823794555021537929910813839068684087,
     0.80277624092225014536138698108025283759e-3});
  a(7, {1, 4, 5, 6},
    {0.1316006357975216279279871693164256985334, -0.2957276252669636417685183174672273730699,
     0.878137803564295237421124704053886667082e-1, 0.6213052975225274774321435005639430026100});
  a(8, {1, 6, 7},
    {0.7166666666666666666666666666666666666667e-1, 0.3305533578915319409260346730051472207728,
     0.2427799754418013924072986603281861125606});
  a(9, {1, 6, 7, 8},
    {0.7180664062500000000000000000000000000000e-1, 0.3294380283228177160744825466257672816401,
     0.1165190029271822839255174533742327183599, -0.3401367187500000000000000000000000000000e-1});
  a(10, {1, 6, 7, 8, 9},
    {0.4836757646340646986611287718844085773549e-1, 0.3928989925676163974333190042057047002852e-1,
     0.1054740945890344608263649267140088017604, -0.2143865284648312665982642293830533996214e-1,
     -0.1041229174627194437759832813847147895623});
  a(11, {1, 6, 7, 8, 9, 10},
    {-0.2664561487201478635337289243849737340534e-1, 0.3333333333333333333333333333333333333333e-1,
     -0.1631072244872467239162704487554706387141, 0.3396081684127761199487954930015522928244e-1,
     0.1572319413814626097110769806810024118077, 0.2152267478031879552303534778794770376960});
  a(12, {1, 6, 7, 8, 9, 10, 11},
    {0.3689009248708622334786359863227633989718e-1, -0.1465181576725542928653609891758501156785,
     0.2242577768172024345345469822625833796001, 0.2294405717066072637090897902753790803034e-1,
     -0.35850052905728761357394424889330334334e-2, 0.8669223316444385506869203619044453906053e-1,
     0.4383840651968337846196219974168630120572});
  a(13, {1, 6, 7, 8, 9, 10, 11, 12},
    {-0.4866012215113340846662212357570395295088, -6.304602650282852990657772792012007122988,
     -0.281245618289472564778284183790118418111, -2.679019236219849057687906597489223155566,
     0.518815663924157511565311164615012522024, 1.365353187603341710683633635235238678626,
     5.885091088503946585721274891680604830712, 2.802808786272062889819965117517532194812});
  a(14, {1, 6, 7, 8, 9, 10, 11, 12, 13},
    {0.4185367457753471441471025246471931649633, 6.724547581906459363100870806514855026676,
     -0.425444280164611790606983409697113064616, 3.343279153001265577811816947557982637749,
     0.617081663117537759528421117507709784737, -0.929966123939932833937749523988800852013,
     -6.099948804751010722472962837945508844846, -3.002206187889399044804158084895173690015,
     0.2553202529443445472336424602988558373637});
  a(15, {1, 6, 7, 8, 9, 10, 11, 12, 13, 14},
    {-0.779374086122884664644623040843840506343, -13.93734253810777678786523664804936051203,
     1.252048853379357320949735183924200895136, -14.69150040801686878191527989293072091588,
     -0.494705058533141685655191992136962873577, 2.242974909146236657906984549543692874755,
     13.36789380382864375813864978592679139881, 14.39665048665068644512236935340272139005,
     -0.7975813331776800379127866056663258667437, 0.4409353709534277758753793068298041158235});
  a(16, {1, 6, 7, 8, 9, 10, 11, 12, 13},
    {2.058051337466886442151242368989994043993, 22.35793772796803295519317565842520212899,
     0.90949810997556332745009198137971890783, 35.89110098240264104710550686568482456493,
     -3.442515027624453437985000403608480262211, -4.865481358036368826566013387928704014496,
     -18.90980381354342625688427480879773032857, -34.26354448030451782929251177395134170515,
     1.264756521695642578827783499806516664686});
  set_entries(t.b, {1, 8, 9, 10, 11, 12, 13, 14, 15},
              {0.1461197685842315252051541915018784713459e-1, -0.3915211862331339089410228267288242030810,
               0.2310932500289506415909675644868993669908, 0.1274766769992852382560589467488989175618,
               0.2246434176204157731566981937082069688984, 0.5684352689748512932705226972873692126743,
               0.5825871557215827200814768021863420902155e-1, 0.1364317403482215641609022744494239843327,
               0.3057013983082797397721005067920369646664e-1});
  set_entries(t.b_hat, {1, 8, 9, 10, 11, 12, 13, 16},
              {0.1996996514886773085518508418098868756464e-1, 2.191499304949330054530747099310837524864,
               0.8857071848208438030833722031786358862953e-1, 0.1140560234865965622484956605091432032674,
               0.2533163805345107065564577734569651977347, -2.056564386240941011158999594595981300493,
               0.3408096799013119935160094894224543812830, 0.4834231373823958314376726739772871714902e-1});
  t.order = 9;
  t.embedded_order = 8;
  return t;
}();

// ---------------------------------------------------------------------------------
// Symmetric compositions of velocity Verlet (types in tableau.hpp). Each set is the
// list of sub-step weights w_1..w_N in the order they are applied (palindromic), then
// the kick/drift sequence derived from it.

// Order 4, the "triple jump": w1 = 1 / (2 - 2^(1/3)), w0 = -2^(1/3) / (2 - 2^(1/3)),
// weights (w1, w0, w1). Forest & Ruth, Physica D 43 (1990) 105; Yoshida, Phys. Lett. A
// 150 (1990) 262 (his construction of order 4 from order 2). Written to 40 digits,
// which match the closed form evaluated in 45-digit arithmetic; the test checks them
// against the closed form in double.
inline constexpr verlet_composition<3> triple_jump4 = {
    .w = {1.351207191959657634047687808971460826922, -1.702414383919315268095375617942921653844,
          1.351207191959657634047687808971460826922},
    .order = 4,
};

// Order 6, Yoshida 1990 (Phys. Lett. A 150, 262), Table 1, solution A: 7 sub-steps
// (w3, w2, w1, w0, w1, w2, w3), w0 = 1 - 2 (w1 + w2 + w3). The paper prints 15 digits
// (w1 = -0.117767998417887e1, w2 = 0.235573213359357, w3 = 0.784513610477560), which
// solve its order equations only to about 3e-15; the 40-digit roots below are those of
// SUNDIALS ARKODE (arkode_sprk.c, ARKODE_SPRK_YOSHIDA_6_8, citing the same paper) and
// agree with the printed values to within 5e-15 (checked in the test).
inline constexpr verlet_composition<7> yoshida6a = [] {
  const double w1 = -1.177679984178871006946415680964315734639;
  const double w2 = 0.2355732133593581336847931829785346016865;
  const double w3 = 0.7845136104775572638194976338663498757768;
  const double w0 = 1.315186320683911218884249728238862514352;
  return verlet_composition<7>{.w = {w3, w2, w1, w0, w1, w2, w3}, .order = 6};
}();

// Order 8, Yoshida 1990 (Phys. Lett. A 150, 262), Table 2, solution D: 15 sub-steps
// (w7, ..., w1, w0, w1, ..., w7), w0 = 1 - 2 (w1 + ... + w7). Only the 15 printed
// digits exist, so its order conditions hold only to those digits, not to round-off
// (sum w^3, w^5, w^7 are 4e-14, 5e-13, 3e-12; the test derives its tolerance from the
// printed digits). Kept for comparison: its weights reach |w| = 1.96 (w0 = 1.71);
// kahan_li8 below is the better 8th-order set (error ~350 times smaller on the
// pendulum test).
inline constexpr verlet_composition<15> yoshida8d = [] {
  // w1 .. w7 as printed.
  const std::array<double, 7> wk = {0.102799849391985,    -0.196061023297549e1, 0.193813913762276e1, -0.158240635368243,
                                    -0.144485223686048e1, 0.253693336566229,    0.914844246229740};
  verlet_composition<15> m{.order = 8};
  double sum = 0.0;
  for (double x : wk) sum += x;
  m.w[7] = 1.0 - 2.0 * sum;
  for (int k = 0; k < 7; ++k) m.w[6 - k] = m.w[8 + k] = wk[k];
  return m;
}();

// Order 8, 15 sub-steps with small weights (max |w| = 0.80): the set Kahan & Li name
// s15odr8 (Composition constants for raising the orders of unconventional schemes for
// ordinary differential equations, Math. Comp. 66 (1997) 1089-1099). Digits read from
// SUNDIALS ARKODE (arkode_sprk.c, ARKODE_SPRK_SUZUKI_UMENO_8_16, 40 digits), which
// attributes the set to Suzuki & Umeno (1993) and McLachlan (SIAM J. Sci. Comput. 16
// (1995) 151); the same values, rounded to 20 digits, are s15odr8 in REBOUND's
// integrator_janus.c. Applied as (g1, ..., g7, g8, g7, ..., g1).
inline constexpr verlet_composition<15> kahan_li8 = [] {
  const std::array<double, 8> g = {
      0.7416703643506129534482278017838063156035, -0.4091008258000315939973000958935634173099,
      0.1907547102962383799538762564503716627355, -0.5738624711160822666563877266355357421595,
      0.2990641813036559238444635406886029882258, 0.3346249182452981837849579798821822886337,
      0.3152930923967665966320566638110024309941, -0.7968879393529163540197888401737330534463,
  };
  verlet_composition<15> m{.order = 8};
  for (int k = 0; k < 8; ++k) m.w[k] = m.w[14 - k] = g[k];
  return m;
}();

inline constexpr auto triple_jump4_kick_drift = kick_drift(triple_jump4);

}  // namespace stepbench
