"""Cache interpolation and lookup: exactness on quadratics, permutation symmetry, error estimate vs
held-out FE solves (real solver), lookup policies and CLIs (analytic stand-in solver)."""

import csv

import numpy as np
import pytest

import cache
import network
from cache import GRIDS, GridSpec, GridTable, grid_coordinates, lookup_qstar, open_store
from cache import precompute as precompute_cli
from cache import lookup as lookup_cli

from test_cache_fakes import fake_solve, smooth_q

PAIR = {(0, 1): 0, (1, 0): 0, (0, 2): 1, (2, 0): 1, (1, 2): 2, (2, 1): 2}


def _permute(r, s, p):
    a, b, c = p
    return r[:, [a, b, c]], s[:, [PAIR[a, b], PAIR[a, c], PAIR[b, c]]]


def _shapes(x):
    r = np.stack([1 + x[:, 3], 1 + x[:, 4], 1 - x[:, 3] - x[:, 4]], axis=1)
    s = np.stack([r[:, 0] + r[:, 1] + x[:, 0], r[:, 0] + r[:, 2] + x[:, 1],
                  r[:, 1] + r[:, 2] + x[:, 2]], axis=1)
    return r, s


def _inside_points(spec, n, rng, margin=0.0):
    rng = np.random.default_rng(rng)
    lo = np.array([a[0] for a in spec.axes]) + margin
    hi = np.array([a[-1] for a in spec.axes]) - margin
    return lo + (hi - lo) * rng.random((n, 5))


def test_interpolant_reproduces_quadratics_exactly():
    # source: construction — multilinear + per-direction curvature terms is exact for every
    # quadratic polynomial in x (bilinear cross terms and separable squares), non-uniform nodes too
    spec = GridSpec("t", [-0.1, 0.0, 0.05, 0.2, 0.45], 0.1, 3)
    mesh = np.meshgrid(*spec.axes, indexing="ij")
    X = np.stack([m.ravel() for m in mesh], axis=1)
    rng = np.random.default_rng(3)
    A = rng.normal(size=(5, 5))
    b = rng.normal(size=5)

    def v(x):
        return -4 + x @ b + 0.5 * np.einsum("ni,ij,nj->n", x, A + A.T, x)

    table = GridTable(spec, np.exp(v(X)).reshape(spec.shape))
    x = _inside_points(spec, 2000, 4)
    got, _ = table(x, _log=True)
    np.testing.assert_allclose(got, v(x), rtol=0, atol=2e-5)  # float32 tables
    plain = GridTable(spec, np.exp(v(X)).reshape(spec.shape), curvature=False)
    assert np.max(np.abs(plain(x, _log=True)[0] - v(x))) > 1e-3  # the correction matters


def test_lookup_is_permutation_and_scale_invariant(tmp_path):
    db = tmp_path / "g.sqlite"
    spec = GRIDS["tiny"]
    with open_store(db) as st:
        st.put_grid("tiny", dict(spec.to_dict(), rtol=1e-3, solver_version="fake-1"))
        precompute_throats = cache.precompute_throats
        precompute_throats(st, *spec.node_shapes(), solver=fake_solve)
    x = _inside_points(spec, 300, 5, margin=0.01)
    x[:, 3:] *= 0.5  # keep rho3 inside the box as well
    r, s = _shapes(x)
    ref = lookup_qstar(r, s, db=db, policy="table-only", solver=fake_solve)
    assert set(ref.source) == {"interp"}
    for p in [(1, 0, 2), (2, 1, 0), (1, 2, 0)]:
        rp, sp = _permute(r * 4e-3, s * 4e-3, p)
        got = lookup_qstar(rp, sp, db=db, policy="table-only", solver=fake_solve)
        np.testing.assert_allclose(got.qstar, ref.qstar, rtol=2e-6)
    # and within its own error estimate of the analytic function it tabulates
    err = np.abs(ref.qstar / smooth_q(r, s) - 1)
    assert np.all(err <= ref.error_estimate)


