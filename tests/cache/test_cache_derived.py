"""The shipped table's derived arrays, saved once and memory-mapped afterwards (cache._derived).

A table rebuilt from the saved arrays must answer every lookup with the same bits as one
computed from the table file, error estimates included; a broken or foreign file is ignored.
"""

import json

import numpy as np
import pytest

from cache import GridSpec, GridTable, shipped_grid_path
from cache._derived import OPTIONAL, ROWS, derived_path, load_derived, save_derived


def _shipped():
    z = np.load(shipped_grid_path("g1"))
    return GridSpec.from_dict(json.loads(str(z["spec"]))), z["qstar"], z["fe_error"]


def test_saved_arrays_rebuild_the_same_table(tmp_path):
    spec, q, fe = _shipped()
    fresh = GridTable(spec, q, fe)
    saved = derived_path(shipped_grid_path("g1"), tmp_path)
    save_derived(saved, dict(fresh.derived(), qstar=q, fe_error=fe))
    rows = load_derived(saved, spec.shape)
    assert set(rows) == set(ROWS) - set(OPTIONAL) and rows["cell_ok"].dtype == bool
    again = GridTable(spec, rows["qstar"], rows["fe_error"], derived=rows)
    rng = np.random.default_rng(7)
    x = rng.uniform([-0.3, -0.3, -0.3, -0.3, -0.3], [2.3, 2.3, 2.3, 0.3, 0.3], (20_000, 5))
    for errors in (True, False):
        (q1, e1), (q2, e2) = fresh(x, errors=errors), again(x, errors=errors)
        np.testing.assert_array_equal(q1, q2)
        np.testing.assert_array_equal(e1, e2)
    np.testing.assert_array_equal(fresh.cell_error, again.cell_error)
    # the node passes the derived table makes on first use only
    np.testing.assert_array_equal(fresh.node_ok, again.node_ok)
    np.testing.assert_array_equal(fresh.fe_error, again.fe_error)
    assert again.fe_error.shape == spec.shape and np.all(again.fe_error >= 0)
    # one copy per table file: a newer one replaces it
    assert [p.name for p in tmp_path.iterdir()] == [saved.name]


def test_broken_or_foreign_files_are_not_used(tmp_path):
    spec, _, _ = _shipped()
    junk = tmp_path / "junk.npy"
    junk.write_bytes(b"not an array")
    assert load_derived(junk, spec.shape) is None
    np.save(junk, np.zeros((len(ROWS), 10)))               # another grid's size
    assert load_derived(junk, spec.shape) is None
    assert load_derived(tmp_path / "absent.npy", spec.shape) is None
    assert derived_path(tmp_path / "absent.npz", tmp_path) is None


def test_copies_of_other_checkouts_are_bounded_by_last_use(tmp_path):
    # each checkout's table file has its own derived copy; KEEP of them stay, the most
    # recently used (a load marks its use), so clones do not fill the cache for good
    import os

    import cache._derived as derived

    src = shipped_grid_path("g1").read_bytes()
    arrays = {k: np.arange(4.0) for k in ROWS}
    cache_dir = tmp_path / "cache"
    paths = []
    for k in range(derived.KEEP + 1):
        table = tmp_path / f"checkout{k}" / "grid_g1.npz"
        table.parent.mkdir()
        table.write_bytes(src)
        paths.append(derived_path(table, cache_dir))
    assert len(set(paths)) == len(paths)
    for k, p in enumerate(paths[:derived.KEEP]):
        save_derived(p, arrays)
        os.utime(p, ns=(10**18 + k * 10**9, 10**18 + k * 10**9))     # saved in that order
    assert load_derived(paths[0], (4,)) is not None                     # the oldest used now
    save_derived(paths[derived.KEEP], arrays)
    left = {p.name for p in cache_dir.iterdir()}
    assert left == {paths[0].name, paths[2].name, paths[derived.KEEP].name}
    assert len(left) == derived.KEEP


@pytest.mark.slow
def test_the_pair_tables_geometric_part_is_kept_with_its_derived_arrays(tmp_path):
    """The deep-pair table keeps its nodes' geometric part (a whole-grid pass of exact open
    areas) with the derived arrays: a table rebuilt from them equals the one computed."""
    from cache._derived import load_derived, save_derived
    from cache._gridio import grid_table
    from cache import read_grid_file

    spec, _, values = read_grid_file(shipped_grid_path("p1"))
    qstar, fe_error = values()
    made = grid_table(spec, qstar, fe_error)
    saved = tmp_path / "p1.derived.npy"
    save_derived(saved, dict(made.derived(), qstar=qstar, fe_error=fe_error))
    rows = load_derived(saved, spec.shape)
    assert "geometric" in rows
    again = grid_table(spec, rows["qstar"], rows["fe_error"], derived=rows)
    np.testing.assert_array_equal(again.node_geometric, made.node_geometric)
    np.testing.assert_array_equal(again.qstar, made.qstar)
    r = np.array([[1.0, 1.0, 0.9], [1.1, 1.0, 1.0]])
    s = np.array([[1.2, 1.8, 1.9], [1.3, 2.0, 2.1]])
    np.testing.assert_array_equal(again.at_throats(r, s)[0], made.at_throats(r, s)[0])
