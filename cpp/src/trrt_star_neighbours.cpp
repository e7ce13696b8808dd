// TRRTstar: the tree's neighbour queries, in unit steps (near, nearest_extendable, most_promising_toward_goal).
#include <ompl/base/goals/GoalSampleableRegion.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "stablepush/internal/trrt_star.hpp"
#include "trrt_star_parts.hpp"

namespace stablepush {

// Neighbour queries scan the nodes' coordinates in unit steps, kept contiguous: exact, and
// deterministic (ties go to the older node). Tree sizes here are thousands of nodes, where a
// tight linear scan beats tree structures; OMPL's GNAT would also draw its pivots from OMPL's
// global seed and make plans depend on the process's history.
void TRRTstar::near(const Pose& q, double radius, std::vector<Node*>& out) const {
  const Eigen::Vector3d u = space_->in_unit_steps(q);
  const double r2 = radius * radius;
  std::vector<std::pair<double, std::size_t>> hits;
  for (std::size_t i = 0; i < unit_coords_.size(); ++i) {
    const double d2 = (unit_coords_[i] - u).squaredNorm();
    if (d2 <= r2) hits.emplace_back(d2, i);
  }
  std::stable_sort(hits.begin(), hits.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.clear();
  for (const auto& hit : hits) out.push_back(nodes_[hit.second]);
}

TRRTstar::Node* TRRTstar::nearest_extendable(const Pose& q) const {
  const Eigen::Vector3d u = space_->in_unit_steps(q);
  Node* best = nullptr;
  double best_d2 = 0.0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const double d2 = (unit_coords_[i] - u).squaredNorm();
    // The coordinates are contiguous, the nodes are not: look at a node only when it would be nearer.
    if (best != nullptr && !(d2 < best_d2)) continue;
    if (nodes_[i]->cost.switches > max_switches_) continue;
    best = nodes_[i];
    best_d2 = d2;
  }
  return best;
}

TRRTstar::Node* TRRTstar::most_promising_toward_goal() const {
  Node* best = nullptr;
  PathCost best_estimate;
  for (Node* n : nodes_) {
    if (n->extended_to_goal || n->cost.switches > max_switches_) continue;
    const PathCost estimate = n->cost + PathCost{0, n->goal_distance};
    if (best == nullptr || estimate < best_estimate) {
      best = n;
      best_estimate = estimate;
    }
  }
  return best;
}

}  // namespace stablepush