@pytest.mark.slow
def test_error_estimate_bounds_heldout_fe_solves(tmp_path):
    # real solver: a 3 x 3 x 3 x 3 x 3 grid (gaps 0, 0.15, 0.3 r̄; rho -0.1, 0, 0.1; about 60
    # distinct FE solves) and 16 held-out random throats inside it, solved directly by FE
    from throats import solve_fem

    spec = GridSpec("fe-test", [0.0, 0.15, 0.3], 0.1, 3)
    db = tmp_path / "fe.sqlite"
    with open_store(db) as st:
        summ = cache.precompute_grid(st, spec, rtol=1e-3, batch_size=64)
    assert summ.failed == 0 and summ.solved == summ.n_unique < 100
    rng = np.random.default_rng(12)
    x = np.c_[rng.uniform(0.0, 0.3, (16, 3)), rng.uniform(-0.05, 0.05, (16, 2))]
    r, s = _shapes(x)
    fe = solve_fem(r, s, rtol=1e-3).qstar
    res = lookup_qstar(r, s, db=db, policy="table-only")
    err = np.abs(res.qstar / fe - 1)
    assert np.all(np.isfinite(res.error_estimate)) and set(res.source) == {"interp"}
    assert np.all(err <= res.error_estimate)
    assert np.median(err) < 0.02  # a very coarse grid: 0.15 r̄ gap spacing


def test_lookup_policies_with_injected_solver(tmp_path):
    db = tmp_path / "p.sqlite"
    spec = GRIDS["tiny"]
    with open_store(db) as st:
        st.put_grid("tiny", dict(spec.to_dict(), rtol=1e-3, solver_version="fake-1"))
        cache.precompute_throats(st, *spec.node_shapes(), solver=fake_solve)
        n_rows = st.count()
    x = _inside_points(spec, 60, 6, margin=0.01)
    x[:, 3:] *= 0.5
    r, s = _shapes(x)
    r = np.r_[r, [[1, 1, 1], [1, 1, np.nan]]]
    s = np.r_[s, [[1, 1, 5], [2, 2, 2]]]
    exact = np.r_[smooth_q(r[:60], s[:60]), np.nan, np.nan]

    t_only = lookup_qstar(r, s, db=db, policy="table-only", solver=fake_solve)
    assert t_only.stats["n_fe"] == 0 and t_only.stats["n_interp"] == 60
    assert list(t_only.source[60:]) == ["failed", "failed"]
    assert "triangle" in t_only.message[60] and "non-finite" in t_only.message[61]

    rtol = float(np.median(t_only.error_estimate[:60]))  # about half must go to "FE"
    mixed = lookup_qstar(r, s, db=db, policy="table+fe", rtol=rtol, solver=fake_solve)
    n_fe = int(np.sum(t_only.error_estimate[:60] > rtol))
    assert mixed.stats["n_fe"] == n_fe and mixed.stats["n_interp"] == 60 - n_fe
    fe_rows = mixed.source == "fe"
    np.testing.assert_allclose(mixed.qstar[fe_rows], exact[fe_rows], rtol=1e-14)
    assert np.all(np.abs(mixed.qstar[:60] / exact[:60] - 1) <= np.maximum(rtol, 1e-12))
    with open_store(db) as st:
        assert st.count() == n_rows + n_fe
    again = lookup_qstar(r, s, db=db, policy="table+fe", rtol=rtol, solver=fake_solve)
    assert again.stats["n_fe"] == 0 and again.stats["n_exact"] == n_fe  # stored, reused
    assert again.stats["hit_rate"] == 1.0

    fe_only = lookup_qstar(r, s, db=db, policy="fe-only", solver=fake_solve)
    np.testing.assert_allclose(fe_only.qstar[:60], exact[:60], rtol=1e-14)
    assert set(fe_only.source[:60]) <= {"exact", "fe"}

    from throats import shape_factor_qstar

    sf = lookup_qstar(r[:60], s[:60], policy="shape-factor")
    np.testing.assert_allclose(sf.qstar, shape_factor_qstar(r[:60], s[:60]), rtol=1e-14)
    with pytest.raises(ValueError, match="unknown policy"):
        lookup_qstar(r, s, db=db, policy="guess")


