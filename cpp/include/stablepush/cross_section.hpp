// The object's cross-section in its own frame O: a simple polygon (concave allowed).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "stablepush/types.hpp"

namespace stablepush {

class CrossSection {
 public:
  /// vertices: the polygon in O [m]. Counterclockwise with x right and z up is the contract;
  /// a clockwise list is reversed. Throws std::invalid_argument with defect() as the message.
  explicit CrossSection(std::vector<Vec2> vertices);

  /// The box of docs/model.md section 4: length along x, height along z [m], centred on O.
  static CrossSection box(double length_x, double height_z);

  /// Why these vertices are not a usable cross-section ("" when they are): fewer than three
  /// vertices, non-finite coordinates, repeated vertices, zero area, self-intersection.
  static std::string defect(const std::vector<Vec2>& vertices);

  const std::vector<Vec2>& vertices() const { return vertices_; }
  /// Area [m^2].
  double area() const { return area_; }
  /// Centroid in O [m].
  const Vec2& centroid() const { return centroid_; }
  /// Polar second moment of area about the centroid, integral of |p - centroid|^2 dA [m^4].
  double polar_moment_about_centroid() const { return polar_moment_centroid_; }
  /// Largest distance from O's origin to the boundary [m]; the length that turns torques into forces
  /// when wrench components are compared (margins in newtons).
  double circumradius() const { return circumradius_; }
  /// Whether the polygon is convex (collinear vertices allowed); containment is then a test
  /// against its edges' half-planes.
  bool convex() const { return convex_; }

  /// Whether the closed disc (centre in O [m], radius [m]) lies inside the closed polygon.
  /// Decided in double unless the answer is within rounding of tangency; then with CGAL's exact
  /// kernel. A convex polygon is the intersection of its edges' inner half-planes, so the disc is
  /// inside iff its centre is at least `radius` inside every edge's line.
  bool contains_disc(const Vec2& center, double radius) const;

  /// Whether the capsule swept by a disc of `radius` [m] whose centre moves along the segment a-b
  /// (in O [m]) lies inside the closed polygon. contains_capsule(c, c, r) == contains_disc(c, r).
  /// In a convex polygon the capsule, the hull of its two end discs, is inside iff both are.
  bool contains_capsule(const Vec2& a, const Vec2& b, double radius) const;

  /// Euclidean distance from a point of O to the boundary [m].
  double distance_to_boundary(const Vec2& p) const;
  /// The edge nearest to the segment a-b as a whole: the one whose larger distance to a and b is
  /// least; returns (edge index, that distance [m]). Edge i runs from vertex i to vertex i + 1.
  std::pair<int, double> nearest_edge(const Vec2& a, const Vec2& b) const;

  /// Indices of the edges (edge i runs from vertex i to vertex i+1) that hold the segment a-b
  /// within `tolerance` [m]; for a point (a == b) on a vertex this names both edges.
  std::vector<int> edges_holding(const Vec2& a, const Vec2& b, double tolerance) const;

  /// Unit normal of edge i pointing into the object.
  Vec2 inward_normal(int edge) const;

 private:
  std::vector<Vec2> vertices_;
  double area_ = 0.0;
  Vec2 centroid_ = Vec2::Zero();
  double polar_moment_centroid_ = 0.0;
  double circumradius_ = 0.0;
  bool convex_ = false;
  /// Edge i's inward unit normal and offset: n_i . p - offset_i is p's signed distance [m] inside
  /// edge i's line (the containment test's half-planes when convex).
  std::vector<Vec2> inward_normals_;
  std::vector<double> offsets_;
  /// The vertices as CGAL points, built once (the general, concave, test and the exact decisions).
  struct ExactPolygon;
  std::shared_ptr<const ExactPolygon> exact_;
  /// The segment a-b starts inside the closed polygon and crosses no edge (touching one counts as
  /// crossing unless a == b); exact predicates.
  bool spine_inside(const Vec2& a, const Vec2& b) const;
  /// contains_capsule decided in exact arithmetic (within rounding of tangency).
  bool contains_capsule_exactly(const Vec2& a, const Vec2& b, double radius) const;
};

}  // namespace stablepush
