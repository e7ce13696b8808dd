// The parallel-jaw gripper: finger pads discretized into hard frictional point contacts
// (paper section IV-A, docs/model.md section 2).
#pragma once

#include <vector>

#include "stablepush/cross_section.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

/// A finger pad: a disc fixed in G.
struct Pad {
  Vec2 center = Vec2::Zero();  ///< in G [m]
  double radius = 0.0;         ///< [m]
};

/// One constituent point contact of a pad.
struct PadPoint {
  Vec2 position;          ///< in G [m]
  double friction_limit;  ///< mu N / k [N]: the largest friction force this point can exert
  double pad_radius;      ///< radius of its pad [m]; sets the slip-speed scale of the stick test
  int pad;                ///< index of its (first) pad
  int count = 1;          ///< pad points it stands for (Gripper::sites merges coincident ones)
};

class Gripper {
 public:
  /// grip_force: N pressed by each pad [N]; mu: pad-object friction; pad_rings: rings per pad
  /// (ring i holds 6 i points at radius i r / pad_rings, first point on +x, plus the centre).
  Gripper(std::vector<Pad> pads, double grip_force, double mu, int pad_rings);

  const std::vector<Pad>& pads() const { return pads_; }
  const std::vector<PadPoint>& points() const { return points_; }
  /// The pad points with coincident ones merged: points at the same place with the same pad
  /// radius (the two pads of a parallel-jaw grasp meet the object at the same place of the grasp
  /// plane) slip, stick and load the object alike, so each becomes one site whose friction limit
  /// is their sum and whose count is their number. What the mechanics walks.
  const std::vector<PadPoint>& sites() const { return sites_; }
  double grip_force() const { return grip_force_; }
  double mu() const { return mu_; }
  int pad_rings() const { return pad_rings_; }

  /// For each pad, whether its disc lies inside the cross-section when the object is at q.
  std::vector<bool> pads_inside(const CrossSection& section, const Pose& q) const;
  /// The grasp is maintained when every pad disc lies inside the cross-section (docs/model.md section 3).
  bool grasp_maintained(const CrossSection& section, const Pose& q) const;
  /// The grasp is maintained throughout the motion that interpolates (x, z, theta) linearly from
  /// `from` to `to`: every pad disc stays inside the cross-section at every instant, not only at
  /// the ends (so a step cannot cut a concave corner).
  bool grasp_maintained_along(const CrossSection& section, const Pose& from, const Pose& to) const;

 private:
  std::vector<Pad> pads_;
  double grip_force_;
  double mu_;
  int pad_rings_;
  std::vector<PadPoint> points_;
  std::vector<PadPoint> sites_;
};

}  // namespace stablepush
