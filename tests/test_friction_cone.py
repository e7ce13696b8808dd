"""Properties of the exact face-normal representation over random pointed cones."""
import numpy as np
import pytest
from scipy.optimize import linprog

from stablepush import _core


def random_pointed_generators(rng, m, dim):
    """Pointed cones of exactly the given dimension. Lower dimensions must be exact, so those
    generators are small-integer combinations of integer vectors (a float 'coplanar' set is,
    exactly, three-dimensional, and the core rightly says so)."""
    if dim == 3:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        basis = np.linalg.svd(np.vstack([axis, rng.normal(size=(2, 3))]))[2]
        gens = [(basis[0] * np.sign(basis[0] @ axis) + rng.normal(size=2) @ basis[1:] * 0.8) * rng.uniform(0.5, 2)
                for _ in range(m)]
        return np.array(gens)
    a = rng.integers(-5, 6, size=3).astype(float)
    while not a.any():
        a = rng.integers(-5, 6, size=3).astype(float)
    if dim == 1:
        return np.array([a * rng.integers(1, 4) for _ in range(m)])
    b = np.cross(a, rng.integers(-5, 6, size=3))
    while not b.any():
        b = np.cross(a, rng.integers(-5, 6, size=3))
    # Combinations 3a + k b with |k| <= 2 stay within a pointed wedge around a.
    return np.array([3 * a + rng.integers(-2, 3) * b for _ in range(m - 2)] + [3 * a + 2 * b, 3 * a - 2 * b])


def in_cone_lp(gens, w):
    """w = sum lambda g, lambda >= 0 (closed cone membership)."""
    res = linprog(np.zeros(len(gens)), A_eq=gens.T, b_eq=w, bounds=[(0, None)] * len(gens), method="highs")
    return res.status == 0


@pytest.mark.parametrize("dim", [3, 2, 1])
def test_h_representation_matches_generators(dim):
    rng = np.random.default_rng(dim)
    for _ in range(60):
        gens = random_pointed_generators(rng, int(rng.integers(dim, 8)), dim)
        cone = _core.WrenchCone([tuple(g) for g in gens], 0.05)
        assert cone.dimension == dim
        rows = np.array(cone.facet_rows)
        eqs = np.array(cone.equality_rows).reshape(-1, 3)
        assert len(eqs) == 3 - dim
        # Every generator is in the cone; every strictly positive combination is strictly inside.
        assert (gens @ rows.T <= 1e-12).all()
        assert (np.abs(gens @ eqs.T) <= 1e-12).all()
        inside = rng.uniform(0.1, 1.0, size=len(gens)) @ gens
        assert (rows @ inside < 0).all()
        # Random wrenches in the cone's span (signed combinations of generators) agree with an LP.
        for _ in range(20):
            w = rng.normal(size=3) if dim == 3 else rng.normal(size=len(gens)) @ gens
            h_inside = (rows @ w <= 1e-12).all()
            if np.min(np.abs(rows @ w)) > 1e-9:
                assert h_inside == in_cone_lp(gens, w)
