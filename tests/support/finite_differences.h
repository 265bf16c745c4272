// Central finite differences of one energy piece, for derivative tests: the
// energy's gradient g_fd and the gradient's Jacobian H_fd with respect to the
// piece's displacement dofs (ordered 3*a + i), with step eps [m].
#pragma once
#include <Eigen/Dense>

#include "fem/energy.h"

namespace morphfem::testing {

template <class Term>
void piece_finite_differences(const Term& term, int k, const PieceState& s, double eps, Eigen::VectorXd& g_fd,
                              Eigen::MatrixXd& H_fd) {
  const int n = static_cast<int>(3 * s.u.rows());
  g_fd.resize(n);
  H_fd.resize(n, n);
  Eigen::VectorXd gp, gm;
  for (int j = 0; j < n; ++j) {
    PieceState plus = s, minus = s;
    plus.u(j / 3, j % 3) += eps;
    minus.u(j / 3, j % 3) -= eps;
    g_fd[j] = (term.piece(k, plus, nullptr, nullptr) - term.piece(k, minus, nullptr, nullptr)) / (2 * eps);
    term.piece(k, plus, &gp, nullptr);
    term.piece(k, minus, &gm, nullptr);
    H_fd.col(j) = (gp - gm) / (2 * eps);
  }
}

}  // namespace morphfem::testing
