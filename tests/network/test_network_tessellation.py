"""tessellate: topology on hand-made cases, lattices with co-spherical points."""

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from network import Packing, tessellate


def _lattice(kind, n):
    """Exact lattice points of n x n x n unit cells (spacing 1)."""
    g = np.arange(n + 1.0)
    sc = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    if kind == "sc":
        return sc
    h = np.arange(n) + 0.5
    if kind == "bcc":
        return np.vstack([sc, np.stack(np.meshgrid(h, h, h, indexing="ij"), -1).reshape(-1, 3)])
    if kind == "fcc":
        pts = [sc]
        for a, b, c in ((g, h, h), (h, g, h), (h, h, g)):
            pts.append(np.stack(np.meshgrid(a, b, c, indexing="ij"), -1).reshape(-1, 3))
        return np.vstack(pts)
    raise ValueError(kind)


def test_one_tetrahedron_has_four_faces():
    c = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0], [5, 5, 5]])
    t = tessellate(Packing(c[:5], np.full(5, 0.1)))
    # unit corner tetrahedron + a far point seeing one face: 2 tetrahedra, 2*4 faces, 1 shared
    assert t.n_pores == 2 and t.n_throats == 7
    assert (t.throat_pores[:, 1] >= 0).sum() == 1
    np.testing.assert_allclose(np.sort(t.pore_volume)[0], 1 / 6)


def test_bipyramid_geometry():
    c = np.array([[0, 0, 0], [3, 0, 0], [0, 4, 0], [1, 1, 5.0], [1, 1, -5.0]])
    r = np.array([0.1, 0.2, 0.3, 0.4, 0.5])
    t = tessellate(Packing(c, r))
    assert t.n_pores == 2 and t.n_throats == 7
    (k,) = np.flatnonzero(t.throat_pores[:, 1] >= 0)
    np.testing.assert_array_equal(t.throat_vertices[k], [0, 1, 2])
    np.testing.assert_allclose(t.throat_radii[k], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(t.throat_sides[k], [3, 4, 5])          # l12, l13, l23
    np.testing.assert_allclose(t.throat_area[k], 6.0)                 # 3-4-5 right triangle
    np.testing.assert_allclose(t.throat_centroid[k], [1, 4 / 3, 0])
    np.testing.assert_allclose(t.pore_volume, [10, 10])              # base 6, height 5
    # every pore lists the shared throat once
    assert all(k in t.pore_throats[p] for p in range(2))


def test_faces_equal_sorted_unique_and_pore_maps():
    rng = np.random.default_rng(3)
    pk = Packing(rng.random((400, 3)), np.full(400, 0.01))
    t = tessellate(pk)
    faces = np.sort(t.pore_vertices[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    uniq, counts = np.unique(faces, axis=0, return_counts=True)
    assert len(uniq) == t.n_throats
    np.testing.assert_array_equal(np.unique(t.throat_vertices, axis=0), uniq)
    # hull faces are exactly the faces seen once
    assert (t.throat_pores[:, 1] < 0).sum() == (counts == 1).sum()
    # pore_throats points at a throat whose vertices are that face
    f = t.throat_vertices[t.pore_throats.ravel()]
    np.testing.assert_array_equal(f, faces)
    # throat_pores consistent with pore_throats
    for side in (0, 1):
        p = t.throat_pores[:, side]
        ok = p >= 0
        assert np.all((t.pore_throats[p[ok]] == np.flatnonzero(ok)[:, None]).any(axis=1))


@pytest.mark.parametrize("kind", ["sc", "bcc", "fcc"])
def test_lattices_tile_the_hull(kind):
    """Co-spherical lattices tessellate; whatever the tie-breaking, the tetrahedra tile the hull."""
    x = _lattice(kind, 4)
    t = tessellate(Packing(x, np.full(len(x), 0.3)))
    hull = ConvexHull(x).volume
    np.testing.assert_allclose(t.pore_volume.sum(), hull, rtol=1e-12)
    assert t.coplanar_points.size == 0
    # every interior face is shared by exactly two pores, hull faces lie on the cube's faces
    hull_c = t.throat_centroid[t.throat_pores[:, 1] < 0]
    on_face = np.isclose(hull_c, 0).any(axis=1) | np.isclose(hull_c, 4).any(axis=1)
    assert on_face.all()


def test_bcc_is_not_degenerate_but_sc_is():
    """BCC's Delaunay tessellation is unique (no ties); SC's is not (cubes of 8 co-spherical points)."""
    for kind, expect_ties in (("bcc", False), ("sc", True)):
        x = _lattice(kind, 3)
        t = tessellate(Packing(x, np.full(len(x), 0.3)))
        inside = np.all((t.throat_centroid > 0.9) & (t.throat_centroid < 2.1), axis=1)
        assert bool(t.throat_tied[inside].any()) is expect_ties, kind


def test_translation_invariance():
    rng = np.random.default_rng(5)
    c = rng.random((300, 3))
    r = 0.01 + 0.01 * rng.random(300)
    a = tessellate(Packing(c, r))
    b = tessellate(Packing(c + [10.0, -3.0, 7.0], r))
    key = lambda t: np.unique(t.throat_vertices, axis=0)  # noqa: E731
    np.testing.assert_array_equal(key(a), key(b))


def test_coplanar_input_raises():
    c = np.column_stack([np.random.default_rng(1).random((10, 2)), np.zeros(10)])
    with pytest.raises(ValueError, match="Delaunay tessellation failed"):
        tessellate(Packing(c, np.full(10, 0.01)))


def test_type_error():
    with pytest.raises(TypeError):
        tessellate(np.zeros((5, 3)))


@pytest.mark.slow
def test_site_coordinates_give_the_centred_answer():
    """A packing offset by 1e6 m (site coordinates) gives the permeability of the same packing
    near the origin (before the shift to the bounding-box centre, Qhull lost 2933 of the 3000
    bundled-scene spheres at this offset and the sample held no pore)."""
    from network import ConductanceOptions, SampleOptions, random_packing, solve_network

    pk = random_packing(600, rng=2, solid_fraction=0.57)
    far = Packing(pk.centers + 1e6, pk.radii)
    opts = dict(sample=SampleOptions(porosity_points=0),
                conductance=ConductanceOptions(policy="shape-factor"))
    a = solve_network(pk, **opts)
    b = solve_network(far, **opts)
    assert a.n_throats == b.n_throats
    assert abs(b.permeability_m2 / a.permeability_m2 - 1) < 1e-6


@pytest.mark.slow
def test_sample_outside_the_bed_is_refused_with_its_extent():
    from network import random_packing
    from network.pores import sample_region

    pk = random_packing(300, rng=1, solid_fraction=0.57)
    hi = (pk.centers + pk.radii[:, None]).max(axis=0)
    box = (0, 2 * hi[0], 0, hi[1], 0, hi[2])
    with pytest.raises(ValueError, match=r"reaches outside the packed bed, which spans x "):
        sample_region(pk, box=box)
    inside = sample_region(pk, box=(0.2 * hi[0], 0.8 * hi[0], 0.2 * hi[1], 0.8 * hi[1],
                                    0.2 * hi[2], 0.8 * hi[2]))
    assert inside.radius is None
