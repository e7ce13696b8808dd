#include "coulomb_pad_friction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace stablepush::sim {
namespace {

constexpr unsigned kState = mjSTATE_INTEGRATION;  // everything a step reads, qfrc_applied included
// mjModel::pair_friction holds 5 numbers a pair: tangent 1, tangent 2, torsional, rolling 1, rolling 2.
constexpr int kPairFrictionWidth = 5;

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

double norm(const Vec3& v) { return std::sqrt(dot(v, v)); }

Vec3 unit(const Vec3& v) {
  const double n = std::max(norm(v), 1e-12);
  return {v[0] / n, v[1] / n, v[2] / n};
}

/// Row j's tangential components of a constraint-space vector (nefc values) as a world vector (the contact
/// frame's tangents, in the sign convention of the rows).
Vec3 tangential(const PadContacts& at, const double* per_row, std::size_t j) {
  const double a = per_row[at.rows[j] + 1], b = per_row[at.rows[j] + 2];
  const Vec3 &t1 = at.t1[j], &t2 = at.t2[j];
  return {a * t1[0] + b * t2[0], a * t1[1] + b * t2[1], a * t1[2] + b * t2[2]};
}

bool any(const std::vector<char>& flags) {
  return std::any_of(flags.begin(), flags.end(), [](char f) { return f != 0; });
}

}  // namespace

/// N of each pad contact in the step before this one, looked up by geom pair: a sliding contact had
/// no cone to skew its normal force there. A pair not in contact then falls back to the caller's N.
struct CoulombPadFriction::Normals {
  std::vector<std::pair<std::int64_t, double>> by_key;  // sorted by key, stable

