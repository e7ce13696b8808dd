// Exact arithmetic for the filtered decisions: CGAL's Gmpzf is an arbitrary-precision binary
// float whose ring operations are exact, so sums and products of the doubles the fast path
// used are represented without error (the filtered-predicate pattern of CGAL's own kernels).
#pragma once

#include <CGAL/Gmpzf.h>
#include <CGAL/Simple_cartesian.h>

namespace stablepush {

using ExactFT = CGAL::Gmpzf;
using ExactKernel = CGAL::Simple_cartesian<ExactFT>;
/// An exact planar wrench (f_x, f_z, tau_y).
using ExactWrench = ExactKernel::Vector_3;

}  // namespace stablepush
