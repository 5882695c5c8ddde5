"""Airflow paths (thesis 3.4, Eqs. 3.24-3.27; Appendices D-E): analytic and lattice checks."""

import dataclasses
import json

import numpy as np
import pytest

from network import Packing, tessellate
from network.paths import (
    EXIT_FACES,
    BuildRules,
    bed_depth,
    branched_path_pressure_drop,
    build_paths,
    entry_faces,
    eq323_area,
    face_graph,
    interior_angles,
    maximin_paths,
    path_length,
    pore_pressure_array,
    pore_quality,
    pressure_along_path,
    shortest_paths,
    smoothed_length,
    smoothing_factor,
    trace_paths,
    turning_angles,
    walk_paths,
)
from network.packing import lattice_packing, random_packing
from network.paths.__main__ import main


# ------------------------------------------------------------------ Eqs. 3.25-3.27
def test_smoothing_factor_limits():
    # Eq. 3.26 with omega_a = 0.1, omega_b = 90 deg: 1 at 180 deg, 1/2 at 90, -> 0 at 0
    w = np.array([0.0, 45.0, 90.0, 135.0, 180.0])
    f = smoothing_factor(w)
    assert f[-1] == pytest.approx(1.0, abs=1.3e-4)  # 1 - e^-9 / (1 + e^-9)
    assert f[0] == pytest.approx(0.0, abs=1.3e-4)
    assert f[2] == 0.5
    assert np.all(np.diff(f) > 0)
    assert smoothing_factor(180.0, omega_a=1.0) == pytest.approx(1.0, abs=1e-30)


@pytest.mark.parametrize("theta_deg", [10.0, 30.0, 50.0])
def test_zigzag_tortuosity_and_smoothing(theta_deg):
    # a zigzag of n segments of length s at +-theta from the axis: every turn is 2 theta,
    # raw tortuosity 1/cos(theta) and Eq. 3.27 gives s + (n - 1) s f(180 - 2 theta)
    n, s = 40, 2e-3
    th = np.radians(theta_deg)
    steps = np.stack([s * np.sin(th) * (-1.0) ** np.arange(n), np.zeros(n),
                      np.full(n, s * np.cos(th))], axis=1)
    pts = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(turning_angles(pts), 2 * theta_deg, atol=1e-9)
    np.testing.assert_allclose(interior_angles(pts), 180 - 2 * theta_deg, atol=1e-9)
    depth = n * s * np.cos(th)
    assert path_length(pts) / depth == pytest.approx(1 / np.cos(th), rel=1e-12)
    want = s + (n - 1) * s * smoothing_factor(180 - 2 * theta_deg)
    assert smoothed_length(pts) == pytest.approx(want, rel=1e-12)


def test_straight_path_keeps_its_length():
    pts = np.column_stack([np.zeros(11), np.zeros(11), np.linspace(0, 0.25, 11)])
    assert smoothed_length(pts) == pytest.approx(0.25, rel=2e-4)  # factor 1 - 1.2e-4 at 180
    assert path_length(pts) == pytest.approx(0.25, rel=1e-12)


def test_appendix_d_angle_rule():
    # Appendix D omits the arccos: omega = (180/3.14) cos(omega), + 180 when negative
    pts = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0]], float)
    np.testing.assert_allclose(interior_angles(pts, rule="appendix-d"),
                               [180 - 180 / 3.14, 0.0], atol=1e-9)
    with pytest.raises(ValueError, match="angle rule"):
        interior_angles(pts, rule="acos")


# ------------------------------------------------------------------ lattice checks
@pytest.fixture(scope="module")
def lattice():
    c, r = lattice_packing("sc", 0.45, n_cells=(4, 4, 10), lattice_constant_m=6.5e-3,
                           jitter=0.05, rng=3)
    tess = tessellate(Packing(c, r))
    return c, r, tess, face_graph(tess)


