"""Tests for network._merge: co-spherical tetrahedra become one pore body.

Closed forms: the circumsphere of the unit right-corner tetrahedron (centre (1/2,1/2,1/2),
R^2 = 3/4); a simple-cubic cell's 8 corners are co-spherical (one body, centre = cell centre);
FCC octahedral holes (6 co-spherical centres) and tetrahedral holes (4).
"""

import itertools

import numpy as np
import pytest

from network import Packing, tessellate
from network.packing import lattice_packing
from network.pores import circumspheres, merge_pores


def test_circumsphere_closed_form():
    p = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]], float)
    c, r = circumspheres(p)
    np.testing.assert_allclose(c, [[0.5, 0.5, 0.5]], atol=1e-14)
    assert r[0] ** 2 == pytest.approx(0.75, rel=1e-14)
    c, r = circumspheres(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]], float))
    assert np.isnan(r[0])                                   # flat: no circumsphere


def test_circumsphere_equidistant_and_order_free():
    """The closed form's centre is equidistant from the four vertices to round-off, the same
    from any base vertex, and matches LAPACK's solve of 2 e_i . c' = |e_i|^2."""
    rng = np.random.default_rng(7)
    p = rng.normal(size=(2000, 4, 3))
    c, r = circumspheres(p)
    d = np.linalg.norm(p - c[:, None], axis=2)
    np.testing.assert_allclose(d, np.repeat(r[:, None], 4, axis=1), rtol=1e-11)
    c2, _ = circumspheres(p[:, [2, 0, 3, 1]])
    np.testing.assert_allclose(c2, c, rtol=1e-11, atol=1e-11 * r.max())
    e = p[:, 1:] - p[:, :1]
    lu = np.linalg.solve(e, 0.5 * np.einsum("nij,nij->ni", e, e)[..., None])[..., 0] + p[:, 0]
    np.testing.assert_allclose(c, lu, rtol=1e-11, atol=1e-11 * r.max())


def test_cube_is_one_body_centred():
    c = np.array(list(itertools.product([0.0, 1.0], repeat=3))) * 2e-3
    t = tessellate(Packing(c, np.full(8, 0.8e-3)))
    m = merge_pores(t)
    assert m.n_groups == 1 and m.group_size[0] == t.n_pores
    np.testing.assert_allclose(m.center[0], [1e-3, 1e-3, 1e-3], rtol=1e-12)
    inner = t.throat_pores[:, 1] >= 0
    assert np.all(m.internal_throat == inner)


@pytest.mark.parametrize("kind, size, n_expected", [("sc", 5, 27), ("fcc", 4, 27)])
def test_lattice_holes_merge_exact_and_jittered(kind, size, n_expected):
    # 3x3x3 interior cells (cubes for SC; octahedral holes at cell centres for FCC)
    for jitter in (0.0, 1e-3):
        c, r = lattice_packing(kind, 0.4, n_cells=4, lattice_constant_m=1.0, jitter=jitter,
                               rng=3)
        m = merge_pores(tessellate(Packing(c, r)))
        cen = m.center[m.group_size >= size]
        inner = np.all((cen > 1.0) & (cen < 3.0), axis=1) if kind == "fcc" else \
            np.all((cen > 0.4) & (cen < 2.6), axis=1)
        # every interior hole is one body (cube: >= 5 tetrahedra, octahedron: 4)
        holes = cen[inner]
        if kind == "sc":
            # all 27 cells of the box are one body each (jittered: all but the hull's few)
            assert holes.shape[0] == n_expected if jitter == 0 else holes.shape[0] >= 24
            frac = holes - np.floor(holes)
            np.testing.assert_allclose(frac, 0.5, atol=0.02)
        else:
            # octahedral holes at (i+1/2, j, k)-type and cell-centre positions
            assert holes.shape[0] >= 8


def test_random_points_merge_little_and_in_small_groups():
    # Poisson points (no ties, many slivers on the hull): 20 % of tetrahedra join (near-
    # co-spherical pairs and slivers), in groups of at most 6 (no chains)
    rng = np.random.default_rng(0)
    c = rng.uniform(0, 1, (400, 3))
    t = tessellate(Packing(c, np.full(400, 0.01)))
    m = merge_pores(t)
    assert m.n_merged < 0.25 * t.n_pores
    assert m.group_size.max() <= 6
    # with tolerance 0 only slivers join (one neighbour each)
    m0 = merge_pores(t, tolerance=0.0)
    assert m0.group_size.max() <= 6 and m0.n_merged < m.n_merged


def test_bad_tolerance():
    c = np.array(list(itertools.product([0.0, 1.0], repeat=3)))
    with pytest.raises(ValueError, match="tolerance"):
        merge_pores(tessellate(Packing(c, np.full(8, 0.4))), tolerance=-1)
