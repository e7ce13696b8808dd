// Pushers: environment features that stick to the object during a stable push. Each is fixed in O
// for the whole push, so its generalized friction cone is computed once per task (paper section V-A).
#pragma once

#include <string>
#include <vector>

#include "stablepush/cross_section.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

struct Pusher {
  std::string name;
  std::vector<Vec2> points;  ///< constituent point contacts in O [m]
  Vec2 inward_normal;        ///< unit normal of the object's boundary at the pusher, into the object, in O
  double mu;                 ///< pusher-object friction coefficient

  /// A pusher on the boundary of `section`: a point (a == b) or the segment a-b discretized into
  /// `n_points` evenly spaced points, ends included. Its normal is the inward normal of the edge
  /// holding it. Throws std::invalid_argument if it is off the boundary (tolerance 1e-9 m), or a
  /// point pusher sits on a vertex (where the normal is ambiguous).
  static Pusher on_boundary(const CrossSection& section, std::string name, const Vec2& a, const Vec2& b, double mu,
                            int n_points);

  /// The generators of its generalized friction cone in O: for every point, the wrenches of the
  /// friction-cone edges n +- mu t (paper section IV-D, "Generalized Friction Cone for a Pusher").
  std::vector<Wrench> cone_generators() const;
};

}  // namespace stablepush
