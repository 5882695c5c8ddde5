"""The face graph and the paths on it, with known answers: one and two tetrahedra by hand, a
hand-made four-pore graph with a short narrow route and a long wide one (shortest, maximin and
greedy walks), paths unchanged by translating the packing, the network pressure along a path
in a linear field, and the branched model's table against its single evaluations."""

import numpy as np
import pytest

from network.paths import (
    FaceGraph,
    branched_path_pressure_drop,
    branched_table,
    build_paths,
    entry_faces,
    face_graph,
    maximin_paths,
    passable_pores,
    pore_quality,
    pressure_along_path,
    shortest_paths,
    trace_paths,
    walk_paths,
)
from network.packing import Packing, lattice_packing
from network.pores import tessellate

#: regular tetrahedron of unit edge centred on the origin
REGULAR = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float) / np.sqrt(8)


def test_one_tetrahedron_has_four_hull_faces():
    g = FaceGraph(points=REGULAR, radii=np.full(4, 0.2), pore_vertices=np.array([[0, 1, 2, 3]]),
                  pore_throats=np.array([[0, 1, 2, 3]]), throat_pores=np.array([[0, -1]] * 4),
                  throat_centroid=np.array([REGULAR[[j for j in range(4) if j != k]].mean(0)
                                            for k in range(4)]),
                  throat_area=np.full(4, np.sqrt(3) / 4), throat_open_area=np.full(4, 0.1),
                  throat_normal=-REGULAR / np.linalg.norm(REGULAR, axis=1, keepdims=True))
    assert (g.n_pores, g.n_throats) == (1, 4)
    assert g.hull_mask().all()
    assert g.pore_quality[0] == pytest.approx(1.0, abs=1e-12)  # regular: 6 sqrt2 V / e^3 = 1
    assert g.mean_diameter == pytest.approx(0.4)
    with pytest.raises(ValueError, match="throat_area must have shape"):
        FaceGraph(**{**g.__dict__, "throat_area": np.zeros(3)})


def test_two_tetrahedra_of_a_bipyramid():
    # an equilateral triangle (side a, z = 0) with apexes at +-h: Delaunay gives two
    # tetrahedra sharing the triangle, 4 + 4 - 1 = 7 faces, one interior
    a, h, r = 1e-2, 1.2e-2, 0.3e-2
    ang = np.array([0, 2, 4]) * np.pi / 3
    tri = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(3)]) * a / np.sqrt(3)
    x = np.vstack([tri, [[0, 0, h], [0, 0, -h]]])
    g = face_graph(tessellate(Packing(x, np.full(5, r))))
    assert (g.n_pores, g.n_throats) == (2, 7)
    inner = np.flatnonzero(~g.hull_mask())
    assert inner.size == 1
    f = inner[0]
    # Eq. 3.18 and Eq. 3.23 (three 60-degree sectors, no overlap since 2r < a)
    assert g.throat_area[f] == pytest.approx(np.sqrt(3) / 4 * a**2, rel=1e-12)
    assert g.throat_open_area[f] == pytest.approx(np.sqrt(3) / 4 * a**2 - np.pi * r**2 / 2,
                                                  rel=1e-9)
    np.testing.assert_allclose(g.throat_centroid[f], 0.0, atol=1e-15)
    # the interior normal points from the owner to the other tetrahedron; hull normals outward
    owner, other = g.throat_pores[f]
    pc = g.points[g.pore_vertices].mean(axis=1)
    assert np.dot(g.throat_normal[f], pc[other] - pc[owner]) > 0
    hull = np.flatnonzero(g.hull_mask())
    own = pc[g.throat_pores[hull, 0]]
    assert np.all(np.einsum("ij,ij->i", g.throat_normal[hull], g.throat_centroid[hull] - own) > 0)
    np.testing.assert_allclose(np.linalg.norm(g.throat_normal, axis=1), 1.0, rtol=1e-14)
    # quality 6 sqrt2 V / e^3 with V = (sqrt3/4 a^2) h / 3, e = mean of a and sqrt(a^2/3 + h^2)
    e = 0.5 * (a + np.sqrt(a**2 / 3 + h**2))
    q = 6 * np.sqrt(2) * (np.sqrt(3) / 4 * a**2 * h / 3) / e**3
    np.testing.assert_allclose(g.pore_quality, q, rtol=1e-12)
    np.testing.assert_allclose(pore_quality(x, g.pore_vertices), q, rtol=1e-12)


