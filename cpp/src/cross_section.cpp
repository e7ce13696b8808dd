#include "stablepush/cross_section.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_2_algorithms.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace stablepush {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;

std::vector<Epick::Point_2> to_cgal(const std::vector<Vec2>& vertices) {
  std::vector<Epick::Point_2> points;
  points.reserve(vertices.size());
  for (const Vec2& v : vertices) points.emplace_back(v.x(), v.y());
  return points;
}

double squared_distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).squaredNorm();
}

// Signed area (shoelace), positive for counterclockwise with x right and z up.
double signed_area(const std::vector<Vec2>& v) {
  double twice = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vec2& p = v[i];
    const Vec2& q = v[(i + 1) % v.size()];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice;
}

}  // namespace

struct CrossSection::ExactPolygon {
  std::vector<Epick::Point_2> points;
};

Vec2 unit_circle_point(long j, long n) {
  // Work with the angle fraction P/Q = j/n scaled so that Q/2 and Q/4 are integers.
  long Q = 8 * n;
  long P = (8 * j) % Q;
  if (P < 0) P += Q;
  if (2 * P > Q) {  // lower half: mirror about the x axis
    const Vec2 v = unit_circle_point(Q - P, Q);
    return Vec2(v.x(), -v.y());
  }
  if (4 * P > Q) {  // second quadrant: mirror about the z axis
    const Vec2 v = unit_circle_point(Q / 2 - P, Q);
    return Vec2(-v.x(), v.y());
  }
  if (8 * P > Q) {  // upper half of the first quadrant: mirror about the diagonal
    const Vec2 v = unit_circle_point(Q / 4 - P, Q);
    return Vec2(v.y(), v.x());
  }
  if (P == 0) return Vec2(1.0, 0.0);
  if (8 * P == Q) return Vec2(std::sqrt(0.5), std::sqrt(0.5));
  const double angle = 2.0 * M_PI * static_cast<double>(P) / static_cast<double>(Q);
  return Vec2(std::cos(angle), std::sin(angle));
}

std::string CrossSection::defect(const std::vector<Vec2>& vertices) {
  if (vertices.size() < 3) return "a polygon needs at least 3 vertices";
  for (const Vec2& v : vertices)
    if (!std::isfinite(v.x()) || !std::isfinite(v.y())) return "a vertex is not a finite number";
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (vertices[i] == vertices[(i + 1) % vertices.size()]) {
      std::ostringstream msg;
      msg << "vertices " << i << " and " << (i + 1) % vertices.size() << " coincide";
      return msg.str();
    }
  const auto points = to_cgal(vertices);
  if (CGAL::orientation_2(points.begin(), points.end(), Epick()) == CGAL::COLLINEAR ||
      !CGAL::is_simple_2(points.begin(), points.end(), Epick())) {
    // is_simple_2 also refuses a polygon whose vertices are all on one line (zero area).
    return "the polygon is self-intersecting or degenerate (zero area)";
  }
  return "";
}

CrossSection::CrossSection(std::vector<Vec2> vertices) : vertices_(std::move(vertices)) {
  const std::string why = defect(vertices_);
  if (!why.empty()) throw std::invalid_argument(why);
  if (signed_area(vertices_) < 0.0) std::reverse(vertices_.begin(), vertices_.end());

  // Area, centroid and polar second moment of a simple polygon by the shoelace decomposition.
  double a2 = 0.0, cx = 0.0, cz = 0.0, j_origin = 0.0;
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec2& p = vertices_[i];
    const Vec2& q = vertices_[(i + 1) % vertices_.size()];
    const double w = p.x() * q.y() - q.x() * p.y();
    a2 += w;
    cx += (p.x() + q.x()) * w;
    cz += (p.y() + q.y()) * w;
    j_origin += w * (p.x() * p.x() + p.x() * q.x() + q.x() * q.x() + p.y() * p.y() + p.y() * q.y() + q.y() * q.y());
  }
  area_ = 0.5 * a2;
  centroid_ = Vec2(cx / (3.0 * a2), cz / (3.0 * a2));
  polar_moment_centroid_ = j_origin / 12.0 - area_ * centroid_.squaredNorm();
  for (const Vec2& v : vertices_) circumradius_ = std::max(circumradius_, v.norm());

  auto exact = std::make_shared<ExactPolygon>();
  exact->points = to_cgal(vertices_);
  const auto& pts = exact->points;
  const std::size_t n = pts.size();
  convex_ = true;  // counterclockwise and simple: convex iff no vertex turns right
  for (std::size_t i = 0; i < n && convex_; ++i)
    convex_ = CGAL::orientation(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) != CGAL::RIGHT_TURN;
  exact_ = std::move(exact);
  for (std::size_t i = 0; i < n; ++i) {
    inward_normals_.push_back(inward_normal(static_cast<int>(i)));
    offsets_.push_back(inward_normals_.back().dot(vertices_[i]));
  }
}

CrossSection CrossSection::box(double length_x, double height_z) {
  const double hx = 0.5 * length_x, hz = 0.5 * height_z;
  return CrossSection({Vec2(-hx, -hz), Vec2(hx, -hz), Vec2(hx, hz), Vec2(-hx, hz)});
}

bool CrossSection::contains_disc(const Vec2& center, double radius) const {
  return contains_capsule(center, center, radius);
}