def test_pore_quality_of_regular_and_flat():
    reg = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    flat = reg * [1, 1, 0]
    q = pore_quality(np.vstack([reg, flat]), [[0, 1, 2, 3], [4, 5, 6, 7]])
    np.testing.assert_allclose(q, [1.0, 0.0], atol=1e-12)


def test_maximin_follows_the_only_wide_channel(lattice):
    # make one chain of faces (the shortest path) 10x wider than every other face: the
    # maximin path must be that chain, and its tortuosity that of the chain
    c, r, tess, g = lattice
    xy = np.array([[9.75e-3, 9.75e-3]])
    f0, p0 = entry_faces(g, xy)
    (chain,), ok = shortest_paths(g, f0, p0)
    assert ok[0] and chain.size > 10
    area = np.where(g.throat_open_area > 0, 1e-6, 0.0)
    area[chain] = 1e-5
    g2 = dataclasses.replace(g, throat_open_area=area)
    for tiebreak in ("tree", "shortest"):
        (faces,), ok, bott = maximin_paths(g2, f0, p0, tiebreak=tiebreak)
        assert ok[0]
        np.testing.assert_array_equal(faces, chain)
        assert bott[0] == pytest.approx(1e-5)
    (p,) = trace_paths(c, r, xy, kind="maximin", graph=g2)
    depth = bed_depth(c, r)
    assert p.tortuosity_raw == pytest.approx(path_length(g.throat_centroid[chain]) / depth)
    np.testing.assert_allclose(p.widths_m, 2 * np.sqrt(1e-5 / np.pi))


@pytest.mark.parametrize("kind", ["widest", "narrowest"])
def test_built_paths_obey_the_step_rule(lattice, kind):
    # every exit is higher than its base, and (where no exit was reselected) is the
    # widest/narrowest face allowed: upward, open by Eq. 3.23, which also gives the width
    c, r, _, _ = lattice
    xy = np.array([[9.75e-3, 9.75e-3], [13e-3, 6.5e-3]])
    paths = build_paths(c, r, xy, kind=kind)
    for p in paths:
        assert p.status == "ok"
        assert p.n_tetrahedra >= 10
        h = p.points[:, 2]
        assert np.all(np.diff(h) > 0)
        assert h[-1] >= c[:, 2].max() - r.mean()
        tri = p.tetra_vertices[:, EXIT_FACES]  # (n, 3, 3)
        op = eq323_area(c, r, tri)
        base_h = c[p.tetra_vertices[:, :3]].mean(axis=1)[:, 2]
        allowed = (op > 0) & (c[tri].mean(axis=2)[:, :, 2] > base_h[:, None])
        chosen = op[np.arange(p.n_tetrahedra), p.exit_local]
        best = np.where(allowed, op, -np.inf if kind == "widest" else np.inf)
        best = best.max(axis=1) if kind == "widest" else best.min(axis=1)
        if p.n_backtracks == 0:
            np.testing.assert_allclose(chosen, best)
        np.testing.assert_allclose(p.widths_m, 2 * np.sqrt(chosen / np.pi))


# A hand-made packing, mm, all radii 1: floor triangle A B C (legs 4.5 and 3), D above its
# centroid, E beyond face BCD (away from A), F beyond face ACD (away from B), D E F at the
# top height 2.7. With equal radii the three sectors of Eq. 3.23 sum to pi r^2 / 2 on any
# triangle, so S_f = (triangle area) - pi / 2 mm^2 and the exits rank as the triangles do.
_HAND_A, _HAND_B, _HAND_C, _HAND_D = (0, 0, 0), (4.5, 0, 0), (0, 3, 0), (1.5, 1, 2.7)
_BC_OUT = np.array([3.0, 4.5]) / np.hypot(3.0, 4.5)  # unit normal of BC in the floor, away from A
_HAND_E = (2.0 + 1.5 * _BC_OUT[0], 4 / 3 + 1.5 * _BC_OUT[1], 2.7)
_HAND_F = (-1.0, 4 / 3, 2.7)