  explicit Normals(const PadContacts& contacts) {
    for (std::size_t j = 0; j < contacts.rows.size(); ++j)
      by_key.emplace_back(contacts.keys[j], contacts.data->efc_force[contacts.rows[j]]);
    std::stable_sort(by_key.begin(), by_key.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  }

  double of(std::int64_t key, double fallback) const {
    auto it = std::lower_bound(by_key.begin(), by_key.end(), key,
                               [](const auto& entry, std::int64_t k) { return entry.first < k; });
    return it != by_key.end() && it->first == key ? it->second : fallback;
  }
};

/// The last trial's directions d and residual r = F(d) - d, all points stacked (Anderson step).
struct CoulombPadFriction::History {
  std::vector<double> d, r;
  bool valid = false;
};

CoulombPadFriction::CoulombPadFriction(mjModel* model, const std::vector<int>& pad_geoms,
                                       const PadFrictionParameters& parameters)
    : model_(model), scratch_(nullptr), p_(parameters), n_points_(static_cast<int>(pad_geoms.size())) {
  if (model_ == nullptr) throw std::invalid_argument("CoulombPadFriction: no model");
  slot_of_geom_.assign(model_->ngeom, -1);
  for (int k = 0; k < n_points_; ++k) {
    const int geom = pad_geoms[k];
    if (geom < 0 || geom >= model_->ngeom)
      throw std::invalid_argument("CoulombPadFriction: pad geom " + std::to_string(geom) + " is not in the model");
    slot_of_geom_[geom] = k;
  }
  point_mu_.assign(n_points_, 0.0);
  for (int i = 0; i < model_->npair; ++i) {
    for (int geom : {model_->pair_geom1[i], model_->pair_geom2[i]}) {
      const int slot = slot_of_geom_[geom];
      if (slot < 0) continue;
      pairs_.push_back(i);
      pair_slots_.push_back(slot);
      const mjtNum* mu = model_->pair_friction + kPairFrictionWidth * i;
      pair_mu_.push_back({mu[0], mu[1]});
      point_mu_[slot] = pair_mu_.back()[0];
    }
  }
  scratch_ = mj_makeData(model_);
  if (scratch_ == nullptr) throw std::runtime_error("CoulombPadFriction: MuJoCo could not allocate its scratch data");
  state_.assign(mj_stateSize(model_, kState), 0.0);
  slipping_.assign(n_points_, 0);
  sliding_.assign(n_points_, 0);
  direction_.assign(n_points_, Vec3{0.0, 0.0, 0.0});
  fast_steps_.assign(n_points_, 0);
  set_frictionless(sliding_);
}

CoulombPadFriction::~CoulombPadFriction() { mj_deleteData(scratch_); }

void CoulombPadFriction::step(mjData* data) {
  update(data);
  if (scratch_is_step_) {
    mj_copyData(data, model_, scratch_);
    ++copied_steps_;
  } else
    mj_step(model_, data);
}

void CoulombPadFriction::update(mjData* data) {
  scratch_is_step_ = false;
  PadContacts contacts = contacts_of(data);
  // Candidates from the previous step's slip (the tangential rows of efc_vel, m/s: the cones are
  // elliptic, so those rows are the contact frame's tangents). A point touching the object through
  // several convex pieces slips if any of them does; a point that touches nothing does not.
  const std::size_t n = contacts.rows.size();
  Flags fast(n), moving(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double slip = std::hypot(data->efc_vel[contacts.rows[j] + 1], data->efc_vel[contacts.rows[j] + 2]);
    fast[j] = slip > p_.slide_speed;
    moving[j] = slip >= p_.stick_speed;
  }
  const std::vector<int> fast_count = count(contacts, fast), moving_count = count(contacts, moving);
  Flags sliding(n_points_);
  for (int k = 0; k < n_points_; ++k) {
    fast_steps_[k] = fast_count[k] > 0 ? fast_steps_[k] + 1 : 0;
    slipping_[k] = contacts.touched[k] && (fast_steps_[k] >= p_.slide_steps || (slipping_[k] && moving_count[k] > 0));
    sliding[k] = sliding_[k] && slipping_[k];
  }
  mju_zero(data->qfrc_applied, model_->nv);
  if (any(slipping_)) {
    mj_getState(model_, data, state_.data(), kState);
    const Normals normal(contacts);
    PadContacts at = std::move(contacts);  // not read after this
    Flags fresh(n_points_);
    for (int k = 0; k < n_points_; ++k) fresh[k] = slipping_[k] && !sliding[k];
    if (any(fresh)) {
      at = solver_step();
      const Flags slides = new_sliders(at, fresh);
      for (int k = 0; k < n_points_; ++k) sliding[k] = sliding[k] || slides[k];
      // no point slides: the step is the solver's, with every friction its own and no force of ours
      scratch_is_step_ = !any(sliding);
    }
    if (any(sliding)) sliding = coulomb_friction(data, sliding, normal, std::move(at));
  }
  if (sliding != sliding_ || any(slipping_)) set_frictionless(sliding);  // a scratch step may have changed them
  sliding_ = std::move(sliding);
}

PadContacts CoulombPadFriction::contacts_of(const mjData* data) const {
  PadContacts c;
  c.data = data;
  c.touched.assign(n_points_, 0);
  for (int i = 0; i < data->ncon; ++i) {
    const mjContact& contact = data->contact[i];
    const int g0 = contact.geom[0], g1 = contact.geom[1];
    if (g0 < 0 || g1 < 0 || contact.efc_address < 0) continue;  // a flex, or excluded from the constraints
    const int slot = std::max(slot_of_geom_[g0], slot_of_geom_[g1]);
    if (slot < 0) continue;
    c.slots.push_back(slot);
    c.rows.push_back(contact.efc_address);
    c.keys.push_back(static_cast<std::int64_t>(g0) * model_->ngeom + g1);
    c.t1.push_back({contact.frame[3], contact.frame[4], contact.frame[5]});
    c.t2.push_back({contact.frame[6], contact.frame[7], contact.frame[8]});
    c.touched[slot] = 1;
  }
  return c;
}

std::vector<int> CoulombPadFriction::count(const PadContacts& at, const Flags& per_contact) const {
  std::vector<int> out(n_points_, 0);
  for (std::size_t j = 0; j < at.slots.size(); ++j) out[at.slots[j]] += per_contact[j] ? 1 : 0;
  return out;
}

std::vector<std::int64_t> CoulombPadFriction::keys_of(const PadContacts& at, const Flags& points) const {
  std::vector<std::int64_t> keys;
  for (std::size_t j = 0; j < at.slots.size(); ++j)
    if (points[at.slots[j]]) keys.push_back(at.keys[j]);
  std::sort(keys.begin(), keys.end());
  return keys;
}

std::vector<double> CoulombPadFriction::end_velocity(const mjData* data) const {
  std::vector<double> velocity(data->nefc, 0.0);
  mj_mulJacVec(model_, data, velocity.data(), data->qvel);
  return velocity;
}

void CoulombPadFriction::step_scratch(const std::vector<double>& qfrc) {
  mj_setState(model_, scratch_, state_.data(), kState);
  mju_copy(scratch_->qfrc_applied, qfrc.data(), model_->nv);
  mj_step(model_, scratch_);
}

PadContacts CoulombPadFriction::solver_step() {
  set_frictionless(Flags(n_points_, 0));
  step_scratch(std::vector<double>(model_->nv, 0.0));
  ++solver_steps_;
  return contacts_of(scratch_);
}

CoulombPadFriction::Flags CoulombPadFriction::new_sliders(const PadContacts& solver, const Flags& fresh) {
  // A fresh candidate slides if all its contacts are on the cone in the solver's step and still
  // slip at its end; its friction direction starts from the solver's.
  const mjData* s = scratch_;
  const std::vector<double> v_end = end_velocity(s);
  const mjtNum* force = s->efc_force;
  const std::size_t n = solver.rows.size();
  Flags stays(n);
  for (std::size_t j = 0; j < n; ++j) {
    const int row = solver.rows[j];
    const double mu = point_mu_[solver.slots[j]];
    const bool on_cone = std::hypot(force[row + 1], force[row + 2]) >= p_.on_cone * mu * force[row];
    stays[j] = !(on_cone && norm(tangential(solver, v_end.data(), j)) >= p_.stick_speed);
  }
  const std::vector<int> staying = count(solver, stays);
  Flags sliding(n_points_);
  for (int k = 0; k < n_points_; ++k) sliding[k] = fresh[k] && staying[k] == 0 && solver.touched[k];
  for (std::size_t j = 0; j < n; ++j)
    if (sliding[solver.slots[j]]) direction_[solver.slots[j]] = unit(tangential(solver, force, j));
  return sliding;
}

CoulombPadFriction::Flags CoulombPadFriction::coulomb_friction(mjData* data, Flags sliding, const Normals& normal,
                                                               PadContacts at) {
  History history;
  for (int trial_number = 0; trial_number < p_.max_trials; ++trial_number) {
    const std::vector<double> qfrc = generalized_friction(at, sliding, normal);
    const std::vector<std::int64_t> pushed_through = keys_of(at, sliding);
    set_frictionless(sliding);
    step_scratch(qfrc);
    ++trial_steps_;
    PadContacts trial = contacts_of(scratch_);
    // The trial can stand as the step only if our force went through the contacts the step has:
    // a sliding point that gained or lost a contact (a convex piece, a multiccd point) would get
    // friction through one that is gone, and none through the new one (its pair is frictionless).
    const bool same_contacts = keys_of(trial, sliding) == pushed_through;
    for (int k = 0; k < n_points_; ++k) sliding[k] = sliding[k] && trial.touched[k];  // no touch, no friction
    const std::vector<double> v_end = end_velocity(scratch_);
    const std::size_t n = trial.rows.size();
    Flags sticks(n);
    std::vector<int> points;
    std::vector<Vec3> opposite;
    double least_agreement = 1.0;
    bool any_sticks = false;
    for (std::size_t j = 0; j < n; ++j) {
      const int slot = trial.slots[j];
      if (!sliding[slot]) continue;
      const Vec3 v = tangential(trial, v_end.data(), j);
      const double speed = norm(v), scale = std::max(speed, 1e-12);
      const Vec3 away{-v[0] / scale, -v[1] / scale, -v[2] / scale};
      const double agree = dot(direction_[slot], away);
      // our friction turned the slip back, or stopped it: the point sticks (the solver's friction)
      sticks[j] = agree <= 0 || speed < p_.stick_speed;
      any_sticks = any_sticks || sticks[j];
      least_agreement = std::min(least_agreement, agree);
      points.push_back(slot);
      opposite.push_back(away);
    }
    at = std::move(trial);
    if (any_sticks) {
      const std::vector<int> stuck = count(at, sticks);
      for (int k = 0; k < n_points_; ++k) sliding[k] = sliding[k] && stuck[k] == 0;
      history.valid = false;
    }
    if (!any(sliding)) return sliding;
    if (any_sticks) continue;
    if (least_agreement >= p_.directions_agree) {
      if (same_contacts) {
        // The trial is the step: each sliding point's friction opposes the slip it produced at the
        // step's end, through the contacts the step has.
        mju_copy(data->qfrc_applied, qfrc.data(), model_->nv);
        scratch_is_step_ = true;
        return sliding;
      }
      break;
    }
    next_directions(points, opposite, history);
  }
  const std::vector<double> qfrc = generalized_friction(at, sliding, normal);
  mju_copy(data->qfrc_applied, qfrc.data(), model_->nv);
  return sliding;
}

void CoulombPadFriction::next_directions(const std::vector<int>& points, const std::vector<Vec3>& opposite,
                                         History& history) {
  // The fixed point d = F(d), F(d) the opposite of the slip d produces. All points ride one object
  // and one hand, so their slips answer together and a plain step can overshoot; one Anderson step
  // (the secant over the last two trials, all points at once) takes that gain out.
  const std::size_t m = 3 * points.size();
  std::vector<double> d(m), r(m), step(m);
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      d[3 * i + c] = direction_[points[i]][c];
      r[3 * i + c] = opposite[i][c] - d[3 * i + c];
    }
  if (history.valid && history.d.size() == m) {
    double dr_dr = 0.0, dr_r = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      const double dr = r[i] - history.r[i];
      dr_dr += dr * dr;
      dr_r += dr * r[i];
    }
    const double gamma = dr_dr > 0 ? dr_r / dr_dr : 0.0;
    for (std::size_t i = 0; i < m; ++i) step[i] = r[i] - gamma * ((d[i] - history.d[i]) + (r[i] - history.r[i]));
  } else {
    for (std::size_t i = 0; i < m; ++i) step[i] = 0.5 * r[i];
  }
  for (std::size_t i = 0; i < points.size(); ++i)
    direction_[points[i]] =
        unit({d[3 * i] + step[3 * i], d[3 * i + 1] + step[3 * i + 1], d[3 * i + 2] + step[3 * i + 2]});
  history.d = std::move(d);
  history.r = std::move(r);
  history.valid = true;
}

