// The exact re-check of a stable-push decision that the double evaluation could not certify.
// Every input is the double the fast path used; sums and products are exact in CGAL::Gmpzf, and
// the sticking case is CGAL's exact LP solver (about 50 us, so it stays off the common path). The
// pads' hold ratio falls back to the same solver where the fast one stalls.
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>

#include <limits>
#include <vector>

#include "motion_terms.hpp"
#include "stablepush/internal/exact.hpp"

namespace stablepush {
namespace {

struct ExactLoads {
  ExactFT fx = 0, fz = 0, tau = 0;
  std::vector<StickingGroup> groups;

  void force(const Vec2& f, const Vec2& arm) {
    const ExactFT f_x = exact(f.x()), f_z = exact(f.y());
    fx += f_x;
    fz += f_z;
    tau += exact(arm.y()) * f_x - exact(arm.x()) * f_z;
  }
  void torque(double t) { tau += exact(t); }
  void sticking(const Vec2& arm, double friction_limit, int) { add_sticking_point(groups, arm, friction_limit); }
};

/// The motion wrench in O, exactly, from the same doubles (R^T applied with the same cos and sin).
ExactWrench exact_required(const ExactLoads& loads, const Rotation2& R) {
  const ExactFT c = exact(R.c), s = exact(R.s);
  return ExactWrench(c * loads.fx - s * loads.fz, s * loads.fx + c * loads.fz, loads.tau);
}

/// row^T L_g: the covector a wrench row induces on a sticking group's force (f in G).
std::pair<ExactFT, ExactFT> exact_pull_back(const ExactWrench& row, const Rotation2& R, const Vec2& arm) {
  const ExactFT c = exact(R.c), s = exact(R.s);
  return {row.x() * c + row.y() * s + row.z() * exact(arm.y()),
          -(row.x() * s) + row.y() * c - row.z() * exact(arm.x())};
}

}  // namespace

PushResult StablePushModel::exact_all_sliding(const WrenchCone& cone, const MotionWrench& load, const Pose& q,
                                              const Motion& dq, PushResult answer) const {
  ExactLoads loads;
  visit_motion_terms(q, load.rotation, dq, load.gravity, loads);
  const ExactWrench required = exact_required(loads, load.rotation);
  answer.exact = true;
  // The caller found the wrench within the certification band of the cone's span (all_sliding):
  // the facets decide, and they measure its projection onto the span.
  answer.feasible = strictly_inside_facets(cone.exact_rows(), required);
  return answer;
}

// maximize t  s.t.  t - sum_g (k_i a_i^T L_g) f_g <= -k_i a_i . w   (facets, k_i > 0 their scales)
//                      - sum_g (e_j^T L_g) f_g  = -e_j . w        (equalities of a lower-dimensional cone)
//                      n_k . f_g <= rho_g cos(pi / sides)          (friction polygons)
PushResult StablePushModel::exact_sticking(const WrenchCone& cone, const MotionWrench& load, const Pose& q,
                                           const Motion& dq) const {
  ExactLoads loads;
  visit_motion_terms(q, load.rotation, dq, load.gravity, loads);
  const ExactWrench required = exact_required(loads, load.rotation);
  const int groups = static_cast<int>(loads.groups.size());
  const int t_var = 2 * groups;

  using Program = CGAL::Quadratic_program<ExactFT>;
  Program lp(CGAL::SMALLER, false, 0, false, 0);  // free variables, rows "<=" unless set
  int row = 0;
  for (std::size_t i = 0; i < cone.exact_rows().facets.size(); ++i, ++row) {
    const ExactFT k = exact(cone.facet_scales()[i]);
    const ExactWrench a = cone.exact_rows().facets[i];
    for (int g = 0; g < groups; ++g) {
      const auto [u, v] = exact_pull_back(a, load.rotation, loads.groups[g].arm);
      lp.set_a(2 * g, row, -(k * u));
      lp.set_a(2 * g + 1, row, -(k * v));
    }
    lp.set_a(t_var, row, exact(1));
    lp.set_b(row, -(k * (a * required)));
  }
  for (const ExactWrench& e : cone.exact_rows().equalities) {
    for (int g = 0; g < groups; ++g) {
      const auto [u, v] = exact_pull_back(e, load.rotation, loads.groups[g].arm);
      lp.set_a(2 * g, row, -u);
      lp.set_a(2 * g + 1, row, -v);
    }
    lp.set_r(row, CGAL::EQUAL);
    lp.set_b(row, -(e * required));
    ++row;
  }
  for (int g = 0; g < groups; ++g)
    for (int k = 0; k < polygon_sides_; ++k, ++row) {
      lp.set_a(2 * g, row, exact(polygon_normals_[k].x()));
      lp.set_a(2 * g + 1, row, exact(polygon_normals_[k].y()));
      lp.set_b(row, exact(loads.groups[g].friction_limit * polygon_inradius_));
    }
  lp.set_c(t_var, exact(-1));
  const auto solution = CGAL::solve_linear_program(lp, ExactFT());

  PushResult result;
  result.contact_case = ContactCase::Sticking;
  result.sticking_points = load.sticking_points;
  result.exact = true;
  if (solution.is_infeasible()) {
    // No admissible sticking force brings w_pusher onto the cone's span.
    result.feasible = false;
    result.margin = -cone.distance_to_span(load.required);
    result.witness = load.required;
    return result;
  }
  std::vector<double> x;
  for (auto it = solution.variable_values_begin(); it != solution.variable_values_end(); ++it)
    x.push_back(CGAL::to_double(*it));
  const auto t = -solution.objective_value();
  result.feasible = CGAL::is_positive(t);
  result.margin = CGAL::to_double(t);
  result.witness = load.required;
  for (int g = 0; g < groups; ++g) {
    result.witness -= sticking_wrench(load.rotation, loads.groups[g].arm, Vec2(x[2 * g], x[2 * g + 1]));
  }
  return result;
}

// maximize lambda  s.t.  sum_g f_g + lambda W = 0,  sum_g cross_y(arm_g, f_g) + lambda cross_y(r_cm, W) = 0,
//                        n_k . f_g <= rho_g cos(pi / sides),  lambda <= cap        (hold_ratio's LP)
double StablePushModel::exact_hold_ratio(const std::vector<StickingGroup>& groups, const Vec2& weight, const Vec2& r_cm,
                                         double cap) const {
  const int count = static_cast<int>(groups.size());
  const int lambda = 2 * count;
  using Program = CGAL::Quadratic_program<ExactFT>;
  Program lp(CGAL::EQUAL, false, 0, false, 0);  // free variables, rows "=" unless set
  for (int g = 0; g < count; ++g) {
    lp.set_a(2 * g, 0, exact(1));
    lp.set_a(2 * g + 1, 1, exact(1));
    lp.set_a(2 * g, 2, exact(groups[g].arm.y()));  // cross_y(arm, f) = arm_z f_x - arm_x f_z
    lp.set_a(2 * g + 1, 2, -exact(groups[g].arm.x()));
  }
  lp.set_a(lambda, 0, exact(weight.x()));
  lp.set_a(lambda, 1, exact(weight.y()));
  lp.set_a(lambda, 2, exact(r_cm.y()) * exact(weight.x()) - exact(r_cm.x()) * exact(weight.y()));
  int row = 3;
  for (int g = 0; g < count; ++g)
    for (int k = 0; k < polygon_sides_; ++k, ++row) {
      lp.set_a(2 * g, row, exact(polygon_normals_[k].x()));
      lp.set_a(2 * g + 1, row, exact(polygon_normals_[k].y()));
      lp.set_r(row, CGAL::SMALLER);
      lp.set_b(row, exact(groups[g].friction_limit * polygon_inradius_));
    }
  lp.set_u(lambda, true, exact(cap));
  lp.set_c(lambda, exact(-1));
  const auto solution = CGAL::solve_linear_program(lp, ExactFT());
  // lambda = 0, every force 0, is feasible and lambda is capped: an optimum exists.
  if (!solution.is_optimal()) throw std::logic_error("hold_ratio: the exact LP found no optimum");
  return CGAL::to_double(-solution.objective_value());
}

}  // namespace stablepush
