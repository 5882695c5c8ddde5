"""Orbit-compact grids and the extension grids x1 and d1 that serve what the shipped g1 cannot.

A compact grid keeps one value per vertex-permutation orbit of its nodes and must give back
every node bit for bit; its orbits are the grid's distinct shapes. x1 serves clump windows
outside g1 (radius deviations beyond ±0.25 r̄, gaps beyond 2.2 r̄), where the shape-factor
estimate is about 2x too open, d1 the deep overlaps of two spheres of one grain, where its deep
class is 10-20 % low, each against FE; rows g1 serves keep their bits.
"""

import numpy as np
import pytest

import cache
import throats
from cache import (EXTENSION_GRIDS, GRIDS, export_grid, lookup_qstar, open_store, precompute_grid,
                   read_grid_file, shipped_grid_path)
from cache._orbits import compact, expand, orbit_representatives
from cache._order import lookup_order
from test_cache_fakes import fake_solve


def test_orbits_give_back_every_node_bit_for_bit():
    spec, _, values = read_grid_file(shipped_grid_path("g2"))
    q, fe = values()
    cq, cfe = compact(spec, q, fe)
    eq, efe = expand(spec, cq, cfe)
    np.testing.assert_array_equal(eq, q)
    np.testing.assert_array_equal(efe, fe)
    # the index arithmetic's orbits are the geometry's distinct shapes
    r, s = spec.node_shapes()
    valid, _ = throats.validate_throats(r, s)
    rep = orbit_representatives(spec)
    keys = cache.shape_keys(cache.signature(r[valid], s[valid]))
    assert len(np.unique(rep[valid])) == len(np.unique(keys, axis=0)) == 4777
    assert len(cq) == len(np.unique(rep)) == 5018        # of 13^3 * 3^2 = 19 773 nodes
    # a node value that breaks the symmetry is refused, not averaged away
    bad = q.copy()
    bad[3, 5, 7, 0, 2] *= 1.01
    with pytest.raises(ValueError, match="orbit"):
        compact(spec, bad)


def test_orbit_export_reads_back_as_the_full_export(tmp_path):
    with open_store(tmp_path / "t.sqlite") as store:
        precompute_grid(store, GRIDS["tiny"], solver=fake_solve, solver_version="fake-1")
        full = export_grid(store, "tiny", tmp_path / "full.npz", solver_version="fake-1")
        small = export_grid(store, "tiny", tmp_path / "small.npz", solver_version="fake-1",
                            orbits=True)
    (sa, va, fa), (sb, vb, fb) = read_grid_file(full), read_grid_file(small)
    assert sa.to_dict() == sb.to_dict() and va == vb == "fake-1"
    for a, b in zip(fa(), fb()):
        np.testing.assert_array_equal(a, b)
    assert np.load(small)["orbit_qstar"].size < 0.5 * np.load(full)["qstar"].size


def test_coverage_names_each_shipped_grid_in_lookup_order():
    # the warning for windows outside every table names these ranges (network's conduit model)
    assert cache.table_coverage() == (
        "g1: gaps -0.2 to 2.2, radius deviations to 0.25; x1: gaps -0.2 to 4.6, radius "
        "deviations to 0.375; d1: gaps -2.2 to 2.2, radius deviations to 0.5; p1: deep pairs "
        "of side 0.05 to 2.7, third sphere's gap -0.2 to 2.6, |tau| to 0.9, radius deviations "
        "to 0.4 (mean radii)")