def _tri_area_mm2(*p):
    p = np.array(p, dtype=float)
    return 0.5 * np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))


def _width_mm(*p):  # Eq. 3.24 with S_f = triangle - pi / 2 (unit radii)
    return 2.0 * np.sqrt((_tri_area_mm2(*p) - np.pi / 2) / np.pi)


@pytest.mark.parametrize("rules", [BuildRules(), BuildRules(overlap="ball"),
                                   BuildRules(overlap="none"), BuildRules(closed="second"),
                                   BuildRules(area="exact"), BuildRules(insphere=False)])
def test_hand_made_widest_and_narrowest_paths(rules):
    A, B, C, D, E, F = range(6)
    c = np.array([_HAND_A, _HAND_B, _HAND_C, _HAND_D, _HAND_E, _HAND_F]) * 1e-3
    r = np.full(6, 1e-3)
    # the AEP (1.5, 1) on the floor z = -1: A, C, B are nearest (2.06, 2.69, 3.32 mm), D is
    # 3.70 mm away; D is the nearest sphere above the floor triangle's centroid. Step 1's
    # exits ABD, ACD, BCD have triangles 6.48, 4.63, 7.64 mm^2: widest BCD, narrowest ACD.
    assert [_tri_area_mm2(*q) for q in ((_HAND_A, _HAND_B, _HAND_D), (_HAND_A, _HAND_C, _HAND_D),
                                        (_HAND_B, _HAND_C, _HAND_D))] == \
        pytest.approx([6.4783, 4.6330, 7.6401], abs=1e-4)
    # step 2: E (F) is nearest above BCD's (ACD's) centroid, on the far side from A (B); the
    # exits keeping D and E (F) lie above the base centroid (z 1.8 > 0.9), the one keeping
    # the two floor spheres does not (z 0.9). Widest: BDE (triangle 4.13 mm^2) over CDE (3.76);
    # narrowest: ADF (3.72) under CDF (4.08). Their centroids (z 1.8) reach the top band
    # (highest centre 2.7 less the mean radius 1), so each path has two tetrahedra.
    wide, = build_paths(c, r, [[1.5e-3, 1e-3]], kind="widest", rules=rules)
    narrow, = build_paths(c, r, [[1.5e-3, 1e-3]], kind="narrowest", rules=rules)
    assert wide.status == narrow.status == "ok"
    assert [set(t) for t in wide.tetra_vertices] == [{A, B, C, D}, {B, C, D, E}]
    assert [set(t) for t in narrow.tetra_vertices] == [{A, B, C, D}, {A, C, D, F}]
    exits = [set(t[EXIT_FACES[j]]) for t, j in zip(wide.tetra_vertices, wide.exit_local)]
    assert exits == [{B, C, D}, {B, D, E}]
    exits = [set(t[EXIT_FACES[j]]) for t, j in zip(narrow.tetra_vertices, narrow.exit_local)]
    assert exits == [{A, C, D}, {A, D, F}]
    P = {k: np.array(v, dtype=float) for k, v in zip("ABCDEF", (_HAND_A, _HAND_B, _HAND_C,
                                                                 _HAND_D, _HAND_E, _HAND_F))}
    np.testing.assert_allclose(wide.widths_m * 1e3, [_width_mm(P["B"], P["C"], P["D"]),
                                                     _width_mm(P["B"], P["D"], P["E"])],
                               rtol=1e-12)
    np.testing.assert_allclose(wide.widths_m * 1e3, [2.7799, 1.8036], atol=1e-4)
    np.testing.assert_allclose(narrow.widths_m * 1e3, [1.9746, 1.6545], atol=1e-4)
    g = [(P["A"] + P["B"] + P["C"]) / 3, (P["B"] + P["C"] + P["D"]) / 3,
         (P["B"] + P["D"] + P["E"]) / 3]
    np.testing.assert_allclose(wide.points * 1e3, g, atol=1e-12)
    length = np.linalg.norm(g[1] - g[0]) + np.linalg.norm(g[2] - g[1])
    assert wide.length_m * 1e3 == pytest.approx(length, rel=1e-12)
    assert wide.depth_m * 1e3 == pytest.approx(2.7 + 2.0, rel=1e-12)  # centre span + diameter


