"""Q* lookup policies checked with numbers on throats of random packings, through the public API.

Held-out throats come from ``network.sample_throats`` (the project's one sampler); the grid is
the shipped ``g1`` table; FE is the real ``throats.solve_fem``.  Every test works on its own
database under ``tmp_path``.
"""

import numpy as np
import pytest

import cache
import network
import throats

RTOL_FE = 1e-3


@pytest.fixture(scope="module")
def heldout():
    """24 throats of a random 5.5-7.5 mm packing and their FE Q* (rtol 1e-3, about 0.3 s)."""
    r, s = network.sample_throats(24, rng=7)
    fe = throats.solve_fem(r, s, rtol=RTOL_FE)
    assert set(fe.status) == {"ok"}
    return r, s, fe


def _no_fe(*args, **kwargs):
    raise AssertionError("this policy must not run FE")


_no_fe.SOLVER_VERSION = throats.SOLVER_VERSION


@pytest.mark.slow
def test_unknown_policy_is_refused_listing_the_choices(heldout, tmp_path):
    r, s, _ = heldout
    with pytest.raises(ValueError) as exc:
        cache.lookup_qstar(r, s, db=tmp_path / "t.sqlite", policy="table")
    for name in ("table-only", "table+fe", "fe-only", "shape-factor"):
        assert name in str(exc.value)
    assert set(cache.POLICIES) == {"table-only", "table+fe", "fe-only", "shape-factor"}
    assert not (tmp_path / "t.sqlite").exists()  # refused before any work


@pytest.mark.slow
def test_shape_factor_policy_is_the_closed_form_within_its_fit_error(heldout):
    # source: throats._shape_factor.FIT, re-measured on network.sample_throats (median 0.22)
    r, s, fe = heldout
    res = cache.lookup_qstar(r, s, policy="shape-factor")
    np.testing.assert_array_equal(res.qstar, throats.shape_factor_qstar(r, s))
    assert set(res.source) == {"shape-factor"} and res.stats["n_fe"] == 0
    assert np.all(np.isnan(res.error_estimate))      # no per-row estimate exists
    err = np.abs(res.qstar / fe.qstar - 1)
    assert 0.05 < np.median(err) < 0.35


@pytest.mark.slow
def test_table_only_is_within_its_estimate_of_fe_and_never_solves(heldout, tmp_path):
    r, s, fe = heldout
    res = cache.lookup_qstar(r, s, db=tmp_path / "t.sqlite", policy="table-only",
                             solver=_no_fe)
    assert set(res.source) == {"interp"} and res.stats["n_fe"] == 0
    err = np.abs(res.qstar / fe.qstar - 1)
    # the estimate bounds the error against FE (FE's own rtol 1e-3 included)
    assert np.all(err <= res.error_estimate + RTOL_FE)
    assert np.median(err) < 3e-3                      # target: median <= 0.3 %
    assert not (tmp_path / "t.sqlite").exists()      # table-only never creates a table


@pytest.mark.slow
def test_table_plus_fe_sends_only_rows_over_rtol_and_stores_them(heldout, tmp_path):
    r, s, fe = heldout
    db = tmp_path / "t.sqlite"
    est = cache.lookup_qstar(r, s, db=db, policy="table-only").error_estimate
    rtol = float(np.median(est))                      # about half the rows are over it
    over = est > rtol
    assert 0 < over.sum() < len(r)
    res = cache.lookup_qstar(r, s, db=db, policy="table+fe", rtol=rtol)
    np.testing.assert_array_equal(res.source == "fe", over)
    np.testing.assert_array_equal(res.source == "interp", ~over)
    assert res.stats["n_fe"] == over.sum()
    assert np.all(res.error_estimate[~over] <= rtol)
    # FE rows are the FE answer at that tolerance, and they are stored in the table
    direct = throats.solve_fem(r[over], s[over], rtol=rtol)
    np.testing.assert_allclose(res.qstar[over], direct.qstar, rtol=1e-9)
    with cache.open_store(db) as st:
        assert st.count() == over.sum() and st.count(status="ok") == over.sum()
    again = cache.lookup_qstar(r, s, db=db, policy="table+fe", rtol=rtol, solver=_no_fe)
    assert again.stats["n_fe"] == 0 and again.stats["n_exact"] == over.sum()
    np.testing.assert_array_equal(again.qstar, res.qstar)
    assert np.all(np.abs(res.qstar / fe.qstar - 1) <= rtol + RTOL_FE)


@pytest.mark.slow
def test_fe_only_equals_solve_fem_and_reuses_its_rows(heldout, tmp_path):
    r, s, fe = heldout
    db = tmp_path / "t.sqlite"
    res = cache.lookup_qstar(r, s, db=db, policy="fe-only", rtol=RTOL_FE)
    assert set(res.source) == {"fe"} and res.stats["n_fe"] == len(r)
    np.testing.assert_allclose(res.qstar, fe.qstar, rtol=1e-9)
    np.testing.assert_allclose(res.error_estimate, fe.error_estimate, rtol=1e-6)
    again = cache.lookup_qstar(r * 2.0, s * 2.0, db=db, policy="fe-only", rtol=RTOL_FE,
                               solver=_no_fe)
    assert set(again.source) == {"exact"}
    np.testing.assert_array_equal(again.qstar, res.qstar)


