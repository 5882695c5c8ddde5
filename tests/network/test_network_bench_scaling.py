"""Part 2 of ``python -m network.bench``: time and memory per stage against packing size.

Two tiny periodic packings (300 and 600 spheres, shape-factor Q*, so no table is needed) through
the command line: each size runs in its own ``--one`` subprocess; the JSON holds a row per size
with every stage time positive and finite, the solver's iterations, memory peaks and the
exponent of wall time ~ N^a, and the packing files are kept for the next run.
"""

import json
import math

import pytest

from network import bench
from network.benchmarks import packing_file, scaling_exponent
from network.packing import read_packing

SIZES = (300, 600)
ROW_KEYS = {"wall_s", "read_s", "stages_s", "iterations", "n_unknowns", "solver_setup_s",
            "solver_solve_s", "n_pores", "n_throats", "permeability_m2", "mass_balance_ok",
            "qstar_sources", "traced_peak_mb", "max_rss_mb", "n_spheres", "policy",
            "conductance_model", "repeats", "threads", "subprocess_s", "loadavg_1min_before",
             "us_per_sphere", "kb_per_sphere"}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bench-scaling")
    out = tmp / "scaling.json"
    rc = bench.main(["--sizes", *map(str, SIZES), "--skip-policies", "--skip-references",
                     "--policy", "shape-factor", "--repeats", "1", "--workdir", str(tmp),
                     "--json", str(out)])
    assert rc == 0
    return tmp, json.loads(out.read_text())


@pytest.mark.slow
def test_json_layout(run):
    _, report = run
    assert set(report) == {"machine_start", "machine_end", "scaling_policy", "scaling_model",
                           "scaling", "scaling_exponent"}
    assert report["scaling_policy"] == "shape-factor" and report["scaling_model"] == "conduit"
    rows = report["scaling"]
    assert [r["n_spheres"] for r in rows] == list(SIZES)
    for r in rows:
        assert set(r) == ROW_KEYS, set(r) ^ ROW_KEYS
        assert r["policy"] == "shape-factor" and r["repeats"] == 1
        assert r["mass_balance_ok"] is True


@pytest.mark.slow
def test_times_are_positive_and_finite(run):
    _, report = run
    for r in report["scaling"]:
        for key in ("wall_s", "subprocess_s", "solver_solve_s"):
            assert math.isfinite(r[key]) and r[key] > 0, key
        for stage in ("tessellate", "conductance", "assemble", "solve"):
            assert math.isfinite(r["stages_s"][stage]) and r["stages_s"][stage] >= 0, stage
        assert r["subprocess_s"] > r["wall_s"]          # the child's imports are outside wall_s
        assert r["iterations"] > 0 and r["n_unknowns"] > 0
        assert r["permeability_m2"] > 0 and r["max_rss_mb"] > 0
    assert math.isfinite(report["scaling_exponent"])
    assert report["scaling_exponent"] == scaling_exponent(report["scaling"])[0]


@pytest.mark.slow
def test_packings_are_kept_and_reused(run):
    tmp, report = run
    for n in SIZES:
        path = packing_file(n, tmp, 1)   # exists: returned without generating again
        mtime = path.stat().st_mtime_ns
        assert read_packing(path).n == n
        assert packing_file(n, tmp, 1).stat().st_mtime_ns == mtime


@pytest.mark.slow
def test_exponent_needs_two_sizes():
    assert scaling_exponent([{"n_spheres": 300, "wall_s": 1.0}, {"n_spheres": 600,
                                                                "error": "timeout"}]) is None
    slope, lo, hi = scaling_exponent([{"n_spheres": 1000, "wall_s": 1.0},
                                      {"n_spheres": 8000, "wall_s": 8.0}])
    assert slope == pytest.approx(1.0) and (lo, hi) == (1000, 8000)


@pytest.mark.slow
def test_per_packing_rows(run):
    """``--per-packing``: the whole network.solve command timed per packing and mode, each row
    with ordered min <= median <= max over its runs, the target where there is one, the
    bundled scene last; the packing files of the scaling part are reused."""
    tmp, _ = run
    out = tmp / "per_packing.json"
    rc = bench.main(["--per-packing", "--sizes", str(SIZES[0]), "--repeats", "2",
                     "--workdir", str(tmp), "--json", str(out)])
    assert rc == 0
    rows = json.loads(out.read_text())["per_packing"]
    assert [(r["n_spheres"], r["mode"]) for r in rows] == [
        (SIZES[0], "stokes"), (SIZES[0], "default"), (None, "stokes"), (None, "default")]
    for r in rows:
        assert r["runs"] == 2 and len(r["times_s"]) == 2
        assert 0 < r["min_s"] <= r["median_s"] <= r["max_s"] < 60
        assert r["target_s"] is None and "met" not in r         # no target for these sizes
    assert rows[0]["packing"] == str(packing_file(SIZES[0], tmp, 1))


