// Pad friction in MuJoCo that sticks and slides as Coulomb's law says: the simulated arm's one
// compiled part (python/stablepush/sim/mujoco/friction.py explains the physics, its thresholds and why).
//
// A pad point whose own slip says it slides gets its contact made frictionless for the step and
// Coulomb's friction applied as a generalized force,
//     qfrc_applied = sum over its contacts of J_t^T (mu N d)   [N -> generalized],
// with N the contact's normal force in the previous step [N], mu the pad pair's coefficient and d
// the unit friction direction in the contact's tangent plane (world frame, the contact rows' sign
// convention). d is found by trial steps on a scratch copy of the state until it opposes the slip it
// produces at the end of the step (backward Euler). Every other point keeps the solver's friction.
//
// It is C++ because the work is a few loops over a dozen contacts at every 0.25 ms step: as numpy
// calls it took half of a simulated run. tests/reference_pad_friction.py is the same algorithm in
// numpy, in the same floating-point order; tests/test_pad_friction.py asks both for the same states.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
#include <vector>

namespace stablepush::sim {

/// The thresholds of the pad friction. friction.py states each one, its unit and why it has its value.
struct PadFrictionParameters {
  double slide_speed;       ///< m/s: a point slipping faster than this for slide_steps steps may slide
  double stick_speed;       ///< m/s: a sliding point whose slip falls below this sticks again
  int slide_steps;          ///< consecutive steps above slide_speed before a point may slide
  double on_cone;           ///< |friction| / (mu N) in the solver's step from which a contact slides
  double directions_agree;  ///< least cosine between a friction and the opposite of its slip
  int max_trials;           ///< trial steps per time step
  double frictionless_mu;   ///< the coefficient of a sliding point's contact (MuJoCo's least)
};

using Vec3 = std::array<double, 3>;

/// The pad contacts of an mjData after its step: per contact its pad point (slot), first constraint
/// row, geom-pair key and contact-frame tangents (world). The contacts and efc_J belong to the state
/// the step started from, qvel to the state it ended in.
struct PadContacts {
  const mjData* data = nullptr;
  std::vector<int> slots;
  std::vector<int> rows;
  std::vector<std::int64_t> keys;
  std::vector<Vec3> t1, t2;
  std::vector<char> touched;  ///< per pad point: any contact
};

class CoulombPadFriction {
 public:
  /// `model` must outlive this object; `pad_geoms` are the pad point geoms (slot k is pad_geoms[k]).
  /// Every explicit contact pair holding a pad geom is switched with it.
  CoulombPadFriction(mjModel* model, const std::vector<int>& pad_geoms, const PadFrictionParameters& parameters);
  ~CoulombPadFriction();
  CoulombPadFriction(const CoulombPadFriction&) = delete;
  CoulombPadFriction& operator=(const CoulombPadFriction&) = delete;

  /// One time step of `data`, after the step's drives are set: `update`, then mj_step, or a copy of the
  /// scratch step when `update` left the step itself there (an accepted trial, or the solver's step).
  void step(mjData* data);

  /// Before an mj_step of `data`, after the step's drives are set: writes model->pair_friction of the
  /// pad pairs and data->qfrc_applied (all of it) with the sliding points' friction. When a trial step
  /// is accepted, qfrc_applied is that trial's force, so mj_step then repeats the trial to the bit.
  void update(mjData* data);

  const std::vector<char>& slipping() const { return slipping_; }  ///< candidates, by their own slip
  const std::vector<char>& sliding() const { return sliding_; }    ///< sliding with our friction
  long solver_steps() const { return solver_steps_; }              ///< scratch steps deciding new sliders
  long trial_steps() const { return trial_steps_; }                ///< scratch steps finding friction directions
  long copied_steps() const { return copied_steps_; }              ///< time steps `step` copied from scratch

 private:
  using Flags = std::vector<char>;
  struct Normals;  // N of the previous step's pad contacts, by geom pair
  struct History;  // the last trial's directions and residual (Anderson step)

  PadContacts contacts_of(const mjData* data) const;
  std::vector<int> count(const PadContacts& at, const Flags& per_contact) const;
  /// The geom-pair keys of the contacts of `points` in `at`, sorted (a pair touching twice is there twice).
  std::vector<std::int64_t> keys_of(const PadContacts& at, const Flags& points) const;
  std::vector<double> end_velocity(const mjData* data) const;
  PadContacts solver_step();
  Flags new_sliders(const PadContacts& solver, const Flags& fresh);
  Flags coulomb_friction(mjData* data, Flags sliding, const Normals& normal, PadContacts at);
  void next_directions(const std::vector<int>& points, const std::vector<Vec3>& opposite, History& history);
  std::vector<double> generalized_friction(const PadContacts& at, const Flags& sliding, const Normals& normal) const;
  void set_frictionless(const Flags& sliding);
  void step_scratch(const std::vector<double>& qfrc);

  mjModel* model_;
  mjData* scratch_;
  PadFrictionParameters p_;
  int n_points_;
  std::vector<int> slot_of_geom_;  // pad point of each geom, or -1
  std::vector<int> pairs_, pair_slots_;
  std::vector<std::array<double, 2>> pair_mu_;  // the pairs' own (task and world) mu
  std::vector<double> point_mu_;
  std::vector<double> state_;
  Flags slipping_, sliding_;
  std::vector<Vec3> direction_;  // per sliding point, its unit friction (world, contact rows' convention)
  std::vector<int> fast_steps_;
  long solver_steps_ = 0, trial_steps_ = 0, copied_steps_ = 0;
  bool scratch_is_step_ = false;  // the scratch data holds the step `update` prepared: `step` copies it
  Flags frictionless_;            // which pad pairs model->pair_friction makes frictionless now
  bool frictionless_known_ = false;
};

}  // namespace stablepush::sim