def test_rule_one_reselects_the_exit():
    # G at (3, -0.25, 2) mm, outside ABCD beyond its edge AB, is the sphere nearest above
    # BCD's centroid but lies on A's side of the plane BCD: the tetrahedron BCDG would
    # overlap ABCD (Fig. 3.7). 'exit' takes ABCD's next-best exit ABD (triangle 6.48 mm^2)
    # and builds ABDG on it; 'ball' keeps BCD and passes over G to E; 'none' builds BCDG.
    A, B, C, D, E, F, G = range(7)
    c = np.array([_HAND_A, _HAND_B, _HAND_C, _HAND_D, _HAND_E, _HAND_F, (3.0, -0.25, 2.0)])
    c, r = c * 1e-3, np.full(7, 1e-3)
    side = np.cross(c[C] - c[B], c[D] - c[B])
    assert np.dot(c[G] - c[B], side) * np.dot(c[A] - c[B], side) > 0  # G on A's side
    got = {}
    for overlap in ("exit", "ball", "none"):
        p, = build_paths(c, r, [[1.5e-3, 1e-3]], kind="widest",
                         rules=BuildRules(overlap=overlap))
        got[overlap] = (set(p.tetra_vertices[0][EXIT_FACES[p.exit_local[0]]]),
                        set(p.tetra_vertices[1]))
    assert got == {"exit": ({A, B, D}, {A, B, D, G}), "ball": ({B, C, D}, {B, C, D, E}),
                   "none": ({B, C, D}, {B, C, D, G})}


def test_the_entry_point_lies_on_the_floor():
    # from (1.5, 1) on the floor z = -1 mm the nearest spheres are A, C, B (2.06, 2.69,
    # 3.32 mm; D 3.70); from the lowest centre height z = 0 they are A, C, D (1.80, 2.50,
    # 2.70 mm; B 3.16), so the path starts from the triangle ACD
    c = np.array([_HAND_A, _HAND_B, _HAND_C, _HAND_D, _HAND_E, _HAND_F]) * 1e-3
    r = np.full(6, 1e-3)
    floor, = build_paths(c, r, [[1.5e-3, 1e-3]])
    centre, = build_paths(c, r, [[1.5e-3, 1e-3]], rules=BuildRules(start="lowest-centre"))
    assert set(floor.tetra_vertices[0, :3]) == {0, 1, 2}
    assert set(centre.tetra_vertices[0, :3]) == {0, 2, 3}


def test_build_rules_are_checked():
    with pytest.raises(ValueError, match="BuildRules.exits"):
        BuildRules(exits="down")
    with pytest.raises(TypeError, match="BuildRules"):
        build_paths(np.zeros((4, 3)), np.ones(4), [[0.0, 0.0]], rules={"exits": "all"})


def test_walked_paths_and_network_pressure(lattice):
    c, r, tess, g = lattice
    xy = np.array([[9.75e-3, 9.75e-3]])
    f0, p0 = entry_faces(g, xy)
    (faces,), status, _, _ = walk_paths(g, f0, p0, kind="widest")
    assert status[0] == "ok"
    (p,) = trace_paths(c, r, xy, kind="widest", method="delaunay", graph=g)
    # pressure along the path: a linear field p = 10 - 100 z gives back the same profile
    pc = c[tess.pore_vertices].mean(axis=1)
    z, pr = pressure_along_path(g, p, 10.0 - 100.0 * pc[:, 2])
    np.testing.assert_allclose(pr, 10.0 - 100.0 * z)
    with pytest.raises(ValueError, match="not on the tessellation"):
        (b,) = build_paths(c, r, xy)
        pressure_along_path(g, b, np.zeros(g.n_pores))