def test_clis_round_trip(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(cache._build, "default_solver", lambda: (fake_solve, "fake-1"))
    rng = np.random.default_rng(8)
    x = np.c_[rng.uniform(0.0, 0.5, (40, 3)), rng.uniform(-0.1, 0.1, (40, 2))]
    r, s = _shapes(x)
    src = tmp_path / "in.csv"
    with open(src, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["id", "r1", "r2", "r3", "l12", "l13", "l23"])
        for i in range(40):
            w.writerow([i, *(r[i] * 3e-3), *(s[i] * 3e-3)])
    good = tmp_path / "good.csv"
    good.write_text("".join(src.read_text().splitlines(keepends=True)[:41]))
    with open(src, "a", newline="") as fh:
        csv.writer(fh).writerow([40, 1, 1, 1, 1, 1, 5])   # not a triangle
    db = tmp_path / "cli.sqlite"
    # precompute refuses the file before writing anything, naming the row
    assert precompute_cli.main(["--db", str(db), "--csv", str(src), "--quiet"]) == 2
    assert "in.csv row 42: sides" in capsys.readouterr().err and not db.exists()
    assert precompute_cli.main(["--db", str(db), "--csv", str(good), "--quiet"]) == 0
    assert '"solved": 40' in capsys.readouterr().out
    assert precompute_cli.main(["--db", str(db), "--csv", str(good), "--quiet"]) == 0
    assert '"reused": 40' in capsys.readouterr().out
    out = tmp_path / "out.csv"
    # lookup answers the other rows, reports the bad one (written empty) and exits 1
    assert lookup_cli.main(["--db", str(db), "--csv", str(src), "--out", str(out),
                            "--policy", "fe-only", "--quiet"]) == 1
    assert "row 42" in capsys.readouterr().err
    with open(out) as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 41 and rows[0]["id"] == "0"
    q = np.array([float(row["qstar"]) for row in rows[:40]])
    np.testing.assert_allclose(q, smooth_q(r, s), rtol=1e-12)
    assert {row["source"] for row in rows[:40]} == {"exact"} and rows[40]["qstar"] == ""
    assert {"open_area", "contact_type", "error_estimate"} <= set(rows[0])
    bad = tmp_path / "bad.sqlite"
    bad.write_bytes(b"not a database at all" * 100)
    assert precompute_cli.main(["--db", str(bad), "--csv", str(good), "--quiet"]) == 2
    assert "not an SQLite database" in capsys.readouterr().err


@pytest.mark.slow
def test_shipped_table_serves_current_solver_within_its_estimate(tmp_path):
    # the shipped grid must match throats.SOLVER_VERSION (stale values are never served) and
    # agree with direct FE on throats of a random 5.5-7.5 mm packing within its own estimate
    import json

    from throats import SOLVER_VERSION, solve_fem

    path = cache.shipped_grid_path()
    z = np.load(path)
    assert str(z["solver_version"]) == SOLVER_VERSION, (
        f"{path} was built with throats solver {z['solver_version']}, current is {SOLVER_VERSION}: "
        "rebuild it (see the cache package docstring)")
    spec = json.loads(str(z["spec"]))
    assert spec["name"] == "g1" and z["qstar"].size == 25**3 * 5**2
    r, s = network.sample_throats(12, n_spheres=400, rng=31)
    fe = solve_fem(r, s, rtol=1e-3).qstar
    res = lookup_qstar(r, s, db=tmp_path / "none.sqlite", policy="table-only")
    err = np.abs(res.qstar / fe - 1)
    assert set(res.source) == {"interp"}
    # g1's estimate is calibrated to cover >= 95 % of packing throats (cache.CALIBRATED_SAFETY,
    # docs/cache-error-estimate.md): here 11 of 12, the twelfth 5 % over its estimate
    assert np.mean(err <= res.error_estimate) >= 10 / 12
    assert np.all(err <= 2 * res.error_estimate)
    assert np.median(err) < 3e-3  # target: median <= 0.3 %
