// The motion validator of a search with a PushChecker written elsewhere (plan_with_checker, the
// Python PushChecker, the C++ tests' toy checkers): OMPL's question (is a -> b valid?) and the
// search's (which pushers?) both go to the checker.
#pragma once

#ifndef STABLEPUSH_INTERNAL_ALLOWED
#error "an internal header of the stablepush core: include stablepush/planning.hpp or stablepush/search.hpp"
#endif

#include <ompl/base/MotionValidator.h>
#include <ompl/base/SpaceInformation.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "stablepush/search.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

/// A motion a -> b is valid when some pusher makes it a stable push; every PushChecker question is
/// the checker's, so that TRRTstar (which finds its PushChecker as the motion validator) asks it.
class CheckerMotionValidator : public ompl::base::MotionValidator, public PushChecker {
 public:
  CheckerMotionValidator(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<PushChecker> checker);
  bool checkMotion(const ompl::base::State* a, const ompl::base::State* b) const override;
  bool checkMotion(const ompl::base::State* a, const ompl::base::State* b,
                   std::pair<ompl::base::State*, double>& last_valid) const override;

  PusherSet all_pushers() const override;
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override;
  PusherSet stable_pushers_preferring(const Pose& a, const Pose& b, PusherSet candidates,
                                      PusherSet preferred) const override;
  double push_margin(const Pose& a, const Pose& b, int pusher) const override;
  PusherSet wedge_pushers() const override;
  std::optional<Pose> onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction, double length,
                                         int pusher) const override;
  std::vector<double> wedge_translation_headings(const Pose& a, int pusher) const override;
  std::vector<Vec2> pivot_points() const override;
  std::uint64_t feasibility_checks() const override;
  void reset_feasibility_checks() override;

 private:
  std::shared_ptr<PushChecker> checker_;
};

}  // namespace stablepush