def test_branched_model_on_a_path_is_linear_in_velocity(lattice):
    c, r, _, _ = lattice
    (p,) = build_paths(c, r, np.array([[9.75e-3, 9.75e-3]]))
    lo = branched_path_pressure_drop(c, r, p, superficial_velocity_m_s=0.013)
    hi = branched_path_pressure_drop(c, r, p, superficial_velocity_m_s=0.027)
    assert hi.total_pa == pytest.approx(lo.total_pa * 0.027 / 0.013, rel=1e-12)
    wide = branched_path_pressure_drop(c, r, p, superficial_velocity_m_s=0.013, width="max")
    narrow = branched_path_pressure_drop(c, r, p, superficial_velocity_m_s=0.013, width="min")
    assert wide.total_pa < lo.total_pa < narrow.total_pa


# ------------------------------------------------------------------ CLI
@pytest.mark.slow
def test_cli_json_and_plot(tmp_path):
    pk = random_packing(386, solid_fraction=0.592, aspect=(0.04, 0.04, 0.06), rng=5,
                        max_sweeps=300)
    x, r = pk.centers, pk.radii
    csv = tmp_path / "p.csv"
    np.savetxt(csv, np.column_stack([x, r]), delimiter=",", header="x,y,z,r", comments="")
    out, png = tmp_path / "o.json", tmp_path / "o.png"
    rc = main([str(csv), "--entries", "2", "--seed", "1", "--json", str(out), "--plot", str(png)])
    assert rc == 0
    res = json.loads(out.read_text())
    kinds = [p["kind"] for p in res["paths"]]
    assert sorted(set(kinds)) == ["maximin", "narrowest", "shortest", "widest"]
    assert all(p["status"] == "ok" for p in res["paths"])
    assert all(p["tortuosity_span"] >= 1.0 for p in res["paths"])
    assert len(res["branched"]) == 4  # 2 widest + 2 narrowest
    assert png.stat().st_size > 10_000


def test_pore_pressure_array_maps_sample_and_groups():
    # tetrahedra 0-4; the sample solved bodies 1 and 3; tetrahedra 3 and 4 form body 3
    p = pore_pressure_array(5, [1, 3], [2.0, 7.0], labels=[0, 1, 2, 3, 3])
    np.testing.assert_array_equal(np.isnan(p), [True, False, True, False, False])
    np.testing.assert_allclose(p[[1, 3, 4]], [2.0, 7.0, 7.0])
    np.testing.assert_allclose(pore_pressure_array(3, [2], [5.0])[2], 5.0)


def test_maximin_is_the_shortest_path_of_its_bottleneck_on_a_lattice():
    # on a simple-cubic lattice all windows of one kind have one area up to rounding: the
    # maximin path kept only faces >= its bottleneck bit for bit and came out up to 22 % longer
    # than the shortest path with the same bottleneck (the third audit)
    from network.paths import face_graph, random_entry_points, trace_paths
    from network.packing import Packing, lattice_packing
    from network.pores import tessellate

    c, r = lattice_packing("sc", 0.45, n_cells=8, lattice_constant_m=0.006)
    g = face_graph(tessellate(Packing(c, r)))
    xy = random_entry_points(c, r, 12, rng=1)
    sh = trace_paths(c, r, xy, kind="shortest", graph=g)
    mx = trace_paths(c, r, xy, kind="maximin", graph=g)
    for a, m in zip(sh, mx):
        assert m.bottleneck_width_m == pytest.approx(a.bottleneck_width_m, rel=1e-9)
        assert m.length_m == pytest.approx(a.length_m, rel=1e-9)
