"""Airflow paths (thesis 3.4, Eqs. 3.24-3.27; Appendices D-E): analytic and lattice checks."""

import dataclasses
import json

import numpy as np
import pytest

from network import Packing, tessellate
from network.paths import (
    EXIT_FACES,
    bed_depth,
    branched_path_pressure_drop,
    build_paths,
    entry_faces,
    eq323_negative,
    face_areas,
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
    # every exit is higher than its base, and (without backtracking) is the widest/narrowest
    # face allowed: upward, open by Eq. 3.23
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
        _, op = face_areas(c, r, tri)
        op = np.where(eq323_negative(c, r, tri), 0.0, op)
        base_h = c[p.tetra_vertices[:, :3]].mean(axis=1)[:, 2]
        allowed = (op > 0) & (c[tri].mean(axis=2)[:, :, 2] > base_h[:, None])
        chosen = op[np.arange(p.n_tetrahedra), p.exit_local]
        best = np.where(allowed, op, -np.inf if kind == "widest" else np.inf)
        best = best.max(axis=1) if kind == "widest" else best.min(axis=1)
        if p.n_backtracks == 0:
            np.testing.assert_allclose(chosen, best)
        np.testing.assert_allclose(p.widths_m, 2 * np.sqrt(chosen / np.pi))


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
