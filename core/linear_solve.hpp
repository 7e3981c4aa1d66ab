#pragma once
// The linear solves of an implicit step: the Newton matrix
//   A = c0 I + c1 dF/dv + c2 dF/dx
// (for backward Euler with scalar mass m: m I - h dF/dv - h^2 dF/dx) formed, factored
// and solved in storage sized once per run, in the Jacobian's own shape: a dense Eigen
// matrix (partial-pivoting LU) for a few coordinates, a band matrix (banded LU with
// partial pivoting, core/band_matrix.hpp) for a chain, whose O(n) band solve replaces an
// O(n^3) dense one. Nothing here allocates after resize.
#include <Eigen/Core>
#include <Eigen/LU>

#include "core/band_matrix.hpp"

namespace stepbench {

template <class J>
struct newton_matrix;

// Dense: Eigen's PartialPivLU, which for a fixed size lives on the stack and for a
// dynamic size is sized by its constructor and then reuses its storage.
template <int N, int Options, int MaxRows, int MaxCols>
struct newton_matrix<Eigen::Matrix<double, N, N, Options, MaxRows, MaxCols>> {
  using matrix = Eigen::Matrix<double, N, N, Options, MaxRows, MaxCols>;
  using vector = Eigen::Matrix<double, N, 1>;
  matrix a;
  Eigen::PartialPivLU<matrix> lu;
  vector scratch;

  void resize(const matrix& like) {
    a = like;
    if constexpr (N == Eigen::Dynamic) lu = Eigen::PartialPivLU<matrix>(like.rows());
    scratch = vector::Zero(like.rows());
  }
  // Forms A = c0 I + c1 d + c2 k and factors it; false when A is singular (a zero pivot).
  bool factorize(double c0, double c1, const matrix& d, double c2, const matrix& k) {
    a = c1 * d + c2 * k;
    a.diagonal().array() += c0;
    lu.compute(a);
    return (lu.matrixLU().diagonal().array() != 0.0).all() && lu.matrixLU().allFinite();
  }
  template <class V>
  void solve_in_place(V& b) {
    scratch.noalias() = lu.solve(b);
    b = scratch;
  }
};

template <>
struct newton_matrix<band_matrix> {
  band_matrix a;
  band_lu lu;

  void resize(const band_matrix& like) {
    a.resize(like.rows(), like.kl(), like.ku());
    lu.resize(like.rows(), like.kl(), like.ku());
  }
  bool factorize(double c0, double c1, const band_matrix& d, double c2, const band_matrix& k) {
    a.assign_combination(c0, c1, d, c2, k);
    return lu.factorize(a);
  }
  template <class V>
  void solve_in_place(V& b) {
    lu.solve_in_place(b);
  }
};

}  // namespace stepbench
