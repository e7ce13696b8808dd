#pragma once

#include "stablepush/cross_section.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

/// Mass properties of the object in the grasp plane.
struct RigidBody {
  double mass = 0.0;        ///< [kg]
  Vec2 com = Vec2::Zero();  ///< centre of mass in O [m]
  double inertia = 0.0;     ///< moment of inertia about the centre of mass and y [kg m^2]

  /// A uniform prism with this cross-section: com at the centroid, I = m J_c / A.
  static RigidBody uniform(const CrossSection& section, double mass) {
    return RigidBody{mass, section.centroid(), mass * section.polar_moment_about_centroid() / section.area()};
  }
};

}  // namespace stablepush
