// A dense active-set LP solver for the tiny problems of the sticking case (3 to 7 variables,
// a few dozen rows). Its answers are never trusted on their own: the caller certifies them
// (a primal witness or a dual bound, evaluated directly) or falls back to CGAL's exact solver.
#pragma once

#ifndef STABLEPUSH_INTERNAL_ALLOWED
#error "an internal header of the stablepush core: include stablepush/stable_push.hpp"
#endif

#include <Eigen/Core>
#include <vector>

namespace stablepush {

struct SmallLpResult {
  enum class Status { Optimal, Unbounded, IterationLimit };
  Status status = Status::IterationLimit;
  Eigen::VectorXd x;            ///< the last iterate (optimal when status == Optimal)
  std::vector<int> active;      ///< rows active at x
  Eigen::VectorXd multipliers;  ///< Lagrange multipliers of `active` (>= 0 at an optimum)
  int iterations = 0;
};

/// Maximize c . x subject to A x <= b, starting from a feasible x0. A primal active-set method:
/// move along the projection of c onto the null space of the active rows until a row blocks,
/// and drop the active row with the smallest index among negative multipliers (Bland's rule,
/// so degenerate vertices cannot cycle).
SmallLpResult maximize_from_feasible(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& c,
                                     const Eigen::VectorXd& x0, int max_iterations = 200);

}  // namespace stablepush
