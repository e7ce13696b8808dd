"""Properties of the exact face-normal representation over random pointed cones."""
import numpy as np
import pytest
from scipy.optimize import linprog

from stablepush import _core


def random_pointed_generators(rng, m, dim):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    gens = []
    basis = np.linalg.svd(np.vstack([axis, rng.normal(size=(2, 3))]))[2]
    for _ in range(m):
        offset = rng.normal(size=2) * 0.8
        if dim == 2:
            offset[1] = 0.0
        if dim == 1:
            offset[:] = 0.0
        g = basis[0] * np.sign(basis[0] @ axis) + offset[0] * basis[1] + offset[1] * basis[2]
        gens.append(g * rng.uniform(0.5, 2.0))
    return np.array(gens)


def in_cone_lp(gens, w):
    """w = sum lambda g, lambda >= 0 (closed cone membership)."""
    res = linprog(np.zeros(len(gens)), A_eq=gens.T, b_eq=w, bounds=[(0, None)] * len(gens), method="highs")
    return res.status == 0


@pytest.mark.parametrize("dim", [3, 2, 1])
def test_h_representation_matches_generators(dim):
    rng = np.random.default_rng(dim)
    for _ in range(60):
        gens = random_pointed_generators(rng, int(rng.integers(2, 8)), dim)
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
        # Random wrenches (projected onto the span for lower dimensions) agree with an LP.
        for _ in range(20):
            w = rng.normal(size=3)
            for e in eqs:
                w -= (w @ e) / (e @ e) * e
            h_inside = (rows @ w <= 1e-12).all()
            if np.min(np.abs(rows @ w)) > 1e-9:
                assert h_inside == in_cone_lp(gens, w)
