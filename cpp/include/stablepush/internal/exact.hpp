// Exact arithmetic for the filtered decisions: CGAL's Gmpzf is an arbitrary-precision binary
// float whose ring operations are exact, so sums and products of the doubles the fast path
// used are represented without error (the filtered-predicate pattern of CGAL's own kernels).
#pragma once

#ifndef STABLEPUSH_INTERNAL_ALLOWED
#error "an internal header of the stablepush core: include stablepush/friction_cone.hpp"
#endif

#include <CGAL/Gmpzf.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace stablepush {

using ExactFT = CGAL::Gmpzf;
using ExactKernel = CGAL::Simple_cartesian<ExactFT>;
/// An exact planar wrench (f_x, f_z, tau_y).
using ExactWrench = ExactKernel::Vector_3;

/// The exact value of a double the fast path used. Gmpzf(double) traps (SIGFPE) on a non-finite
/// value instead of throwing, so an overflow upstream is refused here, by name.
inline ExactFT exact(double x) {
  if (!std::isfinite(x)) throw std::domain_error("a non-finite value reached the exact re-check (an input too large?)");
  return ExactFT(x);
}

/// A WrenchCone's rows in exact arithmetic: its facet_rows()[i] is facets[i] times facet_scales()[i],
/// rounded, and its equality_rows()[j] is equalities[j] times equality_scales()[j], rounded.
struct ExactRows {
  std::vector<ExactWrench> facets, equalities;
};

/// Exact test of the facets alone (every facet row strictly negative on w): for a lower-dimensional
/// cone, whether w's projection onto the span is in the relative interior (its facet rows lie in the span).
inline bool strictly_inside_facets(const ExactRows& rows, const ExactWrench& w) {
  for (const ExactWrench& f : rows.facets)
    if (!CGAL::is_negative(f * w)) return false;
  return true;
}

}  // namespace stablepush
