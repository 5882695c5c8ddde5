"""``python -m network.bench``'s command-line contract: bad input is exit 2 with one ``error:``
line naming the option, before any work and with nothing written; Ctrl-C is exit 1 with one
``interrupted:`` line (docs/cli.md)."""

from __future__ import annotations

import pytest

from network import bench


def _fail_if_called(*a, **kw):
    raise AssertionError("work started before the options were checked")


@pytest.fixture
def no_work(monkeypatch):
    """Every part of the benchmark fails the test if it starts."""
    for name in ("machine", "policies", "scaling", "references", "inertial_speed",
                 "inertial_validation", "per_packing", "run_one"):
        monkeypatch.setattr(bench, name, _fail_if_called)


def _bad(tmp_path, capsys, argv, option, *, json_name="out.json", workdir="wd"):
    out = tmp_path / json_name
    args = ["--workdir", str(tmp_path / workdir), "--json", str(out), *argv]
    with pytest.raises(SystemExit) as e:
        bench.main(args)
    assert e.value.code == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    assert option in lines[0] and "Traceback" not in err
    assert not out.is_file() and not (tmp_path / workdir).exists()
    return lines[0]


@pytest.mark.parametrize("argv, option", [
    (["--sizes", "0"], "--sizes"),
    (["--sizes", "-100"], "--sizes"),
    (["--sizes", "5000", "3"], "--sizes"),
    (["--timeout", "nan"], "--timeout"),
    (["--timeout", "-1"], "--timeout"),
    (["--timeout", "0"], "--timeout"),
    (["--inertial", "--inertial-spheres", "0"], "--inertial-spheres"),
    (["--policy-spheres", "0"], "--policy-spheres"),
    (["--workers", "-1"], "--workers"),
    (["--workers", "0"], "--workers"),
    (["--fe-random", "2"], "--fe-random"),
    (["--fe-random", "0.2"], "--fe-random"),
    (["--ref-random", "1.5"], "--ref-random"),
    (["--repeats", "0"], "--repeats"),
    (["--seed", "-1"], "--seed"),
    (["--inertial-workers", "0"], "--inertial-workers"),
    (["--db", "."], "--db"),
    (["--references-only", "--db", "no-such-table.sqlite"], "--db"),
])
def test_bad_values(argv, option, tmp_path, capsys, no_work):
    _bad(tmp_path, capsys, argv, option)


@pytest.mark.parametrize("first, second", [
    ("--references-only", "--inertial"),
    ("--inertial", "--per-packing"),
    ("--references-only", "--per-packing"),
])
def test_parts_that_run_alone_conflict(first, second, tmp_path, capsys, no_work):
    line = _bad(tmp_path, capsys, [first, second], first)
    assert second in line


def test_bad_outputs(tmp_path, capsys, no_work):
    (tmp_path / "adir").mkdir()
    _bad(tmp_path, capsys, [], "--json", json_name="adir")
    _bad(tmp_path, capsys, [], "--json", json_name="missing/x.json")
    _bad(tmp_path, capsys, ["--json", "/proc/x.json"], "--json")
    with pytest.raises(SystemExit) as e:
        bench.main(["--workdir", "/proc/wd", "--json", str(tmp_path / "o.json")])
    err = capsys.readouterr().err
    assert e.value.code == 2 and err.count("\n") == 1 and err.startswith("error: --workdir")
    (tmp_path / "afile").write_text("")
    _bad(tmp_path, capsys, [], "--workdir", workdir="afile/wd")


def test_ctrl_c_is_one_interrupted_line(tmp_path, capsys, monkeypatch):
    def interrupt(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(bench, "machine", interrupt)     # the first thing every part does
    out = tmp_path / "out.json"
    with pytest.raises(SystemExit) as e:
        bench.main(["--skip-policies", "--skip-references", "--sizes", "300",
                    "--workdir", str(tmp_path / "wd"), "--json", str(out)])
    assert e.value.code == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("interrupted:") and "Traceback" not in err
    assert not out.exists()