std::vector<double> CoulombPadFriction::generalized_friction(const PadContacts& at, const Flags& sliding,
                                                             const Normals& normal) const {
  // J^T f of the sliding points' contacts in `at`: f = mu N d, d each point's direction projected on
  // its contact's tangent plane and made unit again [N -> generalized].
  std::vector<double> per_row(at.data->nefc, 0.0);
  for (std::size_t j = 0; j < at.rows.size(); ++j) {
    const int slot = at.slots[j], row = at.rows[j];
    if (!sliding[slot]) continue;
    const double magnitude = point_mu_[slot] * normal.of(at.keys[j], at.data->efc_force[row]);
    const Vec3 &t1 = at.t1[j], &t2 = at.t2[j], &direction = direction_[slot];
    const double a = dot(direction, t1), b = dot(direction, t2);
    const Vec3 d = unit({a * t1[0] + b * t2[0], a * t1[1] + b * t2[1], a * t1[2] + b * t2[2]});
    const Vec3 force{magnitude * d[0], magnitude * d[1], magnitude * d[2]};
    per_row[row + 1] = dot(force, t1);
    per_row[row + 2] = dot(force, t2);
  }
  std::vector<double> out(model_->nv, 0.0);
  mj_mulJacTVec(model_, at.data, out.data(), per_row.data());
  return out;
}

void CoulombPadFriction::set_frictionless(const Flags& sliding) {
  Flags frictionless(pairs_.size());
  for (std::size_t j = 0; j < pairs_.size(); ++j) frictionless[j] = sliding[pair_slots_[j]];
  if (frictionless_known_ && frictionless == frictionless_) return;  // every write comes through here
  for (std::size_t j = 0; j < pairs_.size(); ++j) {
    mjtNum* mu = model_->pair_friction + kPairFrictionWidth * pairs_[j];
    mu[0] = frictionless[j] ? p_.frictionless_mu : pair_mu_[j][0];
    mu[1] = frictionless[j] ? p_.frictionless_mu : pair_mu_[j][1];
  }
  frictionless_ = std::move(frictionless);
  frictionless_known_ = true;
}

}  // namespace stablepush::sim