def _diamond(open_02=5.0):
    """Four pores: P0 at the floor, P1 (short route, faces of open area 1) and P2 (long
    route, faces 5 and 4) in the middle, P3 at the top. Each pore is its own regular
    tetrahedron; faces: 0 inlet (hull, under P0), 1 = P0|P1, 2 = P0|P2, 3 = P1|P3, 4 = P2|P3,
    5 outlet (hull, over P3), 6-11 side hull faces."""
    centre = np.array([[0, 0, 0], [-0.5, 0, 2], [3, 0, 2], [0, 0, 4]], float)
    pts = (centre[:, None] + REGULAR[None]).reshape(-1, 3)
    pv = np.arange(16).reshape(4, 4)
    pt = np.array([[0, 1, 2, 6], [1, 3, 7, 8], [2, 4, 9, 10], [3, 4, 5, 11]])
    tp = np.array([[0, -1], [0, 1], [0, 2], [1, 3], [2, 3], [3, -1],
                   [0, -1], [1, -1], [1, -1], [2, -1], [2, -1], [3, -1]])
    cen = np.array([[0, 0, -0.5], [-0.25, 0, 1], [1.5, 0, 1], [-0.25, 0, 3], [1.5, 0, 3],
                    [0, 0, 4.5], [0.5, 0.5, 0], [-0.5, 0.5, 2], [-0.5, -0.5, 2], [3, 0.5, 2],
                    [3, -0.5, 2], [0.5, 0.5, 4]], float)
    area = np.array([2, 1, open_02, 1, 4, 2, 3, 3, 3, 3, 3, 3], float)
    return FaceGraph(points=pts, radii=np.full(16, 0.3), pore_vertices=pv, pore_throats=pt,
                     throat_pores=tp, throat_centroid=cen, throat_area=area + 1.0,
                     throat_open_area=area, throat_normal=np.tile([0.0, 0.0, 1.0], (12, 1)))


def test_hand_made_graph_shortest_widest_and_walks():
    g = _diamond()
    assert passable_pores(g).all()
    f0, p0 = entry_faces(g, [[0.0, 0.0]])
    assert (f0[0], p0[0]) == (0, 0)
    # shortest chain of face centroids: via P1 1.52 + 2 + 1.52 = 5.04, via P2 6.24
    (faces,), ok = shortest_paths(g, f0, p0)
    assert ok[0]
    np.testing.assert_array_equal(faces, [0, 1, 3, 5])
    # maximin: the bottleneck of the P2 route is 4 (faces 2 and 4 open 5 and 4), of P1 1;
    # hull faces (inlet, outlet) do not count
    for tiebreak in ("tree", "shortest"):
        (faces,), ok, bott = maximin_paths(g, f0, p0, tiebreak=tiebreak)
        np.testing.assert_array_equal(faces, [0, 2, 4, 5])
        assert bott[0] == 4.0
    # greedy walks: widest leaves P0 by face 2 (5 > 1), narrowest by face 1
    (wide, narrow), status, relaxed, back = walk_paths(g, [0, 0], [0, 0], kind="widest")
    assert list(status) == ["ok", "ok"] and not relaxed.any() and not back.any()
    np.testing.assert_array_equal(wide, [0, 2, 4, 5])
    (narrow,), _, _, _ = walk_paths(g, [0], [0], kind="narrowest")
    np.testing.assert_array_equal(narrow, [0, 1, 3, 5])
    # close face 2: every route goes through P1, bottleneck 1
    closed = _diamond(open_02=0.0)
    (faces,), ok, bott = maximin_paths(closed, f0, p0)
    np.testing.assert_array_equal(faces, [0, 1, 3, 5])
    assert bott[0] == 1.0
    (wide,), _, _, _ = walk_paths(closed, [0], [0], kind="widest")
    np.testing.assert_array_equal(wide, [0, 1, 3, 5])


@pytest.fixture(scope="module")
def lattice():
    c, r = lattice_packing("sc", 0.45, n_cells=(3, 3, 6), lattice_constant_m=6.5e-3,
                           jitter=0.05, rng=7)
    return np.asarray(c), np.asarray(r)