bool CrossSection::contains_capsule(const Vec2& a, const Vec2& b, double radius) const {
  if (convex_) {
    // The least signed distance of the spine's ends inside the edges' lines, in double: each is
    // good to a few ulps of |a|, |b| and the circumradius. A disc (a == b) has one end.
    const bool is_point = a == b;
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < offsets_.size(); ++i) {
      least = std::min(least, inward_normals_[i].dot(a) - offsets_[i]);
      if (!is_point) least = std::min(least, inward_normals_[i].dot(b) - offsets_[i]);
    }
    const double band = 1e-12 * (circumradius_ + a.norm() + b.norm() + radius);
    if (least - radius > band) return true;
    if (radius - least > band) return false;
    return contains_capsule_exactly(a, b, radius);
  }
  // The capsule is inside iff its spine is inside and stays at least `radius` from every edge.
  // Distances are computed in double and re-made exactly only within rounding of tangency.
  if (!spine_inside(a, b)) return false;
  const bool is_point = a == b;
  double min_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec2& p = vertices_[i];
    const Vec2& q = vertices_[(i + 1) % vertices_.size()];
    double d2 = squared_distance_to_segment(a, p, q);
    if (!is_point)
      d2 = std::min({d2, squared_distance_to_segment(b, p, q), squared_distance_to_segment(p, a, b),
                     squared_distance_to_segment(q, a, b)});
    min_d2 = std::min(min_d2, d2);
  }
  const double r2 = radius * radius;
  // The double distance is good to a few ulps of the coordinates' squared magnitude.
  const double band = 1e-12 * (circumradius_ * circumradius_ + a.squaredNorm() + b.squaredNorm() + r2);
  if (min_d2 - r2 > band) return true;
  if (r2 - min_d2 > band) return false;
  return contains_capsule_exactly(a, b, radius);
}

bool CrossSection::spine_inside(const Vec2& a, const Vec2& b) const {
  // Exact predicates (filtered by CGAL): the start inside the closed polygon, and no edge crossed.
  const auto& points = exact_->points;
  if (CGAL::bounded_side_2(points.begin(), points.end(), Epick::Point_2(a.x(), a.y()), Epick()) ==
      CGAL::ON_UNBOUNDED_SIDE)
    return false;
  if (a == b) return true;
  const Epick::Segment_2 spine(Epick::Point_2(a.x(), a.y()), Epick::Point_2(b.x(), b.y()));
  for (std::size_t i = 0; i < points.size(); ++i)
    if (CGAL::do_intersect(spine, Epick::Segment_2(points[i], points[(i + 1) % points.size()]))) return false;
  return true;
}

bool CrossSection::contains_capsule_exactly(const Vec2& a, const Vec2& b, double radius) const {
  if (!spine_inside(a, b)) return false;
  const bool is_point = a == b;
  const Epeck::Point_2 ea(a.x(), a.y()), eb(b.x(), b.y());
  const Epeck::FT exact_r2 = Epeck::FT(radius) * Epeck::FT(radius);
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec2& p = vertices_[i];
    const Vec2& q = vertices_[(i + 1) % vertices_.size()];
    const Epeck::Segment_2 edge(Epeck::Point_2(p.x(), p.y()), Epeck::Point_2(q.x(), q.y()));
    const Epeck::FT d2 =
        is_point ? CGAL::squared_distance(ea, edge) : CGAL::squared_distance(Epeck::Segment_2(ea, eb), edge);
    if (d2 < exact_r2) return false;
  }
  return true;
}

double CrossSection::distance_to_boundary(const Vec2& p) const {
  double min_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < vertices_.size(); ++i)
    min_d2 = std::min(min_d2, squared_distance_to_segment(p, vertices_[i], vertices_[(i + 1) % vertices_.size()]));
  return std::sqrt(min_d2);
}

std::pair<int, double> CrossSection::nearest_edge(const Vec2& a, const Vec2& b) const {
  std::pair<int, double> best{-1, std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec2& p = vertices_[i];
    const Vec2& q = vertices_[(i + 1) % vertices_.size()];
    const double d2 = std::max(squared_distance_to_segment(a, p, q), squared_distance_to_segment(b, p, q));
    if (d2 < best.second) best = {static_cast<int>(i), d2};
  }
  best.second = std::sqrt(best.second);
  return best;
}

std::vector<int> CrossSection::edges_holding(const Vec2& a, const Vec2& b, double tolerance) const {
  std::vector<int> edges;
  const double tol2 = tolerance * tolerance;
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec2& p = vertices_[i];
    const Vec2& q = vertices_[(i + 1) % vertices_.size()];
    if (squared_distance_to_segment(a, p, q) <= tol2 && squared_distance_to_segment(b, p, q) <= tol2)
      edges.push_back(static_cast<int>(i));
  }
  return edges;
}

Vec2 CrossSection::inward_normal(int edge) const {
  if (edge < 0 || edge >= static_cast<int>(vertices_.size())) throw std::out_of_range("edge index");
  const Vec2 d = vertices_[(edge + 1) % vertices_.size()] - vertices_[edge];
  // Counterclockwise polygon: the interior lies to the left of each edge.
  return Vec2(-d.y(), d.x()).normalized();
}

}  // namespace stablepush
