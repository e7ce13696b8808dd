#include "stablepush/gripper.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stablepush {

Gripper::Gripper(std::vector<Pad> pads, double grip_force, double mu, int pad_rings)
    : pads_(std::move(pads)), grip_force_(grip_force), mu_(mu), pad_rings_(pad_rings) {
  if (pads_.empty()) throw std::invalid_argument("a gripper needs at least one pad");
  if (!(grip_force_ > 0.0)) throw std::invalid_argument("grip_force must be > 0");
  if (!(mu_ >= 0.0)) throw std::invalid_argument("mu must be >= 0");
  if (pad_rings_ < 0) throw std::invalid_argument("pad_rings must be >= 0");
  // Uniform pressure: the grip force is spread evenly over the k points of each pad (paper IV-A).
  const int k = 1 + 3 * pad_rings_ * (pad_rings_ + 1);  // 1 + sum_{i=1..rings} 6 i
  const double friction_limit = mu_ * grip_force_ / k;
  for (int p = 0; p < static_cast<int>(pads_.size()); ++p) {
    const Pad& pad = pads_[p];
    if (!(pad.radius >= 0.0)) throw std::invalid_argument("pad radius must be >= 0");
    points_.push_back({pad.center, friction_limit, pad.radius, p});
    for (int ring = 1; ring <= pad_rings_; ++ring) {
      const double radius = pad.radius * ring / pad_rings_;
      for (int j = 0; j < 6 * ring; ++j)
        points_.push_back({pad.center + radius * unit_circle_point(j, 6 * ring), friction_limit, pad.radius, p});
    }
  }
  for (const PadPoint& point : points_) {
    auto same = std::find_if(sites_.begin(), sites_.end(), [&](const PadPoint& site) {
      return site.position == point.position && site.pad_radius == point.pad_radius;
    });
    if (same == sites_.end()) {
      sites_.push_back(point);
    } else {
      same->friction_limit += point.friction_limit;
      same->count += point.count;
    }
  }
}

std::vector<bool> Gripper::pads_inside(const CrossSection& section, const Pose& q) const {
  const Rotation2 rotation(q.theta);
  const Vec2 origin(q.x, q.z);
  std::vector<bool> inside;
  inside.reserve(pads_.size());
  for (const Pad& pad : pads_)
    inside.push_back(section.contains_disc(rotation.apply_inverse(pad.center - origin), pad.radius));
  return inside;
}

bool Gripper::grasp_maintained(const CrossSection& section, const Pose& q) const {
  const Rotation2 rotation(q.theta);
  const Vec2 origin(q.x, q.z);
  for (const Pad& pad : pads_)
    if (!section.contains_disc(rotation.apply_inverse(pad.center - origin), pad.radius)) return false;
  return true;
}

bool Gripper::grasp_maintained_along(const CrossSection& section, const Pose& from, const Pose& to) const {
  const Rotation2 r0(from.theta), r1(to.theta);
  const Vec2 c0(from.x, from.z), c1(to.x, to.z);
  const double dtheta = std::abs(to.theta - from.theta);
  const double dc = (c1 - c0).norm();
  for (const Pad& pad : pads_) {
    // The pad centre in O, f(t) = R(theta(t))^T (p - c(t)), bows away from its chord by at most
    // max|f''| / 8 with |f''| <= dtheta^2 |p - c| + 2 dtheta |dc|; the swept disc therefore lies in
    // the capsule around the chord with its radius grown by that bow.
    const double reach = std::max((pad.center - c0).norm(), (pad.center - c1).norm());
    const double bow = (dtheta * dtheta * reach + 2.0 * dtheta * dc) / 8.0;
    if (!section.contains_capsule(r0.apply_inverse(pad.center - c0), r1.apply_inverse(pad.center - c1),
                                  pad.radius + bow))
      return false;
  }
  return true;
}

}  // namespace stablepush
