"""Cache store: signature invariance, round trip, corrupt/foreign files, two writers, kill -9 + resume,
failed-solve records.  Solvers are the analytic stand-ins of ``test_cache_fakes`` (the store must
work with any solver)."""

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import cache
from cache import CacheFileError, open_store, precompute_throats, shape_keys, signature

from test_cache_fakes import fake_solve, flaky_solve, raising_solve, smooth_q

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parents[1]


def _random_throats(n, rng):
    rng = np.random.default_rng(rng)
    r = rng.uniform(0.8, 1.2, (n, 3))
    gaps = rng.uniform(-0.03, 0.8, (n, 3))
    s = np.stack([r[:, 0] + r[:, 1], r[:, 0] + r[:, 2], r[:, 1] + r[:, 2]], axis=1) + gaps
    return r, s


PERMS = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
PAIR = {(0, 1): 0, (1, 0): 0, (0, 2): 1, (2, 0): 1, (1, 2): 2, (2, 1): 2}


def _permute(r, s, p):
    a, b, c = p
    return r[:, [a, b, c]], s[:, [PAIR[a, b], PAIR[a, c], PAIR[b, c]]]


@pytest.mark.parametrize("perm", PERMS)
@pytest.mark.parametrize("scale", [1.0, 3.25e-3])
def test_signature_invariant_under_permutation_and_scale(perm, scale):
    # source: definition of the shape: Q* depends on shape only
    r, s = _random_throats(50, 1)
    r0, s0 = r.copy(), s.copy()
    rp, sp = _permute(r * scale, s * scale, perm)
    np.testing.assert_array_equal(shape_keys(signature(rp, sp)), shape_keys(signature(r, s)))
    np.testing.assert_allclose(signature(rp, sp), signature(r, s), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(r, r0)  # inputs untouched
    np.testing.assert_array_equal(s, s0)


def test_signature_separates_shapes_and_is_normalised():
    r, s = _random_throats(200, 2)
    sig = signature(r, s)
    assert sig.shape == (200, 5)
    keys = shape_keys(sig)
    assert len(np.unique(keys, axis=0)) == 200
    # r1* + r2* + r3* = 3 with r3* = 3 - r1* - r2*: each scaled radius within (0, 3)
    assert np.all((sig[:, :2] > 0) & (sig[:, :2] < 3))
    with pytest.raises(ValueError, match="shape"):
        signature(np.ones((3, 2)), np.ones((3, 3)))


def _put_rows(store, r, s, status="ok", q=None, version="fake-1", rtol=1e-3):
    sig = signature(r, s)
    n = len(r)
    q = smooth_q(r, s) if q is None else q
    store.put(shape_keys(sig), np.c_[sig[:, :2], 3 - sig[:, 0] - sig[:, 1]], sig[:, 2:],
              solver_version=version, rtol=rtol, qstar=q, open_area=np.full(n, 0.5),
              contact_type=np.full(n, "b"), error_estimate=np.full(n, 2e-4),
              n_elements=np.full(n, 321), seconds=np.full(n, 0.02),
              status=np.full(n, status, dtype=object), message=np.full(n, "", dtype=object))
    return sig


def test_round_trip_and_upsert_rules(tmp_path):
    r, s = _random_throats(30, 3)
    db = tmp_path / "t.sqlite"
    with open_store(db) as st:
        sig = _put_rows(st, r, s)
        _put_rows(st, r[:5], s[:5], q=np.zeros(5))            # ok rows are never overwritten
        _put_rows(st, r[5:10], s[5:10], version="fake-2")      # other solver: separate rows
        assert st.count() == 35
    with open_store(db) as st:
        rows = st.load(solver_version="fake-1")
        idx = cache._signature.match_keys(shape_keys(sig), rows["keys"])
        assert np.all(idx >= 0)
        np.testing.assert_allclose(rows["qstar"][idx], smooth_q(r, s), rtol=1e-15)
        np.testing.assert_allclose(rows["radii"][idx].sum(1), 3.0, rtol=1e-12)
        assert set(rows["contact_type"]) == {"b"} and set(rows["n_elements"]) == {321}
        assert st.meta()["format"] == cache._store.FORMAT
        # a failed row is replaced by a later result for the same settings
        _put_rows(st, r[:1] * 2, s[:1] * 2, version="fake-3", status="failed", q=np.array([np.nan]))
        _put_rows(st, r[:1], s[:1], version="fake-3")
        rows3 = st.load(solver_version="fake-3")
        assert list(rows3["status"]) == ["ok"]
        assert rows3["qstar"][0] == pytest.approx(smooth_q(r[:1], s[:1])[0], rel=1e-15)


def test_corrupt_and_foreign_files_are_refused(tmp_path):
    junk = tmp_path / "junk.sqlite"
    junk.write_bytes(os.urandom(5000))
    with pytest.raises(CacheFileError, match="not an SQLite database"):
        open_store(junk)
    # a real cache with its pages overwritten in the middle
    good = tmp_path / "good.sqlite"
    with open_store(good) as st:
        r, s = _random_throats(400, 4)
        _put_rows(st, r, s)
        st.conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    data = bytearray(good.read_bytes())
    assert len(data) > 3 * 4096
    data[4096 + 100:3 * 4096] = os.urandom(3 * 4096 - 4096 - 100)
    bad = tmp_path / "bad.sqlite"
    bad.write_bytes(bytes(data))
    with pytest.raises(CacheFileError):
        with open_store(bad) as st:
            st.load()
    # a valid SQLite database of another program
    foreign = tmp_path / "foreign.sqlite"
    con = sqlite3.connect(foreign)
    con.execute("CREATE TABLE users (name TEXT)")
    con.commit()
    con.close()
    with pytest.raises(CacheFileError, match="another program"):
        open_store(foreign)
    # a grainflow cache of a future format version
    future = tmp_path / "future.sqlite"
    with open_store(future) as st:
        st.conn.execute("UPDATE grainflow_meta SET value = '99' WHERE key = 'format_version'")
    with pytest.raises(CacheFileError, match="format version"):
        open_store(future)
    with pytest.raises(FileNotFoundError):
        open_store(tmp_path / "missing.sqlite", create=False)


def test_precompute_dedupes_reuses_and_records_failures(tmp_path):
    r, s = _random_throats(60, 5)
    rp, sp = _permute(r * 2.0, s * 2.0, (2, 0, 1))  # the same 60 shapes again
    rr, ss = np.r_[r, rp], np.r_[s, sp]
    bad_r = np.array([[1.0, 1.0, 1.0], [1.0, np.nan, 1.0]])
    bad_s = np.array([[2.0, 2.0, 5.0], [2.0, 2.0, 2.0]])  # not a triangle; NaN radius
    db = tmp_path / "p.sqlite"
    with open_store(db) as st:
        s1 = precompute_throats(st, np.r_[rr, bad_r], np.r_[ss, bad_s], solver=flaky_solve,
                                batch_size=7)
        n_flaky = int(np.sum((s / r.mean(1, keepdims=True)).max(1) > 2.5))
        assert 0 < n_flaky < 60
        assert (s1.n_unique, s1.solved, s1.failed, s1.reused) == (62, 60 - n_flaky, n_flaky + 2, 0)
        assert st.count() == 62
        msgs = st.load(statuses=["failed", "invalid"])["message"]
        assert sum("mesh lost a gap" in m for m in msgs) == n_flaky
        assert sum("triangle" in m for m in msgs) == 1 and sum("non-finite" in m for m in msgs) == 1
        s2 = precompute_throats(st, rr, ss, solver=fake_solve)  # failures kept unless asked
        assert (s2.solved, s2.reused, s2.reused_failed) == (0, 60 - n_flaky, n_flaky)
        s3 = precompute_throats(st, rr, ss, solver=fake_solve, retry_failed=True)
        assert (s3.solved, s3.failed, s3.reused) == (n_flaky, 0, 60 - n_flaky)
        assert st.count(status="ok") == 60 and st.count() == 62
        s4 = precompute_throats(st, r[:3], s[:3], solver=raising_solve, solver_version="fake-9")
        assert s4.failed == 3
        assert all("gmsh crashed" in m for m in st.load(solver_version="fake-9")["message"])


_WRITER = textwrap.dedent("""
    import sys, numpy as np
    sys.path[:0] = [{tests!r}, {helpers!r}]
    from cache import open_store, precompute_throats
    from test_cache_store import _random_throats
    from test_cache_fakes import slow_fake_solve
    lo, hi, batch = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    r, s = _random_throats(400, 11)
    with open_store(sys.argv[4]) as st:
        out = precompute_throats(st, r[lo:hi], s[lo:hi], solver=slow_fake_solve, batch_size=batch)
    print(out.solved, out.reused)
""")


def _writer(tmp_path, lo, hi, batch, db, delay):
    script = tmp_path / "writer.py"
    script.write_text(_WRITER.format(tests=str(TESTS), helpers=str(TESTS.parent)))
    env = dict(os.environ, CACHE_FAKE_DELAY=str(delay), PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, str(script), str(lo), str(hi), str(batch), str(db)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


@pytest.mark.slow
def test_two_processes_write_one_database(tmp_path):
    # overlapping ranges [0, 250) and [150, 400): 400 distinct shapes, each stored exactly once
    db = tmp_path / "two.sqlite"
    open_store(db).close()
    p1 = _writer(tmp_path, 0, 250, 5, db, 0.002)
    p2 = _writer(tmp_path, 150, 400, 5, db, 0.002)
    out = [p.communicate(timeout=120) for p in (p1, p2)]
    assert p1.returncode == 0 and p2.returncode == 0, out
    solved = [tuple(map(int, o[0].split())) for o in out]
    r, s = _random_throats(400, 11)
    with open_store(db) as st:
        rows = st.load()
        assert st.count() == 400 == len(np.unique(rows["keys"], axis=0))
        idx = cache._signature.match_keys(shape_keys(signature(r, s)), rows["keys"])
        np.testing.assert_allclose(rows["qstar"][idx], smooth_q(r, s), rtol=1e-14)
    # the shared 100 shapes were solved by one writer, or by both (then stored once)
    assert 400 <= solved[0][0] + solved[1][0] <= 500


@pytest.mark.slow
def test_kill_minus_9_then_resume_loses_nothing_duplicates_nothing(tmp_path):
    db = tmp_path / "kill.sqlite"
    open_store(db).close()
    batch = 8
    p = _writer(tmp_path, 0, 400, batch, db, 0.004)  # ~1.6 s for all 400
    deadline = time.time() + 60
    n_before = 0
    while time.time() < deadline:
        time.sleep(0.05)
        with open_store(db, check=False) as st:
            n_before = st.count()
        if n_before >= 10 * batch:
            break
    os.kill(p.pid, signal.SIGKILL)
    p.communicate()
    assert p.returncode == -signal.SIGKILL
    with open_store(db) as st:  # the file is intact (quick_check) after the kill
        n_killed = st.count()
        kept = st.load()
    assert 10 * batch <= n_killed < 400
    assert n_killed % batch == 0  # whole transactions only: never a partial batch
    p2 = _writer(tmp_path, 0, 400, batch, db, 0.0)
    o, e = p2.communicate(timeout=120)
    assert p2.returncode == 0, e
    solved, reused = map(int, o.split())
    assert (solved, reused) == (400 - n_killed, n_killed)
    with open_store(db) as st:
        rows = st.load()
    assert len(rows["keys"]) == 400 == len(np.unique(rows["keys"], axis=0))
    idx = cache._signature.match_keys(kept["keys"], rows["keys"])
    np.testing.assert_array_equal(rows["qstar"][idx], kept["qstar"])  # nothing lost or changed
