"""cache.precompute as processes: Ctrl-C stops cleanly and says what was saved,
workers do not outlive a parent killed with kill -9, two runs on one table split the work."""

import pytest
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import network
from cache import open_store, precompute_throats

ROOT = Path(__file__).resolve().parents[2]


def _csv(path, n, rng):
    r, s = network.sample_throats(n, rng=rng)
    np.savetxt(path, np.c_[r, s], delimiter=",", header="r1,r2,r3,l12,l13,l23", comments="",
               fmt="%.17g")
    return r, s


def _start(db, csv, *extra):
    return subprocess.Popen(
        [sys.executable, "-m", "cache.precompute", "--db", str(db), "--csv", str(csv), "--quiet",
         *extra], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True,   # its own process group, as a terminal's Ctrl-C sees it
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _rows(db):
    try:
        with sqlite3.connect(db, timeout=10) as c:
            return c.execute("SELECT count(*) FROM throats").fetchone()[0]
    except sqlite3.Error:
        return 0


def _wait_for_rows(db, proc, limit=20.0):
    t0 = time.monotonic()
    while _rows(db) == 0:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < limit, "no batch stored in time"
        time.sleep(0.05)


def _children(pid):
    out = []
    for d in Path("/proc").iterdir():
        try:
            stat = (d / "stat").read_text()
        except (OSError, ValueError):
            continue
        if d.name.isdigit() and int(stat.rsplit(")", 1)[1].split()[1]) == pid:
            out.append(int(d.name))
    return out


def _gone(pid):
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return True
    return stat.rsplit(")", 1)[1].split()[0] in ("Z", "X")   # exited, not yet reaped


@pytest.mark.slow
def test_ctrl_c_stops_cleanly_and_says_what_was_saved(tmp_path):
    csv, db = tmp_path / "t.csv", tmp_path / "t.sqlite"
    _csv(csv, 1500, 7)
    p = _start(db, csv, "--workers", "2")
    _wait_for_rows(db, p)
    kids = _children(p.pid)
    assert len(kids) >= 2
    os.killpg(p.pid, signal.SIGINT)                       # what Ctrl-C in a terminal sends
    out, err = p.communicate(timeout=25)
    assert p.returncode == 1, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    line = [x for x in err.splitlines() if x.startswith("interrupted:")]
    assert len(line) == 1 and "rerun the same command to resume" in line[0]
    summary = json.loads(out)
    assert summary["interrupted"] and summary["rows"] == _rows(db) > 0
    assert summary["solved"] + summary["failed"] == _rows(db) < 1500
    t0 = time.monotonic()
    while not all(_gone(k) for k in kids) and time.monotonic() - t0 < 5:
        time.sleep(0.1)
    assert all(_gone(k) for k in kids)


@pytest.mark.slow
def test_workers_exit_after_kill_9_of_the_parent_and_a_rerun_finishes(tmp_path):
    csv, db = tmp_path / "t.csv", tmp_path / "t.sqlite"
    r, s = _csv(csv, 300, 8)
    p = _start(db, csv, "--workers", "2")
    _wait_for_rows(db, p)
    kids = _children(p.pid)
    assert len(kids) >= 2
    p.kill()
    p.wait(timeout=10)
    t0 = time.monotonic()
    while not all(_gone(k) for k in kids) and time.monotonic() - t0 < 5:
        time.sleep(0.1)
    assert all(_gone(k) for k in kids), "pool workers outlived their parent"
    # the dead run's claims hold nothing up: a rerun solves exactly what is missing
    before = _rows(db)
    with open_store(db) as store:
        summ = precompute_throats(store, r, s)
        assert store.count() == 300
        # and the rerun cleared them: no claim outlives its run
        assert store.conn.execute("SELECT COUNT(*) FROM claims").fetchone()[0] == 0
    assert summ.solved == 300 - before and summ.extra["remaining"] == 0


@pytest.mark.slow
def test_two_runs_on_one_table_split_the_work(tmp_path):
    csv, db, ref = tmp_path / "t.csv", tmp_path / "t.sqlite", tmp_path / "serial.sqlite"
    r, s = _csv(csv, 120, 9)
    with open_store(db):
        pass                                  # both runs open an existing table
    procs = [_start(db, csv) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [o[1] for o in outs]
    runs = [json.loads(o[0]) for o in outs]
    assert sum(x["solved"] for x in runs) == 120           # each shape solved once
    assert all(x["solved"] > 0 for x in runs)              # by both runs together
    assert all(x["solved"] + x["reused"] == 120 for x in runs)
    with open_store(ref) as store:
        precompute_throats(store, r, s)
    with open_store(db) as a, open_store(ref) as b:
        ra, rb = a.load(), b.load()
    ia, ib = np.lexsort(ra["keys"].T), np.lexsort(rb["keys"].T)
    np.testing.assert_array_equal(ra["keys"][ia], rb["keys"][ib])
    np.testing.assert_array_equal(ra["qstar"][ia], rb["qstar"][ib])
    np.testing.assert_array_equal(ra["status"][ia], rb["status"][ib])
