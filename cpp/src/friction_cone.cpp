#include "stablepush/friction_cone.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "stablepush/internal/exact.hpp"

namespace stablepush {
namespace {

ExactWrench to_exact(const Wrench& w) { return ExactWrench(exact(w.x()), exact(w.y()), exact(w.z())); }

bool is_zero(const ExactWrench& v) { return CGAL::is_zero(v.x()) && CGAL::is_zero(v.y()) && CGAL::is_zero(v.z()); }

bool same_direction(const ExactWrench& a, const ExactWrench& b) {
  return is_zero(CGAL::cross_product(a, b)) && CGAL::is_positive(a * b);
}

Wrench to_double(const ExactWrench& v) {
  return Wrench(CGAL::to_double(v.x()), CGAL::to_double(v.y()), CGAL::to_double(v.z()));
}

/// One kind of row (facets or equalities), exact and normalized: a normalized row r has
/// sqrt(r_x^2 + r_z^2 + (torque_length r_tau)^2) = 1 (see WrenchCone).
struct RowList {
  std::vector<ExactWrench>& exact;
  std::vector<double>& scales;
  std::vector<Wrench>& rows;
  double torque_length;

  void add(const ExactWrench& row) const {
    const Wrench r = to_double(row);
    const double scale = 1.0 / std::sqrt(r.x() * r.x() + r.y() * r.y() + torque_length * torque_length * r.z() * r.z());
    exact.push_back(row);
    scales.push_back(scale);
    rows.push_back(scale * r);
  }
  /// A facet row, unless a facet of the same direction is there already.
  void add_unique(const ExactWrench& row) const {
    for (const ExactWrench& f : exact)
      if (same_direction(f, row)) return;
    add(row);
  }
};

}  // namespace

WrenchCone::WrenchCone(std::vector<Wrench> generators, double torque_length)
    : generators_(std::move(generators)), torque_length_(torque_length) {
  auto exact_rows = std::make_shared<ExactRows>();
  const RowList facets{exact_rows->facets, facet_scales_, facet_rows_, torque_length_};
  const RowList equalities{exact_rows->equalities, equality_scales_, equality_rows_, torque_length_};
  exact_rows_ = exact_rows;
  if (generators_.empty()) throw std::invalid_argument("a wrench cone needs at least one generator");
  if (!(torque_length_ > 0.0)) throw std::invalid_argument("torque_length must be > 0");
  std::vector<ExactWrench> g;
  for (const Wrench& w : generators_) {
    if (!w.allFinite()) throw std::invalid_argument("a cone generator is not finite");
    g.push_back(to_exact(w));
    if (is_zero(g.back())) throw std::invalid_argument("a cone generator is zero");
  }
  const std::size_t m = g.size();

  // Rank of the generators, exactly: a non-parallel pair (a, b), then a third off their plane.
  std::size_t a = 0, b = m;
  for (std::size_t j = 1; j < m && b == m; ++j)
    if (!is_zero(CGAL::cross_product(g[0], g[j]))) b = j;
  if (b == m) {
    // Dimension 1: the ray through g[0] (every generator is a positive multiple of it).
    for (std::size_t j = 1; j < m; ++j)
      if (!CGAL::is_positive(g[0] * g[j])) throw std::invalid_argument("the cone is not pointed");
    dimension_ = 1;
    facets.add_unique(-g[0]);
    const ExactWrench axes[3] = {ExactWrench(1, 0, 0), ExactWrench(0, 1, 0), ExactWrench(0, 0, 1)};
    for (const ExactWrench& axis : axes) {
      const ExactWrench row = CGAL::cross_product(g[0], axis);
      if (is_zero(row)) continue;
      if (!exact_rows->equalities.empty() && is_zero(CGAL::cross_product(exact_rows->equalities[0], row))) continue;
      equalities.add(row);
      if (exact_rows->equalities.size() == 2) break;
    }
    return;
  }
  const ExactWrench plane_normal = CGAL::cross_product(g[a], g[b]);
  bool full = false;
  for (std::size_t k = 0; k < m && !full; ++k) full = !CGAL::is_zero(plane_normal * g[k]);

  if (!full) {
    // Dimension 2: a wedge in the plane with normal plane_normal, bounded by its two extreme rays.
    dimension_ = 2;
    equalities.add(plane_normal);
    for (std::size_t r = 0; r < m; ++r) {
      bool any_pos = false, any_neg = false;
      for (std::size_t k = 0; k < m; ++k) {
        const CGAL::Sign s = CGAL::sign(CGAL::cross_product(g[r], g[k]) * plane_normal);
        any_pos |= (s == CGAL::POSITIVE);
        any_neg |= (s == CGAL::NEGATIVE);
      }
      if (any_pos && any_neg) continue;  // not an extreme ray
      ExactWrench outward = CGAL::cross_product(plane_normal, g[r]);
      for (std::size_t k = 0; k < m; ++k)
        if (CGAL::is_positive(outward * g[k])) {
          outward = -outward;
          break;
        }
      facets.add_unique(outward);
    }
    return;
  }

  // Dimension 3: every facet of a pointed cone is spanned by two of its extreme rays, so a pair
  // whose plane has all generators on one side gives a facet (duplicates collapse in add_facet).
  dimension_ = 3;
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = i + 1; j < m; ++j) {
      const ExactWrench n = CGAL::cross_product(g[i], g[j]);
      if (is_zero(n)) continue;
      bool any_pos = false, any_neg = false;
      for (std::size_t k = 0; k < m; ++k) {
        const CGAL::Sign s = CGAL::sign(n * g[k]);
        any_pos |= (s == CGAL::POSITIVE);
        any_neg |= (s == CGAL::NEGATIVE);
      }
      if (any_pos && any_neg) continue;
      if (any_pos && !any_neg)
        facets.add_unique(-n);
      else if (any_neg && !any_pos)
        facets.add_unique(n);
      else
        throw std::invalid_argument("the cone is not pointed");
    }
  if (exact_rows->facets.size() < 3) throw std::invalid_argument("the cone is not pointed");
}

double WrenchCone::distance_to_span(const Wrench& w) const {
  double distance = 0.0;
  for (const Wrench& e : equality_rows_) distance = std::max(distance, std::abs(e.dot(w)));
  return distance;
}

}  // namespace stablepush
