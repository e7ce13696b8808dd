// A polyhedral wrench cone and its face-normal (H-)representation, computed exactly with CGAL
// (paper section V-A, "Feasibility Check", and ref. [Hirai91]).
#pragma once

#include <memory>
#include <vector>

#include "stablepush/types.hpp"

namespace stablepush {

/// The cone's rows in exact arithmetic (CGAL), for the core's exact re-check: internal/exact.hpp.
struct ExactRows;

class WrenchCone {
 public:
  /// The conic hull of `generators` (wrenches in O, each with a positive normal-force part, so
  /// the cone is pointed). `torque_length` [m] turns torques into forces when rows are normalized:
  /// a row r has sqrt(r_x^2 + r_z^2 + (torque_length r_tau)^2) = 1, so r . w is in newtons.
  WrenchCone(std::vector<Wrench> generators, double torque_length);

  /// 1 (a ray: point pusher with mu = 0), 2 (a wedge: a point pusher) or 3.
  int dimension() const { return dimension_; }
  const std::vector<Wrench>& generators() const { return generators_; }
  double torque_length() const { return torque_length_; }

  /// Outward facet rows: w in the cone  <=>  facet_rows()[i] . w <= 0 for all i and the equalities hold.
  const std::vector<Wrench>& facet_rows() const { return facet_rows_; }
  /// Rows spanning the complement of the cone's linear span: e . w = 0 on the cone (empty for dimension 3).
  const std::vector<Wrench>& equality_rows() const { return equality_rows_; }

  /// The same rows in exact arithmetic, before their scales (internal/exact.hpp defines them).
  const ExactRows& exact_rows() const { return *exact_rows_; }
  const std::vector<double>& facet_scales() const { return facet_scales_; }
  const std::vector<double>& equality_scales() const { return equality_scales_; }

  /// Distance [N] from w to the cone's linear span (largest |e . w| over the equality rows; 0 in 3-D).
  double distance_to_span(const Wrench& w) const;

 private:
  std::vector<Wrench> generators_;
  double torque_length_;
  int dimension_ = 0;
  std::vector<Wrench> facet_rows_, equality_rows_;
  std::vector<double> facet_scales_, equality_scales_;
  std::shared_ptr<const ExactRows> exact_rows_;  // shared: copies of a cone share its exact rows
};

}  // namespace stablepush
