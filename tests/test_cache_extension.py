"""Orbit-compact grids and the extension grid x1 that serves what the shipped g1 cannot.

A compact grid keeps one value per vertex-permutation orbit of its nodes and must give back
every node bit for bit; its orbits are the grid's distinct shapes. The extension serves clump
windows outside g1 (radius deviations beyond ±0.25 r̄, gaps beyond 2.2 r̄), where the
shape-factor estimate is about 2x too open, within its accuracy against FE; rows g1 serves keep
their bits.
"""

import numpy as np
import pytest

import cache
import throats
from cache import (EXTENSION_GRID, GRIDS, export_grid, lookup_qstar, open_store, precompute_grid,
                   read_grid_file, shipped_grid_path)
from cache._orbits import compact, expand, orbit_representatives, toward_extension
from test_cache_fakes import fake_solve


def test_orbits_give_back_every_node_bit_for_bit():
    spec, _, values = read_grid_file(shipped_grid_path("g2"))
    q, fe = values()
    cq, cfe = compact(spec, q, fe)
    np.testing.assert_array_equal(expand(spec, cq), q)
    np.testing.assert_array_equal(expand(spec, cfe), fe)
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


def test_reordering_keeps_the_shape_and_puts_the_odd_radius_third():
    rng = np.random.default_rng(3)
    r = rng.uniform(0.5, 1.5, (2000, 3))
    s = np.stack([r[:, 0] + r[:, 1], r[:, 0] + r[:, 2], r[:, 1] + r[:, 2]], axis=1)
    s += rng.uniform(-0.1, 2.0, (2000, 3))
    rp, sp = toward_extension(r, s)
    np.testing.assert_allclose(cache.signature(rp, sp), cache.signature(r, s), rtol=0, atol=1e-12)
    dev = np.abs(rp - rp.mean(axis=1, keepdims=True))
    assert np.all(dev[:, 2] >= dev.max(axis=1))
