"""gmsh's Delaunay kernel, completed at the hull and checked, against Qhull
(network.pores._delaunay)."""

import logging

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from network import Packing, tessellate, tie_groups
from network.pores._delaunay import _gmsh_tetrahedra, delaunay


def _rows(simp):
    return {tuple(r) for r in np.sort(simp, axis=1).tolist()}


def _adjacent(simp, neigh):
    """Set of (tetrahedron, its neighbour across face k, that face) as sorted vertex tuples."""
    out = set()
    for t, k in zip(*np.nonzero(neigh >= 0)):
        out.add((tuple(sorted(simp[t])), tuple(sorted(simp[neigh[t, k]])),
                 tuple(sorted(np.delete(simp[t], k)))))
    return out


@pytest.fixture(scope="module")
def bed():
    """6 000 centres, a jittered dense lattice in a flat-walled box (a bin's packing has flat
    walls, which is where gmsh drops hull tetrahedra)."""
    rng = np.random.default_rng(7)
    g = np.stack(np.meshgrid(*[np.arange(18.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    return (g + rng.uniform(-0.3, 0.3, g.shape))[:6000]


@pytest.mark.slow
def test_gmsh_gives_qhulls_tetrahedra_and_neighbours(bed):
    s_g, n_g, used = delaunay(bed, engine="gmsh")
    s_q, n_q, used_q = delaunay(bed, engine="qhull")
    assert (used, used_q) == ("gmsh", "qhull")
    assert _rows(s_g) == _rows(s_q)
    assert _adjacent(s_g, n_g) == _adjacent(s_q, n_q)
    assert np.sum(n_g < 0) == np.sum(n_q < 0)
    # face k is opposite vertex k: the neighbour across it shares the other three vertices
    t, k = np.nonzero(n_g >= 0)
    shared = np.array([np.isin(np.delete(s_g[a], b), s_g[n_g[a, b]]).all() for a, b in zip(t, k)])
    assert shared.all()


def test_the_hull_beside_gmsh_changes_nothing(bed, caplog):
    """threads=2 computes the check's convex hull on a second thread while gmsh runs: the same
    tetrahedra and neighbours, bit for bit, as one thread (and still gmsh's, checked)."""
    s1, n1, used1 = delaunay(bed, engine="gmsh", threads=1)
    s2, n2, used2 = delaunay(bed, engine="gmsh", threads=2)
    assert used1 == used2 == "gmsh"
    assert np.array_equal(s1, s2) and np.array_equal(n1, n2)


def test_the_hull_gap_is_filled(bed):
    """gmsh alone misses Delaunay tetrahedra at the hull: the completion puts them back and
    the volumes then sum to the convex hull's."""
    raw = _gmsh_tetrahedra(bed)
    simp, _, _ = delaunay(bed, engine="gmsh")
    pv = bed[simp]
    volume = np.abs(np.linalg.det(pv[:, 1:] - pv[:, :1])).sum() / 6
    assert raw.shape[0] < simp.shape[0]
    assert volume == pytest.approx(ConvexHull(bed).volume, rel=1e-12)


def test_tessellation_is_the_same_network(bed):
    pk = Packing(bed, np.full(bed.shape[0], 0.45))
    a, b = tessellate(pk, engine="gmsh"), tessellate(pk, engine="qhull")
    assert (a.n_pores, a.n_throats) == (b.n_pores, b.n_throats)
    assert a.pore_volume.sum() == pytest.approx(b.pore_volume.sum(), rel=1e-13)
    np.testing.assert_allclose(np.sort(a.throat_area), np.sort(b.throat_area), rtol=1e-12)
    # the two engines list a tetrahedron's vertices in other orders, so its centre is solved
    # from another base vertex: round-off, up to 3e-14 of the circumradius (measured against
    # long double on 20 000 centres), 1e-14 of a sliver's 1.5e5 offset here
    np.testing.assert_allclose(np.sort(a.pore_circumcenter, axis=0),
                               np.sort(b.pore_circumcenter, axis=0), rtol=1e-13, atol=1e-9)


def test_lattice_ties_give_the_same_pore_bodies():
    """Simple cubic: co-spherical groups; whichever engine triangulates them, tie_groups makes
    one body per cube."""
    g = np.stack(np.meshgrid(*[np.arange(6.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    for engine in ("gmsh", "qhull"):
        t = tessellate(Packing(g, np.full(g.shape[0], 0.5)), engine=engine)
        assert t.pore_volume.sum() == pytest.approx(125.0, rel=1e-12)
        assert tie_groups(t)[1] == 125


def test_duplicates_and_flat_input_go_to_qhull(caplog):
    rng = np.random.default_rng(3)
    p = rng.random((500, 3))
    p = np.vstack([p, p[:3]])
    with caplog.at_level(logging.INFO, logger="network.pores._delaunay"):
        simp, _, used = delaunay(p, engine="gmsh")
    assert used == "qhull" and "Qhull" in caplog.text
    assert _rows(simp) == _rows(delaunay(p, engine="qhull")[0])
    flat = np.column_stack([rng.random((50, 2)), np.zeros(50)])
    for engine in ("gmsh", "qhull"):
        with pytest.raises(ValueError, match="coplanar or degenerate"):
            delaunay(flat, engine=engine)
    with pytest.raises(ValueError, match="unknown Delaunay engine"):
        delaunay(p, engine="cgal")


@pytest.mark.slow
def test_tiled_copies_keep_gmsh_and_give_the_same_pore_bodies():
    """Translated copies (the bench's tiling above 1e5 spheres) make exactly co-spherical and
    coplanar groups at the seams and on the hull: gmsh's triangulation is completed and
    checked there too, and tie_groups gives Qhull's pore bodies."""
    rng = np.random.default_rng(11)
    c = rng.random((1200, 3))
    tiled = np.vstack([c + np.array([i, j, 0.0]) * 1.001 for i in range(2) for j in range(2)])
    simp, _, used = delaunay(tiled, engine="gmsh")
    assert used == "gmsh"
    pv = tiled[simp]
    volume = np.abs(np.linalg.det(pv[:, 1:] - pv[:, :1])).sum() / 6
    assert volume == pytest.approx(ConvexHull(tiled).volume, rel=1e-12)
    pk = Packing(tiled, np.full(tiled.shape[0], 0.02))
    a, b = tessellate(pk, engine="gmsh"), tessellate(pk, engine="qhull")
    assert tie_groups(a)[1] == tie_groups(b)[1]
