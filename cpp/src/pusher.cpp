#include "stablepush/pusher.hpp"

#include <sstream>
#include <stdexcept>

namespace stablepush {

Pusher Pusher::on_boundary(const CrossSection& section, std::string name, const Vec2& a, const Vec2& b, double mu,
                           int n_points) {
  constexpr double kOnBoundaryTolerance = 1e-9;  // m
  if (!(mu >= 0.0)) throw std::invalid_argument("pusher '" + name + "': mu must be >= 0");
  const bool is_point = (a == b);
  if (!is_point && n_points < 2)
    throw std::invalid_argument("pusher '" + name + "': a segment needs at least 2 points");
  const std::vector<int> edges = section.edges_holding(a, b, kOnBoundaryTolerance);
  if (edges.empty()) {
    std::ostringstream msg;
    const auto [edge, distance] = section.nearest_edge(a, b);
    // nearest_edge's distance is the farther end's from the edge that holds the segment best.
    msg << "pusher '" << name << "' is not on the object's boundary: " << (is_point ? "it is " : "its farther end is ")
        << 1e3 * distance << " mm from the nearest edge (edge " << edge << ", from vertex " << edge << ")";
    throw std::invalid_argument(msg.str());
  }
  if (is_point && edges.size() > 1)
    throw std::invalid_argument("pusher '" + name + "' sits on a vertex of the object, where its normal is ambiguous");

  Pusher pusher{std::move(name), {}, section.inward_normal(edges.front()), mu};
  if (is_point) {
    pusher.points.push_back(a);
  } else {
    for (int i = 0; i < n_points; ++i) {
      const double s = static_cast<double>(i) / (n_points - 1);
      pusher.points.push_back((1.0 - s) * a + s * b);
    }
  }
  return pusher;
}

std::vector<Wrench> Pusher::cone_generators() const {
  const Vec2 tangent(-inward_normal.y(), inward_normal.x());
  std::vector<Wrench> generators;
  for (const Vec2& p : points) {
    for (const double side : {+1.0, -1.0}) {
      const Vec2 edge = inward_normal + side * mu * tangent;
      generators.emplace_back(edge.x(), edge.y(), cross_y(p, edge));
      if (mu == 0.0) break;  // both edges coincide
    }
  }
  return generators;
}

}  // namespace stablepush
