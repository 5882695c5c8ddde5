"""The conduit model's compiled loop (network.conductance._conduit_kernel) against the numpy
path it replaces for the 'table-only' policy: the same conductances and window Q* to 1e-13
(bit for bit on hosts where NumPy's exp, log and arcsin are the C library's; its AVX-512
versions differ from those in the last bit, up to 6e-16 relative here) and the same lookup
counts on a random packing (throats the table cannot serve go through the numpy path inside the
compiled one), its size threshold, and that stored FE rows turn it off."""

import numpy as np
import pytest

import network
import network.conductance._conduit as conduit
from network.conductance import (KERNEL_MIN_THROATS, conduit_conductance, load_conduit_kernel,
                                  throat_qstar)


#: the compiled loop against the numpy path: a few last bits (NumPy's SIMD exp, log, arcsin)
ULPS = dict(rtol=1e-13, atol=0.0)


@pytest.fixture(scope="module")
def tess():
    pk = network.random_packing(700, solid_fraction=0.55, rng=11)
    return network.tessellate(pk)


def _both(tess, db, monkeypatch, **kw):
    monkeypatch.setattr(conduit, "KERNEL_MIN_THROATS", 0)
    fast = conduit_conductance(tess, policy="table-only", db=db, **kw)
    with monkeypatch.context() as m:
        m.setattr(conduit, "grid_alone", lambda _db: None)
        slow = conduit_conductance(tess, policy="table-only", db=db, **kw)
    return fast, slow


@pytest.mark.slow
@pytest.mark.parametrize("threads", [1, 2])
def test_kernel_equals_numpy_path(tess, tmp_path, monkeypatch, threads):
    db = tmp_path / "none.sqlite"                    # no stored rows: the grid alone serves
    assert load_conduit_kernel(db)
    fast, slow = _both(tess, db, monkeypatch, threads=threads)
    assert fast.stats["qstar_stats"]["backend"] == "conduit kernel"
    np.testing.assert_allclose(fast.g, slow.g, **ULPS)
    np.testing.assert_allclose(fast.qstar, slow.qstar, **ULPS)
    assert fast.stats["section_qstar_stats"] == slow.stats["section_qstar_stats"]
    src = fast.stats["qstar_stats"]["sources"]
    assert src == slow.stats["qstar_stats"]["sources"]
    # both paths ran: windows and sections outside the grid went through numpy
    assert src.get("shape-factor", 0) > 0 and src["interp"] > 5 * src["shape-factor"]
    assert fast.stats["section_qstar_stats"]["sources"].get("shape-factor", 0) > 0
    assert np.isfinite(fast.g).all() and (fast.g >= 0).all()


@pytest.mark.slow
def test_zero_and_clamped_heights(tess, tmp_path):
    """Sides of zero height (slivers), both sides zero (g NaN: a zero-length conduit), heights
    beyond the largest sphere (clamped), for 2-9 sections: the same as the numpy block."""
    db = tmp_path / "none.sqlite"
    grid = conduit.grid_alone(db)
    n = 2000
    r, s = tess.throat_radii[:n], tess.throat_sides[:n]
    h = np.tile(r.mean(axis=1)[:, None], (1, 2)) * np.linspace(0.1, 1.5, n)[:, None]
    h[:500, 0] = 0.0
    h[500:1000] *= 10.0
    h[1000:1100] = 0.0
    qkw = dict(policy="table-only", rtol=1e-3, db=db, workers=1, progress=False,
               estimate=False)
    for m in (2, 6, 9):
        def numpy_rows(rows):
            st = {"n_sections": 0, "sources": {}}
            out = conduit._conduit_block(r[rows], s[rows], h[rows], 1.9e-5, st, throat_qstar,
                                         sections="qstar", n_sections=m, qkw=qkw,
                                         srtol=1e-2)
            return out + (st,)
        q_f, g_f, _, st_f = conduit._kernel_block(r, s, h, 1.9e-5, m, grid, numpy_rows)
        q_s, g_s, _, st_s = numpy_rows(np.arange(n))
        np.testing.assert_allclose(g_f, g_s, **ULPS)
        np.testing.assert_allclose(q_f, q_s, **ULPS)
        assert st_f == st_s
        assert np.isnan(g_f[1000:1100]).all() and np.isfinite(g_f[:1000]).all()


@pytest.mark.slow
def test_threshold_and_stored_rows(tess, tmp_path, monkeypatch):
    db = tmp_path / "none.sqlite"
    res = conduit_conductance(tess, policy="table-only", db=db)
    assert tess.n_throats < KERNEL_MIN_THROATS
    assert res.stats["qstar_stats"].get("backend") != "conduit kernel"
    # a table holding FE rows answers them first: the compiled loop must not be used
    from cache import open_store, precompute_throats
    from test_cache_fakes import fake_solve
    stored = tmp_path / "stored.sqlite"
    with open_store(stored) as store:
        precompute_throats(store, tess.throat_radii[:3], tess.throat_sides[:3],
                           rtol=1e-3, solver=fake_solve, solver_version="fake-1")
    assert not load_conduit_kernel(stored)
    monkeypatch.setattr(conduit, "KERNEL_MIN_THROATS", 0)
    res = conduit_conductance(tess, policy="table-only", db=stored)
    assert res.stats["qstar_stats"].get("backend") != "conduit kernel"


def test_compiled_cache_follows_the_table_kernel_source():
    # numba caches conduit_rows by its own file's time stamp: the digest of the file whose
    # functions it inlines lives in that file, so editing one without the other fails here
    import hashlib
    from pathlib import Path

    import cache
    from network.conductance import _conduit_kernel

    src = (Path(cache.__file__).parent / "_kernel.py").read_bytes()
    assert hashlib.sha256(src).hexdigest()[:16] == _conduit_kernel.INTERP_SOURCE_SHA256


@pytest.mark.slow
def test_permeability_does_not_depend_on_the_order_of_the_packing_rows():
    # the audit's find: a shuffled packing file moved k by 3e-5 (the table read each throat in
    # its Delaunay vertex order); now every lookup reads one order (cache/_order.py)
    from network.flow import FlowOptions, solve_network
    from network.packing import Packing, random_packing

    pk = random_packing(600, rng=3)
    perm = np.random.default_rng(0).permutation(pk.n)
    ks = [solve_network(p, axis=2, flow=FlowOptions(viscosity_pa_s=1.9e-5)).permeability_m2
          for p in (pk, Packing(pk.centers[perm], pk.radii[perm]))]
    assert ks[1] == pytest.approx(ks[0], rel=1e-9)
