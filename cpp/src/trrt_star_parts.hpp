// TRRTstar's private parts, shared by its source files (trrt_star.cpp: the T-RRT* core;
// trrt_star_steering.cpp: steering, point-pusher wedge steps, descents and runs across;
// trrt_star_neighbours.cpp: the tree's neighbour queries). Not a header of the library.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "stablepush/internal/trrt_star.hpp"

namespace stablepush {

namespace ob = ompl::base;

struct TRRTstar::Node {
  ob::State* state = nullptr;
  Pose pose;
  int pusher = kNoPusher;  ///< the pusher of the push into this node
  Node* parent = nullptr;
  std::vector<Node*> children;
  PathCost cost;
  double goal_distance = 0.0;     ///< T-RRT configuration cost [unit steps]
  bool extended_to_goal = false;  ///< a goal sample has already been extended from here
  int descent = -1;               ///< the descent that made this node or started from it (index into descent_ends_)
  /// Whether the pads hold the object here well enough for a transit (TRRTstar::transit_allowed):
  /// 1 or 0 once known, -1 before.
  mutable signed char transit_held = -1;
};

/// A way to connect a new pose: from `parent`, at `cost`, by any pusher of `pushers`.
struct TRRTstar::Candidate {
  Node* parent = nullptr;
  PathCost cost;
  PusherSet pushers = 0;
};

namespace trrt_star_detail {
/// Edges shorter than this [unit steps] are not pushes (co-located nodes differ only by pusher),
/// and a descent this near the goal is there.
inline constexpr double kMinEdge = GraspPoseSpace::kShortestPush;

inline PusherSet single(int pusher) { return pusher < 0 ? 0u : (1u << pusher); }
}  // namespace trrt_star_detail
using trrt_star_detail::kMinEdge;
using trrt_star_detail::single;

/// The unit steps a descent tries from `from`: turn 0 goes straight toward the goal; turn
/// ring * 8 + k turns from it toward the k-th of eight directions square to the way to the goal,
/// by ring / kRings of steer_angle for rings 1..kRings, and on from steer_angle evenly to 90 deg
/// for the wide rings kRings + 1 .. 2 kRings (the start's first steps across, descend_across).
struct TRRTstar::Steering {
  static constexpr int kRings = 4;

  Steering(const GraspPoseSpace& space, double steer_angle_deg, const Pose& from, const Pose& goal)
      : space(space), steer_angle_deg(steer_angle_deg), from(from) {
    const Eigen::Vector3d to_goal = space.in_unit_steps(goal - from);
    distance = to_goal.norm();
    length = std::min(1.0, distance);
    if (distance < kMinEdge) return;
    u = to_goal / distance;
    // Two directions square to u, from the coordinate axis least aligned with it.
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    Eigen::Index least;
    u.cwiseAbs().minCoeff(&least);
    axis[least] = 1.0;
    e1 = u.cross(axis).normalized();
    e2 = u.cross(e1);
  }

  /// The last ring a descent tries: kRings (none when steer_angle is 0).
  int rings() const { return steer_angle_deg > 0.0 ? kRings : 0; }

  Pose step(int turn) const {
    const int ring = turn / 8;
    const double alpha_deg = ring <= kRings ? steer_angle_deg * ring / kRings
                                            : steer_angle_deg + (90.0 - steer_angle_deg) * (ring - kRings) / kRings;
    const double alpha = alpha_deg * M_PI / 180.0, phi = 2.0 * M_PI * (turn % 8) / 8.0;
    const Eigen::Vector3d dir = std::cos(alpha) * u + std::sin(alpha) * (std::cos(phi) * e1 + std::sin(phi) * e2);
    return from + space.from_unit_steps(length * dir);
  }

  const GraspPoseSpace& space;
  double steer_angle_deg;
  Pose from;
  double distance = 0.0;  ///< to the goal [unit steps]
  double length = 0.0;    ///< of a step [unit steps]: 1, or what is left
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), e1 = Eigen::Vector3d::Zero(), e2 = Eigen::Vector3d::Zero();
};

}  // namespace stablepush