def test_lookup_order_keeps_the_shape_puts_the_odd_radius_third_for_every_vertex_order():
    rng = np.random.default_rng(3)
    r = rng.uniform(0.5, 1.5, (2000, 3))
    r[:300] = 1.0                                     # equal radii: the order by opposite side
    r[300:600, 1] = r[300:600, 0]
    s = np.stack([r[:, 0] + r[:, 1], r[:, 0] + r[:, 2], r[:, 1] + r[:, 2]], axis=1)
    s += rng.uniform(-0.1, 2.0, (2000, 3))
    s[:100] = 2.3                                     # equilateral: every order the same
    rp, sp = lookup_order(r, s)
    np.testing.assert_allclose(cache.signature(rp, sp), cache.signature(r, s), rtol=0, atol=1e-12)
    dev = np.abs(rp - rp.mean(axis=1, keepdims=True))
    assert np.all(dev[:, 2] >= dev.max(axis=1))
    col = {(0, 1): 0, (0, 2): 1, (1, 2): 2}
    for a, b, c in [(0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
        side = [col[tuple(sorted(p))] for p in ((a, b), (a, c), (b, c))]
        rq, sq = lookup_order(r[:, [a, b, c]], s[:, side])
        assert np.array_equal(rq, rp) and np.array_equal(sq, sp)     # bit for bit
    assert np.array_equal(np.stack(lookup_order(rp, sp)), np.stack((rp, sp)))   # idempotent


# windows of the shelled-corn clump bed (a 2028-grain cube) that g1 cannot serve, in
# units of r̄: radius deviations to -0.373 (a half-size end sphere) and gaps to 3.2 r̄
#: x1 against FE (rtol 1e-4) on these: within 0.07 % (the estimate: +29 %, +191 %, +130 %)
TOL_X1 = 0.01
#: d1 (gap step 0.2 r̄) against FE (rtol 1e-4) on the deep windows below: within TOL_D1
TOL_D1 = 0.03

CORN_WINDOWS = {
    "radii beyond g1": ([0.627139, 1.112045, 1.260816], [2.460587, 1.89567, 2.948195]),
    "gap beyond g1": ([0.795081, 0.795081, 1.409839], [4.819171, 3.50186, 4.576066]),
    "both": ([0.627139, 1.112045, 1.260816], [4.489564, 2.534915, 3.674316]),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", CORN_WINDOWS)
def test_extension_serves_clump_windows_outside_g1_against_fe(name, tmp_path):
    r, s = (np.array([v]) for v in CORN_WINDOWS[name])
    g1 = cache.load_grid_table(tmp_path / "t.sqlite", grid="g1")     # g1 alone, injected
    alone = lookup_qstar(r, s, policy="table-only", table=g1, db=tmp_path / "t.sqlite")
    assert list(alone.source) == ["shape-factor"]
    res = lookup_qstar(r[:, ::-1], s[:, ::-1], policy="table-only", db=tmp_path / "t.sqlite")
    assert list(res.source) == ["interp"] and res.stats["n_interp_extension"] == 1
    fe = throats.solve_fem(r, s, rtol=1e-4).qstar[0]
    assert res.qstar[0] == pytest.approx(fe, rel=TOL_X1)
    assert abs(alone.qstar[0] / fe - 1) > 0.25         # what the estimate gave


@pytest.mark.slow
def test_rows_g1_serves_keep_their_bits(tmp_path):
    rng = np.random.default_rng(11)
    r = rng.uniform(0.85, 1.15, (500, 3))
    s = np.column_stack([r[:, 0] + r[:, 1], r[:, 0] + r[:, 2], r[:, 1] + r[:, 2]])
    s += rng.uniform(-0.15, 2.1, (500, 3))
    g1 = cache.load_grid_table(tmp_path / "t.sqlite", grid="g1")     # g1 alone, injected
    both = lookup_qstar(r, s, policy="table-only", db=tmp_path / "t.sqlite")
    alone = lookup_qstar(r, s, policy="table-only", db=tmp_path / "t.sqlite", table=g1)
    inside = np.asarray(alone.source) == "interp"
    assert inside.mean() > 0.9 and both.stats.get("n_interp_extension", 0) <= (~inside).sum()
    np.testing.assert_array_equal(both.qstar[inside], alone.qstar[inside])
    assert EXTENSION_GRIDS == ("x1", "d1", "p1")
    assert all(shipped_grid_path(name).exists() for name in EXTENSION_GRIDS)


# deep overlaps of corn (two spheres of one grain, gap below -0.2 r̄): 0.24 and 0.82 r̄, where
# the estimate's deep class is 18 % and 20 % low
DEEP_WINDOWS = {
    "shallow": ([0.659862, 1.170069, 1.170069], [1.588953, 2.933039, 2.828358]),
    "middle": ([0.95731, 0.95731, 1.08538], [3.033753, 1.226258, 2.595152]),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", DEEP_WINDOWS)
def test_deep_grid_serves_deep_overlaps_against_fe(name, tmp_path):
    r, s = (np.array([v]) for v in DEEP_WINDOWS[name])
    assert throats.deep_overlap(r, s)[0]
    res = lookup_qstar(r[:, [2, 0, 1]], s[:, [1, 2, 0]], policy="table-only",
                       db=tmp_path / "t.sqlite")
    assert list(res.source) == ["interp"] and res.stats["n_interp_d1"] == 1
    fe = throats.solve_fem(r, s, rtol=1e-4).qstar[0]
    assert res.qstar[0] == pytest.approx(fe, rel=TOL_D1)
    assert throats.shape_factor_qstar(r, s)[0] < 0.85 * fe       # what the estimate gave


def test_the_deepest_overlaps_go_to_the_pair_grid(tmp_path):
    # a wheat window overlapping by 1.59 r̄: d1's cell there has corners of three collinear
    # centres (no triangle), so d1 does not serve it; the deep-pair grid p1 does, against FE
    r, s = np.array([[0.790151, 1.104925, 1.104925]]), np.array([[2.110816, 2.339809, 0.621037]])
    res = lookup_qstar(r, s, policy="table-only", db=tmp_path / "t.sqlite")
    assert list(res.source) == ["interp"] and res.stats["n_interp_p1"] == 1
    assert res.stats["n_shape_factor_deep"] == 0
    fe = throats.solve_fem(r, s, rtol=1e-4).qstar[0]
    assert res.qstar[0] == pytest.approx(fe, rel=0.02)


def test_table_routes_follow_the_lookup():
    # the rows each shipped table serves, as cache.table_routes tells them, are the lookup's
    # 'interp' rows (g1's, then the extension grids' counts), the rest its estimate
    import network

    t = network.tessellate(network.random_packing(300, diameter_range_m=(0.001, 0.006),
                                                  solid_fraction=0.55, rng=5))
    r, s = t.throat_radii, t.throat_sides
    routes = cache.table_routes(r, s)
    assert [e[0] for e in routes] == ["g1", *EXTENSION_GRIDS]
    res = lookup_qstar(r, s, policy="table-only")
    src = np.asarray(res.source)
    for name, rows, _, _, served in routes:
        assert res.stats.get(f"n_interp_{name}", int(served.sum())) == int(served.sum())
    assert np.array_equal(np.sort(routes[-1][1][~routes[-1][4]]),
                          np.flatnonzero(src != "interp"))
    assert routes[1][1].size == routes[0][1].size - int(routes[0][4].sum())


@pytest.mark.slow
def test_x1_error_estimate_covers_held_out_windows():
    # x1's safety factor (cache.CALIBRATED_SAFETY, docs/scripts/calibrate_extension.py) was
    # measured on clump beds and 1-6 mm sphere packings of seeds 2 and 3: on seed 4's windows
    # beyond g1 (every fourth of them) the estimate bounds the table's error against FE (rtol
    # 1e-4) on 94.7 % here; the rule is 95 % of a population
    import network

    t = network.tessellate(network.random_packing(400, diameter_range_m=(0.001, 0.006),
                                                  solid_fraction=0.55, rng=4))
    routes = {e[0]: e for e in cache.table_routes(t.throat_radii, t.throat_sides)}
    _, _, rp, sp, _ = routes["x1"]              # beyond g1, reordered as the lookup asks x1
    x1 = cache.load_grid_table(grid="x1")
    assert x1.safety == cache.CALIBRATED_SAFETY["x1"] < cache.ERROR_SAFETY
    q, est = x1.at_throats(rp, sp, errors=True)
    rows = np.flatnonzero(np.isfinite(est))[::4][:300]
    assert rows.size == 300
    ref = throats.solve_fem(rp[rows], sp[rows], rtol=1e-4).qstar
    err = np.abs(np.log(q[rows] / ref))
    assert np.mean(err <= est[rows]) >= 0.9
    assert np.median(err) < 2e-3