def test_paths_do_not_move_with_the_packing(lattice):
    # translating packing and entry points by the same vector changes no choice: the same
    # tetrahedra and face centroids, and lengths, widths and tortuosities to rounding
    c, r = lattice
    shift = np.array([0.125, -0.25, 0.5])
    xy = np.array([[7.0e-3, 7.0e-3], [12e-3, 9e-3]])
    g0 = face_graph(tessellate(Packing(c, r)))
    g1 = face_graph(tessellate(Packing(c + shift, r)))
    for kind, method in [("widest", "build"), ("narrowest", "build"), ("widest", "delaunay"),
                         ("maximin", "build"), ("shortest", "build")]:
        a = trace_paths(c, r, xy, kind=kind, method=method, graph=g0)
        b = trace_paths(c + shift, r, xy + shift[:2], kind=kind, method=method, graph=g1)
        for pa, pb in zip(a, b):
            assert pa.status == pb.status == "ok"
            # the same tetrahedra (the order within an inlet face may follow rounding)
            ta, tb = pa.tetra_vertices, pb.tetra_vertices
            np.testing.assert_array_equal(np.sort(ta[:, :3]), np.sort(tb[:, :3]), err_msg=kind)
            np.testing.assert_array_equal(ta[:, 3], tb[:, 3], err_msg=kind)
            np.testing.assert_allclose(pb.points, pa.points + shift, rtol=0, atol=1e-15)
            assert pb.length_m == pytest.approx(pa.length_m, rel=1e-12)
            assert pb.tortuosity == pytest.approx(pa.tortuosity, rel=1e-12)
            np.testing.assert_allclose(pb.widths_m, pa.widths_m, rtol=1e-9)


@pytest.mark.parametrize("kind", ["shortest", "maximin"])
def test_pressure_along_a_path_in_a_linear_field(lattice, kind):
    # p = p0 - G z at the tetrahedron centroids: the profile along any path on the
    # tessellation is p0 - G z of its tetrahedra, and the drop between its ends G dz
    c, r = lattice
    tess = tessellate(Packing(c, r))
    g = face_graph(tess)
    (p,) = trace_paths(c, r, [[7e-3, 7e-3]], kind=kind, graph=g)
    pc = c[tess.pore_vertices].mean(axis=1)
    grad = 250.0
    z, pr = pressure_along_path(g, p, 3.0 - grad * pc[:, 2])
    np.testing.assert_allclose(z, pc[p.pores, 2], rtol=1e-15)
    assert pr[0] - pr[-1] == pytest.approx(grad * (z[-1] - z[0]), rel=1e-12)
    with pytest.raises(ValueError, match="shape"):
        pressure_along_path(g, p, np.zeros(3))


def test_branched_table_equals_single_evaluations(lattice):
    # Table 4.4 layout: every (width, multiplier, velocity) entry is one
    # branched_path_pressure_drop, and a velocity U is a flow Q0 = U S0
    c, r = lattice
    (p,) = build_paths(c, r, [[7e-3, 7e-3]])
    tab = branched_table(c, r, p, velocities_m_s=(0.013, 0.027), branches="all")
    for w in ("max", "min", "average"):
        for m in ("MFx3", "MFx2"):
            for u in (0.013, 0.027):
                one = branched_path_pressure_drop(c, r, p, superficial_velocity_m_s=u,
                                                  width=w, multiplier=m, branches="all")
                assert tab[w][m][f"{u:g}"] == pytest.approx(one.total_pa, rel=1e-14)
    q = branched_path_pressure_drop(c, r, p, q0_m3_s=0.013 * tab["q0_per_u_m2"],
                                    branches="all")
    assert q.total_pa == pytest.approx(tab["average"]["MFx3"]["0.013"], rel=1e-14)
    # series sum: the path's drop is the sum over its tetrahedra of straight + daughters
    np.testing.assert_allclose(q.dp_tetra_pa, q.dp_straight_pa + q.dp_branch_pa.sum(axis=1))
    assert q.total_pa == pytest.approx(q.dp_tetra_pa.sum(), rel=1e-14)
    with pytest.raises(ValueError, match="superficial_velocity_m_s or q0_m3_s"):
        branched_path_pressure_drop(c, r, p)
