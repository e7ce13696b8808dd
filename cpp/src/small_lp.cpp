#include "stablepush/internal/small_lp.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace stablepush {

SmallLpResult maximize_from_feasible(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& c,
                                     const Eigen::VectorXd& x0, int max_iterations) {
  const int rows = static_cast<int>(A.rows());
  const int n = static_cast<int>(A.cols());
  SmallLpResult result;
  result.x = x0;
  std::vector<int>& active = result.active;
  std::vector<char> is_active(rows, 0);
  const double c_norm = c.norm();

  Eigen::MatrixXd AW;
  Eigen::VectorXd y;
  for (int it = 0; it < max_iterations; ++it) {
    result.iterations = it + 1;
    const int k = static_cast<int>(active.size());
    Eigen::VectorXd d = c;
    if (k > 0) {
      AW.resize(k, n);
      for (int i = 0; i < k; ++i) AW.row(i) = A.row(active[i]);
      // Multipliers by least squares, y = (A_W A_W^T)^-1 A_W c; the residual is the search direction.
      y = (AW * AW.transpose()).ldlt().solve(AW * c);
      d = c - AW.transpose() * y;
    }
    if (d.norm() <= 1e-11 * c_norm) {
      // c lies in the span of the active rows: optimal unless a multiplier is negative.
      int drop = -1;
      for (int i = 0; i < k; ++i)
        if (y[i] < -1e-12 * c_norm && (drop < 0 || active[i] < active[drop])) drop = i;
      if (drop < 0) {
        result.status = SmallLpResult::Status::Optimal;
        result.multipliers = k > 0 ? y : Eigen::VectorXd();
        return result;
      }
      is_active[active[drop]] = 0;
      active.erase(active.begin() + drop);
      continue;
    }
    // Ratio test along d: the first row to become tight (smallest index on ties).
    double step = std::numeric_limits<double>::infinity();
    int blocking = -1;
    const double d_norm = d.norm();
    for (int i = 0; i < rows; ++i) {
      if (is_active[i]) continue;
      const double ad = A.row(i).dot(d);
      if (ad <= 1e-13 * A.row(i).norm() * d_norm) continue;
      const double ratio = std::max(0.0, (b[i] - A.row(i).dot(result.x)) / ad);
      if (ratio < step) {
        step = ratio;
        blocking = i;
      }
    }
    if (blocking < 0) {
      result.status = SmallLpResult::Status::Unbounded;
      return result;
    }
    result.x += step * d;
    active.push_back(blocking);
    is_active[blocking] = 1;
  }
  result.status = SmallLpResult::Status::IterationLimit;
  return result;
}

}  // namespace stablepush
