// Exact arithmetic for the filtered decisions: CGAL's Gmpzf is an arbitrary-precision binary
// float whose ring operations are exact, so sums and products of the doubles the fast path
// used are represented without error (the filtered-predicate pattern of CGAL's own kernels).
#pragma once

#include <CGAL/Gmpzf.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <stdexcept>

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

}  // namespace stablepush
