"""The three benchmark command lines keep the project's contract: exit 0 done, 1 failed or
interrupted (one ``interrupted:`` line), 2 bad input (one ``error:`` line naming the option,
checked before any work, nothing written); an empty set prints '-' and writes null."""

import importlib
import json

import pytest

dem_bench = importlib.import_module("dem.bench")
cache_bench = importlib.import_module("cache.bench")
throats_bench = importlib.import_module("throats.bench")

BENCHES = {"dem": dem_bench, "cache": cache_bench, "throats": throats_bench}
OUT = {"dem": "--json", "cache": "--out", "throats": "--json"}

BAD = [
    ("throats", ["--n", "0"], "--n"), ("throats", ["--n", "-3"], "--n"),
    ("throats", ["--rtols", "nan"], "--rtols"), ("throats", ["--rtols", "-1"], "--rtols"),
    ("throats", ["--rtols", "0"], "--rtols"), ("throats", ["--seed", "-1"], "--seed"),
    ("dem", ["--n", "0"], "--n"), ("dem", ["--n", "-5"], "--n"),
    ("dem", ["--repeat", "0"], "--repeat"), ("dem", ["--threads", "0"], "--threads"),
    ("dem", ["--steps", "0"], "--steps"),
    ("dem", ["--scales", "-1", "--mass-scale-study"], "--scales"),
    ("dem", ["--mass-scale-study", "--grains", "10"], "--grains"),
    ("dem", ["--n", "x"], "--n"),
    ("dem", ["--pour", "0"], "--pour"), ("dem", ["--pour-stress", "100"], "--pour-stress"),
    ("dem", ["--pour", "3", "--pour-stress", "-1"], "--pour-stress"),
    ("dem", ["--pour-no-freeze"], "--pour-no-freeze"), ("dem", ["--pour", "3", "--grains", "5"], "--pour"),
    ("cache", ["--n-fe", "0"], "--n-fe"), ("cache", ["--n-fe", "-2"], "--n-fe"),
    ("cache", ["--repeat", "0"], "--repeat"), ("cache", ["--rtols", "nan"], "--rtols"),
    ("cache", ["--n-batch", "0"], "--n-batch"), ("cache", ["--n-extension", "-1"], "--n-extension"),
    ("cache", ["--db", "afolder"], "--db"), ("cache", ["--db", "missing/t.sqlite"], "--db"),
    ("cache", ["--db", "junk.sqlite"], "--db"), ("cache", ["--reference", "afolder"], "--reference"),
    ("cache", ["--reference", "missing/r.npz"], "--reference"),
    ("cache", ["--reference", "junk.npz"], "--reference"),
]
BAD += [(b, [OUT[b], path], OUT[b]) for b in BENCHES
        for path in ("/proc/x.json", "missing/x.json", "afolder")]


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    """A current folder with a folder, a junk table and a junk npz in it; returns its listing."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afolder").mkdir()
    (tmp_path / "junk.sqlite").write_text("junk\n")
    (tmp_path / "junk.npz").write_text("junk\n")
    return tmp_path


def _listing(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


@pytest.mark.parametrize("bench, argv, option", BAD, ids=[f"{b} {' '.join(a)}" for b, a, _ in BAD])
def test_bad_input_exits_2_with_one_error_line(bench, argv, option, workdir, monkeypatch, capsys):
    before = _listing(workdir)

    def no_work(*a, **k):
        raise AssertionError("work started before the options were checked")

    monkeypatch.setattr(dem_bench, "rate", no_work)
    monkeypatch.setattr(cache_bench.network, "sample_throats", no_work)
    monkeypatch.setattr(throats_bench, "run", no_work)
    try:
        code = BENCHES[bench].main(argv)
    except SystemExit as e:          # argparse-level errors (one line too)
        code = e.code
    err = capsys.readouterr().err.strip().splitlines()
    err = [line for line in err if not line.startswith("note:")]
    assert code == 2
    assert len(err) == 1 and err[0].startswith("error:") and option in err[0], err
    assert "Traceback" not in err[0]
    assert _listing(workdir) == before


def _interrupt(*a, **k):
    raise KeyboardInterrupt


@pytest.mark.parametrize("bench", sorted(BENCHES))
def test_ctrl_c_exits_1_with_one_interrupted_line(bench, workdir, monkeypatch, capsys):
    monkeypatch.setattr(dem_bench, "rate", _interrupt)
    monkeypatch.setattr(cache_bench.network, "sample_throats", _interrupt)
    monkeypatch.setattr(throats_bench.network, "sample_throats", _interrupt)
    argv = {"dem": ["--n", "64"], "cache": ["--n-fe", "3"], "throats": ["--n", "3"]}[bench]
    before = _listing(workdir)
    code = BENCHES[bench].main([*argv, OUT[bench], "b.json"])
    err = [line for line in capsys.readouterr().err.strip().splitlines()
           if not line.startswith("note:")]
    assert code == 1 and len(err) == 1 and err[0].startswith("interrupted: "), err
    assert _listing(workdir) == before


@pytest.mark.slow
def test_cache_bench_prints_dash_and_writes_null_for_an_empty_extension_set(
        workdir, monkeypatch, capsys):
    """An extension grid that served no shape: '-' in the table, null in the JSON (it raised
    KeyError 'median')."""
    def empty_extension(n, seed, version):
        empty = cache_bench._pct([])
        return {"d1": {"n": 0, "served": 0, "table": empty, "shape_factor": empty, "bytes": 1}}

    monkeypatch.setattr(cache_bench, "_extension", empty_extension)
    argv = ["--db", "none.sqlite", "--n-fe", "3", "--n-batch", "100", "--repeat", "1",
            "--n-extension", "1", "--rtols", "1e-2", "--out", "b.json"]
    assert cache_bench.main(argv) == 0
    text = capsys.readouterr().out
    assert "table          median -  p90 -  p99 -  max -" in text
    ext = json.loads((workdir / "b.json").read_text())["extension"]["d1"]
    assert ext["table"] == {"n": 0, "median": None, "p90": None, "p99": None, "max": None}


def test_throats_bench_help_names_the_default_output(capsys):
    with pytest.raises(SystemExit):
        throats_bench.main(["--help"])
    assert "default" in capsys.readouterr().out.split("--json")[-1].split("--fit")[0]