@pytest.mark.slow
def test_table_error_estimate_is_honest_on_packing_throats(tmp_path):
    # g1's estimate, calibrated on network.sample_throats(1600, rng=2026)
    # (docs/cache-error-estimate.md), on 160 other throats against FE at rtol 1e-4: it covers
    # about 96 % of the errors with a median margin under 5x, and sends 64-67 % of the rows to
    # FE at rtol 3e-3 (a flat safety factor 2 covers 100 % with a 7x margin and sends 87 %)
    r, s = network.sample_throats(160, rng=13)
    ref = throats.solve_fem(r, s, rtol=1e-4).qstar
    res = cache.lookup_qstar(r, s, db=tmp_path / "t.sqlite", policy="table-only")
    err = np.abs(res.qstar / ref - 1)
    est = res.error_estimate
    assert set(res.source) == {"interp"}
    assert np.mean(err <= est) >= 0.9
    assert np.median(est / err) < 5          # a flat safety factor 2: 7x at the median
    rtol = 3e-3
    sent = est > rtol
    assert sent.mean() < 0.8
    # what table+fe would return: FE (error ~1e-5) where sent, the table elsewhere
    assert np.mean(err[~sent] > rtol) <= 0.02
    assert cache.CALIBRATED_SAFETY["g1"] < cache.ERROR_SAFETY


@pytest.mark.slow
def test_table_policies_use_values_already_stored_in_the_db(heldout, tmp_path):
    # a stored FE value is served exactly (interpolation is up to 1.3 % off there)
    r, s, fe = heldout
    db = tmp_path / "t.sqlite"
    interp = cache.lookup_qstar(r, s, db=db, policy="table-only").qstar
    stored = cache.lookup_qstar(r[:10], s[:10], db=db, policy="fe-only", rtol=RTOL_FE)
    res = cache.lookup_qstar(r, s, db=db, policy="table-only", solver=_no_fe)
    assert list(res.source) == ["exact"] * 10 + ["interp"] * 14
    np.testing.assert_array_equal(res.qstar[:10], stored.qstar)
    np.testing.assert_array_equal(res.error_estimate[:10], stored.error_estimate)
    np.testing.assert_array_equal(res.qstar[10:], interp[10:])     # the rest: interpolated
    assert np.max(np.abs(interp[:10] / stored.qstar - 1)) > 1e-4    # it mattered
    mixed = cache.lookup_qstar(r, s, db=db, policy="table+fe", rtol=1.0, solver=_no_fe)
    assert list(mixed.source) == ["exact"] * 10 + ["interp"] * 14
    np.testing.assert_array_equal(mixed.qstar, res.qstar)


@pytest.mark.slow
def test_invalid_rows_fail_alone(heldout, tmp_path):
    """Rows with NaN, inf, zero or negative entries or sides that are no triangle come back
    'failed' (NaN, a message); the valid rows beside them get what they get alone."""
    r, s, _ = heldout
    bad_r, bad_s = np.tile(r[:1], (6, 1)), np.tile(s[:1], (6, 1))
    bad_r[0, 1] = np.nan
    bad_r[1, 2] = -1.0
    bad_s[2, 0] = np.inf
    bad_s[3, 2] = 0.0
    bad_s[4] = [1.0, 1.0, 3.0]                     # 3 > 1 + 1: no triangle
    bad_r[5, 0] = np.inf
    rr, ss = np.vstack([r, bad_r]), np.vstack([s, bad_s])
    db = tmp_path / "t.sqlite"
    both = cache.lookup_qstar(rr, ss, db=db, policy="table-only")
    alone = cache.lookup_qstar(r, s, db=db, policy="table-only")
    n = len(r)
    np.testing.assert_array_equal(both.qstar[:n], alone.qstar)
    assert list(both.source[n:]) == ["failed"] * 6
    assert np.isnan(both.qstar[n:]).all() and all(m for m in both.message[n:])
    assert both.stats["n_failed"] == 6


@pytest.mark.slow
def test_table_only_counts_the_estimates_deep_overlap_rows(tmp_path):
    # outside g1's gap range (-0.2 r̄): deep overlaps of two spheres of one grain, served by the
    # extension grid d1 where its cell is whole, else by the deep-pair grid p1 (the fourth row:
    # a wheat window overlapping by 1.59 r̄, whose d1 cell has a corner of three collinear
    # centres); a deep pair whose third sphere lies beyond p1's gaps (the last row, 3.4 r̄) takes
    # the estimate with its own constants and is counted apart; an in-range shape is g1's
    r = np.ones((5, 3))
    r[3] = [0.790151, 1.104925, 1.104925]
    s = np.array([[1.5, 2.3, 2.3], [0.9, 2.3, 2.3], [2.1, 2.1, 2.1],
                  [2.110816, 2.339809, 0.621037], [0.6, 5.4, 5.4]])
    res = cache.lookup_qstar(r, s, policy="table-only", db=tmp_path / "t.sqlite")
    assert list(res.source) == ["interp", "interp", "interp", "interp", "shape-factor"]
    assert res.stats["n_interp_d1"] == 2 and res.stats["n_interp_p1"] == 1
    assert res.stats["n_interp_extension"] == 3
    assert res.stats["n_shape_factor"] == 1 and res.stats["n_shape_factor_deep"] == 1
    assert throats.deep_overlap(r, s).tolist() == [True, True, False, True, True]
