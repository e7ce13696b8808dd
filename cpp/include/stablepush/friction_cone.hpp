// A polyhedral wrench cone and its face-normal (H-)representation, computed exactly with CGAL
// (paper section V-A, "Feasibility Check", and ref. [Hirai91]).
#pragma once

#include <vector>

#include "stablepush/exact.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

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

  /// The same rows in exact arithmetic; facet_rows()[i] is exact_facets()[i] times facet_scales()[i], rounded.
  const std::vector<ExactWrench>& exact_facets() const { return exact_facets_; }
  const std::vector<double>& facet_scales() const { return facet_scales_; }
  const std::vector<ExactWrench>& exact_equalities() const { return exact_equalities_; }
  const std::vector<double>& equality_scales() const { return equality_scales_; }

  /// Distance [N] from w to the cone's linear span (largest |e . w| over the equality rows; 0 in 3-D).
  double distance_to_span(const Wrench& w) const;

  /// Exact test of the facets alone (every facet row strictly negative on w): for a
  /// lower-dimensional cone, whether w's projection onto the span is in the relative interior
  /// (its facet rows lie in the span).
  bool strictly_inside_facets(const ExactWrench& w) const;

 private:
  void add_facet(const ExactWrench& outward);
  void add_equality(const ExactWrench& row);
  double row_scale(const ExactWrench& row) const;

  std::vector<Wrench> generators_;
  double torque_length_;
  int dimension_ = 0;
  std::vector<Wrench> facet_rows_, equality_rows_;
  std::vector<ExactWrench> exact_facets_, exact_equalities_;
  std::vector<double> facet_scales_, equality_scales_;
};

}  // namespace stablepush
