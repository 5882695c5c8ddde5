"""The table's one-point numba evaluation (cache.point_kernel) against GridTable's
chunked numpy evaluation: same ln Q* bit for bit and the same served cells, on the shipped
grid and on a grid with missing nodes, inside, at the gap nodes (where GAP_SNAP moves a
point to the cell above) and outside the box."""

import numba
import numpy as np
import pytest

from cache import GRIDS, GridTable, load_grid_table, point_kernel

from test_cache_fakes import smooth_q


interp_point = point_kernel()


@numba.njit(cache=False)
def _loop(r, s, gap, rho_lo, rho_hi, rho_inv, n_rho, strides, values, curv, snap, v, ok):
    for p in range(r.shape[0]):
        v[p], ok[p] = interp_point(r[p, 0], r[p, 1], r[p, 2], s[p, 0], s[p, 1], s[p, 2], gap,
                                   rho_lo, rho_hi, rho_inv, n_rho, strides, values, curv, snap)


def _throats(spec, n, rng):
    """Throats whose coordinates fill the grid box and 10 % beyond it, a third of the gaps
    put on a node or within 1e-3 below one (the snapped side)."""
    rng = np.random.default_rng(rng)
    lo = np.array([a[0] for a in spec.axes])
    hi = np.array([a[-1] for a in spec.axes])
    x = lo - 0.1 * (hi - lo) + 1.2 * (hi - lo) * rng.random((n, 5))
    g = spec.gap_nodes
    on = rng.random((n, 3)) < 0.33
    x[:, :3] = np.where(on, rng.choice(g, (n, 3)) - rng.choice([0.0, 1e-3, 1e-12], (n, 3)),
                        x[:, :3])
    x[:, 3:] = np.clip(x[:, 3:], -0.45, 0.45)
    r = np.stack([1 + x[:, 3], 1 + x[:, 4], 1 - x[:, 3] - x[:, 4]], axis=1)
    s = np.stack([r[:, 0] + r[:, 1] + x[:, 0], r[:, 0] + r[:, 2] + x[:, 1],
                  r[:, 1] + r[:, 2] + x[:, 2]], axis=1)
    scale = rng.uniform(1e-4, 3.0, (n, 1))          # Q* is scale-free; the bits of x are not
    return np.ascontiguousarray(r * scale), np.ascontiguousarray(s * scale)


def _compare(table, r, s):
    q, err = table.at_throats(r, s, errors=False)
    v, ok = np.empty(len(r)), np.empty(len(r), dtype=bool)
    _loop(r, s, *table.kernel_arrays(), v, ok)
    served = np.isnan(err)
    np.testing.assert_array_equal(ok, served)
    # the same float32 blend and float64 curvature terms: identical ln Q*, so identical Q*
    with np.errstate(over="ignore"):
        np.testing.assert_array_equal(np.exp(v[ok]), q[ok])
    return served


@pytest.mark.slow
def test_shipped_grid_bit_for_bit():
    table = load_grid_table(None)
    assert table is not None
    r, s = _throats(table.spec, 60_000, 1)
    served = _compare(table, r, s)
    assert 0.3 < served.mean() < 0.9          # both outcomes exercised


@pytest.mark.slow
def test_grid_with_missing_nodes_and_no_curvature():
    spec = GRIDS["g2"]
    r, s = spec.node_shapes()
    q = smooth_q(r, s).reshape(spec.shape)
    rng = np.random.default_rng(5)
    q[rng.random(spec.shape) < 0.01] = np.nan          # failed nodes: cells not served
    for curvature in (True, False):
        table = GridTable(spec, q, curvature=curvature)
        rr, ss = _throats(spec, 30_000, 7)
        served = _compare(table, rr, ss)
        assert 0.1 < served.mean() < 0.9


def test_one_node_axis_not_taken():
    from cache import GridSpec
    spec = GridSpec("one", [-0.1, 0.0, 0.2], 0.1, 1, _sub=False)
    r, s = spec.node_shapes()
    table = GridTable(spec, smooth_q(r, s).reshape(spec.shape), estimate=False)
    assert table.kernel_arrays() is None
