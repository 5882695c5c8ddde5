"""A default throat store costs nothing beyond the rows it can answer: the side-sum filter never
drops a stored shape (permuted, scaled or not), a store answers exactly the rows it holds and
interpolation the rest, and a small store asks SQLite once per stored key, not once per row.
Every store here lives in a temporary HOME, never in the user's ~/.cache."""

import sqlite3

import numpy as np
import pytest

import throats
from cache import lookup_qstar, open_store, shape_keys, signature
from cache._signature import SIDE_SUM_SLACK, near_side_sums, side_sum

RNG = np.random.default_rng(7)


def _throats(n, rng=RNG):
    r = rng.uniform(1.0, 2.0, (n, 3))
    s = np.sort(r, axis=1)[:, [0, 0, 1]] + np.sort(r, axis=1)[:, [1, 2, 2]] \
        + rng.uniform(0.1, 1.0, (n, 3))
    return r, s


def _store(path, r, s, q, version=throats.SOLVER_VERSION):
    cr, cs = throats.canonical_form(r, s)
    k = len(r)
    with open_store(path) as st:
        st.put(shape_keys(signature(r, s)), cr, cs, solver_version=version, rtol=1e-3,
               qstar=q, open_area=np.full(k, np.nan), contact_type=np.full(k, "", object),
               error_estimate=np.zeros(k), n_elements=np.full(k, -1), seconds=np.zeros(k),
               status=np.full(k, "ok", object), message=np.full(k, "", object))


@pytest.fixture
def home(tmp_path, monkeypatch):
    """A temporary HOME (and no GRAINFLOW_CACHE_DB): the default store is tmp_path's."""
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.delenv("GRAINFLOW_CACHE_DB", raising=False)
    return tmp_path / ".cache" / "grainflow" / "throats.sqlite"


def test_side_sum_is_within_slack_of_the_key_sum_in_every_vertex_order_and_scale():
    r, s = _throats(2000)
    keys = shape_keys(signature(r, s))
    perm = [1, 2, 0]                          # vertices (a, b, c) -> (b, c, a)
    pair = {(0, 1): 0, (0, 2): 1, (1, 2): 2}
    sides_p = np.column_stack([s[:, pair[tuple(sorted((perm[0], perm[1])))]],
                               s[:, pair[tuple(sorted((perm[0], perm[2])))]],
                               s[:, pair[tuple(sorted((perm[1], perm[2])))]]])
    for rr, ss in ((r, s), (r[:, perm] * 3.7, sides_p * 3.7), (r * 1e-3, s * 1e-3)):
        gap = np.abs(side_sum(rr, ss) - keys[:, 2:].sum(axis=1))
        assert gap.max() <= SIDE_SUM_SLACK
        assert near_side_sums(rr, ss, keys[:, 2:].sum(axis=1)).all()


def test_the_filter_drops_shapes_not_stored():
    r, s = _throats(1000)
    stored = shape_keys(signature(r[:10], s[:10]))[:, 2:].sum(axis=1)
    near = near_side_sums(r, s, stored)
    assert near[:10].all()
    assert near[10:].mean() < 0.01            # random others: sums far apart in quanta
    assert not near_side_sums(r, s, []).any()


@pytest.mark.slow
def test_a_small_default_store_answers_its_rows_exactly_the_rest_as_without(home):
    r, s = _throats(3000)
    without = lookup_qstar(r, s, policy="table-only")
    assert not home.exists()
    q_stored = np.linspace(0.1, 0.2, 28)
    _store(home, r[:28], s[:28], q_stored)
    got = lookup_qstar(r, s, policy="table-only")
    np.testing.assert_array_equal(got.qstar[:28], q_stored)
    assert set(got.source[:28]) == {"exact"}
    np.testing.assert_array_equal(got.qstar[28:], without.qstar[28:])
    np.testing.assert_array_equal(got.source[28:], without.source[28:])


@pytest.mark.slow
def test_a_small_store_is_asked_once_per_stored_key_not_per_row(home, monkeypatch):
    """SQLite's executemany sees only the rows the store can answer (28 shapes, each asked for
    ten times: 28 inserts), not the 30 000 rows looked up."""
    r, s = _throats(3000)
    _store(home, r[:28], s[:28], np.full(28, 0.3))
    r10, s10 = np.tile(r, (10, 1)), np.tile(s, (10, 1))
    inserted = []
    real_connect = sqlite3.connect

    class Counting(sqlite3.Connection):
        def executemany(self, sql, rows):
            rows = list(rows)
            if "INTO _q" in sql:
                inserted.append(len(rows))
            return super().executemany(sql, rows)

    monkeypatch.setattr(sqlite3, "connect",
                        lambda *a, **kw: real_connect(*a, factory=Counting, **kw))
    got = lookup_qstar(r10, s10, policy="table-only")
    assert inserted == [28]
    assert (got.source == "exact").sum() == 280


def test_cold_tables_names_the_tables_not_derived_yet(tmp_path, monkeypatch):
    """A fresh cache folder: every shipped table is cold (a command's first progress line
    says so, network.conductance.first_run_note); once a table's derived arrays are saved
    there it is not; the shape-factor policy needs no note."""
    import cache._lookup as lookup
    from cache import EXTENSION_GRIDS, cold_tables, shipped_grid_path
    from cache._derived import derived_path
    from network.conductance import first_run_note

    monkeypatch.setenv("GRAINFLOW_CACHE_DB", str(tmp_path / "throats.sqlite"))
    monkeypatch.setattr(lookup, "_TABLES", {})
    names = ["g1", *EXTENSION_GRIDS]
    assert cold_tables() == [n for n in names if shipped_grid_path(n).exists()]
    assert "g1" in first_run_note("table-only") and first_run_note("shape-factor") is None
    for n in names:
        path = derived_path(shipped_grid_path(n), tmp_path)
        if path is not None:
            path.write_bytes(b"")
    assert cold_tables() == [] and first_run_note("table-only") is None