@pytest.mark.slow
def test_per_packing_yade_where_installed(run, monkeypatch):
    """``--per-packing --yade`` times YADE's FlowEngine on the same packing where the ``yade``
    program is installed (FlowEngine's solve and the whole command, positive, the engine inside
    the command), each run paired with one of ours; without it the row says so; ``--yade``
    alone is bad input."""
    import shutil

    from network.benchmarks import _per_packing

    tmp, _ = run
    path = packing_file(SIZES[0], tmp, 1)
    once = _per_packing.yade_run(path)
    if shutil.which("yade") is None:
        assert once is None
    else:
        engine, whole = once
        assert 0 < engine < whole < 120
        # paired with ours: the ratio of each pair, its median, the pairs ours was faster in
        here = _per_packing.yade_summary([once, once], [0.5 * engine, 2.0 * engine])
        assert here["ratio_to_flowengine"] == [0.5, 2.0]
        assert here["ratio_to_flowengine_median"] == 1.25
        assert here["faster_than_flowengine_runs"] == 1
        assert here["flowengine_median_s"] == engine and here["command_median_s"] == whole
        # the run of ours right after YADE's is timed apart; the counted one follows ours
        row = _per_packing.per_packing([SIZES[0]], tmp, 1, repeats=1, bundled=False,
                                       yade=True)[0]
        apart = row["yade_here"]["ours_after_yade_s"]
        assert len(apart) == 1 and apart[0] > 0 and row["times_s"][0] > 0
        assert row["yade_here"]["ours_after_yade_median_s"] == apart[0]
        assert "ours right after a YADE run" in _per_packing.per_packing_line(row)
    monkeypatch.setattr(_per_packing.shutil, "which", lambda name: None)
    assert _per_packing.yade_run(path) is None
    rows = _per_packing.per_packing([SIZES[0]], tmp, 1, repeats=1, bundled=False, yade=True)
    assert rows[0]["mode"] == "stokes" and rows[0]["yade_here"] is None
    assert "YADE here: not installed" in _per_packing.per_packing_line(rows[0])
    assert "yade_here" not in rows[1]                       # the default-mode row
    with pytest.raises(SystemExit) as e:
        bench.main(["--yade"])
    assert e.value.code == 2


@pytest.mark.slow
def test_per_packing_baseline(run, tmp_path):
    """``--per-packing --baseline DIR``: another checkout's own command runs right after each
    counted ``--stokes`` run of ours, its packages imported from DIR; the row carries the paired
    speed-up baseline / ours; a DIR that is not such a checkout is bad input."""
    import subprocess
    from pathlib import Path

    import network
    from network.benchmarks import _per_packing

    repo = Path(network.__file__).resolve().parents[1]
    src = _per_packing.baseline_source(repo)
    assert src["dir"] == str(repo) and src["env"]["PYTHONPATH"].split(":")[0] == str(repo)
    with pytest.raises(ValueError, match="no network/solve.py there"):
        _per_packing.baseline_source(tmp_path)
    (tmp_path / "network").mkdir()
    (tmp_path / "network" / "solve.py").write_text("")
    with pytest.raises(ValueError, match="not imported from there"):
        _per_packing.baseline_source(tmp_path)      # a namespace portion loses to the package
    # the paired speed-up: each baseline run over the run of ours right before it
    s = _per_packing.baseline_summary(src, [4.3, 4.3], [2.0, 1.0])
    assert s["speedup"] == pytest.approx([2.15, 4.3]) and s["speedup_min"] == pytest.approx(2.15)
    assert s["speedup_median"] == pytest.approx(3.225) and s["median_s"] == 4.3
    # paired runs on a small packing: this checkout as its own baseline
    tmp, _ = run
    rows = _per_packing.per_packing([SIZES[0]], tmp, 1, repeats=1, bundled=False, baseline=repo)
    base = rows[0]["baseline"]
    assert rows[0]["mode"] == "stokes" and "baseline" not in rows[1]
    assert len(base["times_s"]) == 1 and base["speedup"][0] == pytest.approx(
        base["times_s"][0] / rows[0]["times_s"][0])
    assert "speed-up" in _per_packing.per_packing_line(rows[0])
    # a commit of this checkout: extracted for the run, its command from there, removed after
    with pytest.raises(ValueError, match="neither a directory nor a commit"):
        _per_packing.baseline_source("no-such-commit-0000")
    head = subprocess.run(["git", "-C", str(repo), "rev-parse", "--short=7", "HEAD"],
                          capture_output=True, text=True, check=False)
    if head.returncode != 0:            # not a git checkout: a commit cannot be a baseline
        with pytest.raises(ValueError, match="neither a directory nor a commit"):
            _per_packing.baseline_source("HEAD")
        return
    work = tmp_path / "work"
    work.mkdir()
    src = _per_packing.baseline_source("HEAD", work)
    assert src["commit"] == head.stdout.strip() and src["temporary"] is not None
    assert Path(src["dir"]).parent == work and (Path(src["dir"]) / "network" / "solve.py").is_file()
    rows = _per_packing.per_packing([SIZES[0]], tmp, 1, repeats=1, bundled=False, baseline=src)
    assert rows[0]["baseline"]["commit"] == src["commit"] and rows[0]["baseline"]["times_s"][0] > 0
    assert not any(work.iterdir())                                  # the extraction is gone
    for argv in (["--baseline", str(repo)], ["--per-packing", "--baseline", str(tmp_path)]):
        with pytest.raises(SystemExit) as e:
            bench.main(argv)
        assert e.value.code == 2
